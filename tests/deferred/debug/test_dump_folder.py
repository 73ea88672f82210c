"""A dump folder as a whole (deferred.debug.dump_folder): dumps into folders of other files, dumps
that fail or are interrupted by Ctrl-C or SIGTERM leave the old dump or a whole new one, two dumps
into one folder, and object names too long for a file name.
"""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from command_line import leftovers, one_line, run, snapshot

import deferred.debug.dump as dump_module
import deferred.debug.dump_folder as dump_folder
from deferred.cli import main
from deferred.debug.capture import capture_frame
from deferred.debug.dump import safe_name, write_dump
from deferred.debug.dump_folder import is_dump_folder
from deferred.errors import InputError, RenderError
from deferred.io.paths import NAME_MAX, temporary_path
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict


def assert_whole_dump(folder: Path) -> dict:
    """A dump folder as a dump writes it: a manifest whose files all exist, and no pass file
    the manifest does not list."""
    assert is_dump_folder(folder), sorted(p.name for p in folder.iterdir())
    manifest = json.loads((folder / "manifest.json").read_text())
    listed = set(manifest["files"].values()) | \
        {p["file"] for p in manifest["passes"] if p["file"]}
    missing = [name for name in listed if not (folder / name).is_file()]
    assert not missing, missing
    on_disk = {f"passes/{p.name}" for p in (folder / "passes").glob("*.exr")}
    assert on_disk <= listed, on_disk - listed
    return manifest


# -- dump folders -------------------------------------------------------------------------------

