"""No output is lost or half written, none replaces an input (deferred.io.safety and
deferred.io.paths): writers that fail (a full disk, a writer that reports success and writes
nothing), outputs that name an input, output names too long for a file name.
"""

import errno
import json
import os
import resource
import subprocess
import sys
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest
from command_line import leftovers, one_line, run, snapshot

from deferred.errors import RenderError
from deferred.io.images import write_image, write_text


def scene_toml(tmp_path: Path, extra_object: str = "", name: str = "scene.toml") -> Path:
    scene = tmp_path / name
    scene.write_text('size = [48, 32]\nlight_path = "volumes"\n'
                     '[[object]]\nname = "ball"\nmesh = "builtin:sphere"\n' + extra_object +
                     '[[light]]\ntype = "ambient"\n')
    return scene


def textured_scene(tmp_path: Path, texture: str = "tex.png") -> tuple[Path, Path]:
    path = tmp_path / texture
    path.parent.mkdir(parents=True, exist_ok=True)
    write_image(path, np.full((4, 4, 3), 200, np.uint8))
    scene = scene_toml(tmp_path, '[[object]]\nname = "floor"\nmesh = "builtin:plane"\n'
                                 f'[object.params]\ntexture = "{texture}"\n')
    return scene, path


# -- writers that fail --------------------------------------------------------------------------

class FakeOutput:
    """An OIIO ImageOutput that writes through the real one, then misbehaves as told."""

    real = oiio.ImageOutput

    def __init__(self, name, mode):
        self.inner = self.real.create(name)
        self.name, self.mode = name, mode

    def open(self, name, spec):
        return self.inner.open(name, spec)

    def write_image(self, pixels):
        return self.inner.write_image(pixels)

    def close(self):
        closed = self.inner.close()
        if self.mode == "empty":  # success reported, nothing on the disk
            open(self.name, "wb").close()
        return closed

    @property
    def has_error(self):
        return self.mode == "silent-error" or self.inner.has_error

    def geterror(self):
        return self.inner.geterror()


def fake_writer(monkeypatch, mode):
    class Output:
        @staticmethod
        def create(name):
            return FakeOutput(name, mode)

    monkeypatch.setattr(oiio, "ImageOutput", Output)


def old_file(tmp_path, name="out.png"):
    path = tmp_path / name
    path.write_bytes(b"the old file")
    return path


@pytest.mark.parametrize("mode, reason", [
    ("silent-error", "the writer reported an error without a reason"),
    ("empty", "the writer left an empty file"),
])
def test_image_writer_failure_keeps_the_old_file(tmp_path, monkeypatch, mode, reason):
    out = old_file(tmp_path)
    fake_writer(monkeypatch, mode)
    with pytest.raises(RenderError) as caught:
        write_image(out, np.zeros((8, 8, 3), np.uint8))
    assert str(caught.value) == f"cannot write {out}: {reason}"
    assert out.read_bytes() == b"the old file"
    assert leftovers(tmp_path) == []


@pytest.mark.parametrize("name", ["out.exr", "manifest.json"])
def test_full_disk_at_the_rename_or_the_flush(tmp_path, monkeypatch, name):
    """os.replace (images) and os.fsync (text: where delayed allocation reports a full disk)
    fail with ENOSPC: the old file stays, the temporary goes, the reason is the OS's."""
    out = old_file(tmp_path, name)

    def no_space(*args):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    if name.endswith(".json"):
        monkeypatch.setattr(os, "fsync", no_space)
        call = lambda: write_text(out, "{}\n")  # noqa: E731
    else:
        monkeypatch.setattr(os, "replace", no_space)
        call = lambda: write_image(out, np.zeros((8, 8, 3), np.float32),  # noqa: E731
                                   channels=("R", "G", "B"))
    with pytest.raises(RenderError, match=f"^cannot write {out}: No space left on device$"):
        call()
    assert out.read_bytes() == b"the old file"
    assert leftovers(tmp_path) == []


def test_an_error_without_a_message_still_says_why(tmp_path, monkeypatch):
    out = old_file(tmp_path, "data.csv")
    monkeypatch.setattr(os, "fsync", lambda fd: (_ for _ in ()).throw(OSError()))
    with pytest.raises(RenderError) as caught:
        write_text(out, "a,b\n")
    assert str(caught.value) == f"cannot write {out}: OSError"
    assert out.read_bytes() == b"the old file"