def test_dump_refuses_a_folder_of_other_files(tmp_path, capsys):
    out = tmp_path / "photos"
    out.mkdir()
    (out / "holiday.png").write_bytes(b"not mine to delete")
    (out / "passes").mkdir()
    code, _, err = run(capsys, "dump", "-o", out, "--size", "32x18")
    assert code == 2
    assert one_line(err).startswith(f"error: -o: {out} is not empty and holds no dump")
    assert snapshot(out) == {"holiday.png": b"not mine to delete"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["photos"]  # no lock, no staging


def small_scene(name: str = "ball", color=(0.8, 0.3, 0.2)):
    return scene_from_dict({
        "size": [48, 32], "light_path": "volumes",
        "camera": {"position": [0.0, 1.2, 3.0], "target": [0.0, 0.4, 0.0]},
        "object": [{"name": name, "mesh": "builtin:sphere", "position": [0.0, 0.5, 0.0],
                    "params": {"color": list(color)}}],
        "light": [{"type": "ambient", "color": [0.2, 0.2, 0.25]},
                  {"type": "point", "position": [1.0, 1.0, 1.0], "intensity": 3.0}]})


@pytest.fixture
def capture(gl):
    made = []

    def make(scene=None):
        renderer = Renderer(scene or small_scene(), "deferred", gl=gl)
        made.append(renderer)
        return capture_frame(renderer)

    yield make
    for renderer in made:
        renderer.release()


def test_write_dump_refuses_a_folder_of_other_files(tmp_path, capture):
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match="is not empty and holds no dump"):
        write_dump(capture(), tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


def test_a_failed_dump_leaves_the_old_one(tmp_path, capture, monkeypatch):
    out = tmp_path / "d"
    frame = capture()
    write_dump(frame, out)
    (out / "notes.txt").write_text("mine")
    before = snapshot(out)
    calls = []
    real = dump_module.write_image

    def third_fails(path, *args, **kwargs):
        calls.append(path)
        if len(calls) == 3:
            raise RenderError(f"cannot write {path}: No space left on device")
        return real(path, *args, **kwargs)

    monkeypatch.setattr(dump_module, "write_image", third_fails)
    with pytest.raises(RenderError, match="No space left on device"):
        write_dump(frame, out)
    assert snapshot(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d"]


def test_interrupted_between_the_renames_keeps_the_old_dump(tmp_path, capture, monkeypatch):
    out = tmp_path / "d"
    frame = capture()
    write_dump(frame, out)
    before = snapshot(out)
    real = os.rename
    renames = []

    def interrupted(source, target):
        renames.append(target)
        if len(renames) == 2:  # old dump moved away, new one about to go in
            raise KeyboardInterrupt
        return real(source, target)

    monkeypatch.setattr(dump_folder.os, "rename", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_dump(frame, out)
    monkeypatch.undo()
    assert snapshot(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d"]


def test_a_dump_killed_between_the_renames_is_recovered(tmp_path, capture):
    """SIGKILL cannot be caught: the next dump into the folder puts the old one back before
    it looks at it, and removes what the killed one left."""
    out = tmp_path / "d"
    frame = capture()
    write_dump(frame, out)
    os.rename(out, tmp_path / ".d.old-1234")
    (tmp_path / ".d.dump-5678" / "passes").mkdir(parents=True)
    write_dump(frame, out)
    assert_whole_dump(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d"]


def test_a_300_character_object_name_dumps_and_compares(tmp_path, capture, capsys):
    long_name = "fur_" + "x" * 296
    first, second = tmp_path / "a", tmp_path / "b"
    write_dump(capture(small_scene(long_name)), first)
    manifest = write_dump(capture(small_scene(long_name, (0.1, 0.9, 0.1))), second)
    assert_whole_dump(second)
    files = [p["file"] for p in manifest["passes"] if long_name in p["name"]]
    assert files and all(len(Path(f).name.encode()) < NAME_MAX - 20 for f in files)
    code, _, err = run(capsys, "dump", "--compare", first, second, "-o", tmp_path / "diff")
    assert code == 1, err  # they differ (the fur's colour)
    compared = json.loads((tmp_path / "diff" / "compare.json").read_text())
    keys = {b["buffer"]: b for b in compared["buffers"]}
    gbuffer = keys[f"passes/{long_name}.gbuffer"]  # keyed by the whole pass name
    assert gbuffer["max"] > 0 and (tmp_path / "diff" / gbuffer["image"]).is_file()


def test_long_names_stay_distinct_and_short():
    a, b = "x" * 300 + "a", "x" * 300 + "b"
    assert safe_name(a) != safe_name(b) and len(safe_name(a)) <= 100
    assert safe_name("ball.gbuffer") == "ball.gbuffer"
    assert len(temporary_path("/tmp/" + "y" * 250 + ".png").name.encode()) <= NAME_MAX


# -- interrupted and concurrent dumps (subprocesses) --------------------------------------------

# The child takes Ctrl-C as Python normally does even where the test runner was started with
# SIGINT ignored (a background job), which the child would inherit.
CHILD = ("import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
         "from deferred.cli import main; sys.exit(main(sys.argv[1:]))")


def start_dump(out: Path, size: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", CHILD, "dump", "-o", str(out), "--size",
                             size], cwd=out.parent, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)


@pytest.mark.slow
@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupted_dump_leaves_a_whole_dump(tmp_path, signum, code):
    out = tmp_path / "d"
    assert main(["dump", "-o", str(out), "--size", "48x32"]) == 0
    before = snapshot(out)
    for attempt in range(3):  # the signal must land while files are written
        child = start_dump(out, "640x360")
        deadline = time.monotonic() + 60
        while not any(p.name.startswith(".d.dump-") for p in tmp_path.iterdir()):
            assert child.poll() is None, child.stderr.read()
            assert time.monotonic() < deadline
            time.sleep(0.005)
        time.sleep(0.1 * attempt)
        child.send_signal(signum)
        err = child.communicate(timeout=60)[1]
        assert sorted(p.name for p in tmp_path.iterdir()) == ["d"], err  # no staging, lock
        assert leftovers(out) == []
        manifest = assert_whole_dump(out)
        if child.returncode == code:
            assert err.strip().splitlines()[-1] == ("interrupted" if code == 130
                                                    else "terminated")
            assert snapshot(out) == before  # the old dump, untouched
            return
        assert child.returncode == 0, err  # finished before the signal: the new dump
        assert manifest["size"] == [640, 360]
        before = snapshot(out)
    pytest.fail("the dump always finished before the signal")


@pytest.mark.slow
def test_two_dumps_into_one_folder_leave_one_whole_dump(tmp_path):
    out = tmp_path / "d"
    children = [start_dump(out, size) for size in ("96x54", "128x72")]
    for child in children:
        err = child.communicate(timeout=120)[1]
        assert child.returncode == 0, err
    manifest = assert_whole_dump(out)
    assert manifest["size"] in ([96, 54], [128, 72])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d"]
    assert leftovers(out) == []