@pytest.mark.slow
def test_render_on_a_full_disk_exits_1_and_keeps_the_old_image(tmp_path):
    """A real short write: a file size limit makes write(2) fail (EFBIG) as a full disk makes
    it fail (ENOSPC). OIIO's PNG writer reports success from write_image and close."""
    out = tmp_path / "out.png"
    write_image(out, np.random.default_rng(1).integers(0, 255, (90, 160, 3), dtype=np.uint8))
    before = out.read_bytes()
    limit = 4096  # the new frame (about 13 kB) does not fit; the old file is there already

    def small_files():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    # -B: Python would write stale modules' bytecode under the limit too, and its pyc writer
    # does not notice a short write: a truncated .pyc in the source tree breaks every later run
    result = subprocess.run([sys.executable, "-B", "-m", "deferred.cli", "render", "-o",
                             str(out), "--size", "160x90"], preexec_fn=small_files,
                            capture_output=True, text=True, cwd=tmp_path,
                            env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})
    assert result.returncode == 1, result.stderr
    line = one_line(result.stderr)
    assert line.startswith(f"render failed: cannot write {out}: ")
    assert len(line) > len(f"render failed: cannot write {out}: ") + 5  # a reason
    assert out.read_bytes() == before
    assert leftovers(tmp_path) == []


@pytest.mark.slow
def test_cli_write_failure_exits_1_with_the_reason(tmp_path, capsys, monkeypatch):
    out = old_file(tmp_path, "out.exr")
    monkeypatch.setattr(os, "replace", lambda *a: (_ for _ in ()).throw(
        OSError(errno.ENOSPC, "No space left on device")))
    code, _, err = run(capsys, "render", "-o", out, "--size", "32x18")
    assert code == 1
    assert one_line(err) == f"render failed: cannot write {out}: No space left on device"
    assert out.read_bytes() == b"the old file"


@pytest.mark.slow
def test_bench_csv_write_failure_exits_1(tmp_path, capsys, monkeypatch):
    out = old_file(tmp_path, "bench.csv")
    monkeypatch.setattr(os, "fsync", lambda fd: (_ for _ in ()).throw(
        OSError(errno.EIO, "Input/output error")))
    code, _, err = run(capsys, "bench", "--size", "32x18", "--lights", "1", "--shells", "0",
                       "--runs", "1", "--warmup", "0", "--pipelines", "deferred",
                       "--light-paths", "volumes", "--csv", out)
    assert code == 1
    assert err.strip().splitlines()[-1] == \
        f"render failed: cannot write {out}: Input/output error"
    assert out.read_bytes() == b"the old file"
    assert leftovers(tmp_path) == []


# -- outputs that name an input -----------------------------------------------------------------

@pytest.mark.parametrize("case", ["texture", "texture-symlink", "scene-hardlink",
                                  "mesh-hardlink", "sequence-frame"])
def test_render_output_that_is_an_input_exits_2(tmp_path, capsys, case):
    scene, texture = textured_scene(tmp_path)
    args = ["--size", "32x18"]
    if case == "texture":
        out, victim = texture, texture
    elif case == "texture-symlink":
        out, victim = tmp_path / "alias.png", texture
        out.symlink_to(texture)
    elif case == "scene-hardlink":
        out, victim = tmp_path / "scene-copy.exr", scene
        os.link(scene, out)
    elif case == "mesh-hardlink":
        mesh = tmp_path / "tri.obj"
        mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
        scene.write_text(scene.read_text().replace('"builtin:sphere"', '"tri.obj"'))
        out, victim = tmp_path / "mesh.png", mesh
        os.link(mesh, out)
    else:
        frame = tmp_path / "tex_1.png"
        os.replace(texture, frame)
        scene.write_text(scene.read_text().replace('"tex.png"', '"tex_1.png"'))
        out, victim = tmp_path / "tex_#.png", frame
        args += ["--frames", "3"]
    before = victim.read_bytes()
    code, _, err = run(capsys, "render", scene, "-o", out, *args)
    assert code == 2
    assert one_line(err) == f"error: -o: would overwrite {victim}, a file the scene reads"
    assert victim.read_bytes() == before
    assert leftovers(tmp_path) == []


def test_bench_output_that_is_an_input_exits_2(tmp_path, capsys):
    scene, texture = textured_scene(tmp_path)
    before = texture.read_bytes()
    os.link(scene, tmp_path / "results.json")
    for option, out, victim in (("--plot", texture, texture),
                                ("--json", tmp_path / "results.json", scene)):
        code, _, err = run(capsys, "bench", scene, option, out)
        assert code == 2
        assert one_line(err) == f"error: {option}: would overwrite {victim}, a file the " \
                                "scene reads"
    assert texture.read_bytes() == before
    assert scene.read_text().startswith("size = [48, 32]")


def fake_dump(folder: Path, value: float) -> None:
    (folder / "passes").mkdir(parents=True)
    write_image(folder / "final.exr", np.full((4, 4, 3), value, np.float32),
                channels=("R", "G", "B"))
    write_text(folder / "manifest.json", json.dumps({"format": "deferred-dump/1",
                                                     "files": {}, "passes": []}))


@pytest.mark.parametrize("inside", ["a", "a/diff", "b/x/y"])
def test_compare_output_inside_a_dump_exits_2(tmp_path, capsys, inside):
    fake_dump(tmp_path / "a", 0.0)
    fake_dump(tmp_path / "b", 1.0)
    before = snapshot(tmp_path)
    code, _, err = run(capsys, "dump", "--compare", tmp_path / "a", tmp_path / "b",
                       "-o", tmp_path / inside)
    assert code == 2
    victim = inside.split("/")[0]
    assert one_line(err) == f"error: -o: {tmp_path / inside} is inside the dump " \
                            f"{tmp_path / victim} being compared; difference images would " \
                            "overwrite its files"
    assert snapshot(tmp_path) == before
    assert not (tmp_path / inside).exists() or inside == "a"


def test_dump_that_would_replace_a_texture_exits_2(tmp_path, capsys):
    out = tmp_path / "d"
    scene = scene_toml(tmp_path)
    assert run(capsys, "dump", scene, "-o", out)[0] == 0
    scene.write_text(scene.read_text().replace(
        '[[light]]', '[object.params]\ntexture = "d/final.png"\n[[light]]'))
    before = snapshot(out)
    code, _, err = run(capsys, "dump", scene, "-o", out)
    assert code == 2
    assert one_line(err) == f"error: -o: would overwrite {out / 'final.png'}, a file the " \
                            "scene reads"
    assert snapshot(out) == before


def test_render_output_name_too_long_exits_2_before_rendering(tmp_path, capsys):
    code, _, err = run(capsys, "render", "-o", tmp_path / ("z" * 260 + ".png"))
    assert code == 2
    assert "file name longer than 255 bytes" in one_line(err)


@pytest.mark.slow
@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
def test_bench_json_to_a_full_stdout_exits_1(tmp_path):
    with open("/dev/full", "w") as full:
        result = subprocess.run([sys.executable, "-m", "deferred.cli", "bench", "--size", "32x18",
                                 "--lights", "1", "--shells", "0", "--runs", "1", "--warmup", "0",
                                 "--pipelines", "deferred", "--light-paths", "volumes",
                                 "--json", "-"], stdout=full, stderr=subprocess.PIPE, text=True,
                                cwd=tmp_path)
    assert result.returncode == 1
    assert result.stderr.strip().splitlines()[-1] == \
        "render failed: cannot write standard output: No space left on device"
    assert "Traceback" not in result.stderr and "Exception ignored" not in result.stderr


SPHERE_SCENE = '[[object]]\nmesh = "builtin:sphere"\nmaterial = "standard"\n'


@pytest.mark.parametrize("name, frames", [("out.png", 1), ("out.exr", 1), ("out.gif", 2),
                                          ("out_#.png", 2)])
def test_an_output_that_is_a_symbolic_link_is_written_through(tmp_path, capsys, name, frames):
    """-o onto a link replaces the file it points to and keeps the link (a link replaced by a
    regular file would silently cut it from what it shared)."""
    (tmp_path / "scene.toml").write_text(SPHERE_SCENE)
    shared = tmp_path / "shared"
    shared.mkdir()
    first = name.replace("#", "0")
    (shared / first).write_bytes(b"old")
    (tmp_path / first).symlink_to(shared / first)
    code, _, err = run(capsys, "render", tmp_path / "scene.toml", "-o", tmp_path / name,
                       "--size", "32x24", "--frames", frames)
    assert code == 0, err
    assert (tmp_path / first).is_symlink() and os.readlink(tmp_path / first) == str(shared / first)
    assert (shared / first).read_bytes() != b"old" and (shared / first).stat().st_size > 100
    assert leftovers(tmp_path) == []


def test_a_link_to_a_missing_folder_is_refused_before_rendering(tmp_path, capsys):
    (tmp_path / "scene.toml").write_text(SPHERE_SCENE)
    (tmp_path / "out.png").symlink_to(tmp_path / "nowhere" / "out.png")
    code, _, err = run(capsys, "render", tmp_path / "scene.toml", "-o", tmp_path / "out.png")
    assert code == 2 and one_line(err) == (
        f"error: -o: output out.png is a symbolic link to {tmp_path}/nowhere/out.png, whose "
        "folder does not exist")
    assert (tmp_path / "out.png").is_symlink()
