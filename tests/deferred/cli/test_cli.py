"""The command line: outputs, exit codes, one-line errors, no partial files."""

import subprocess
import sys

import numpy as np
import pytest

from deferred.cli import main
from deferred.io.images import read_channels, read_image


def run(capsys, *args):
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.mark.slow
def test_render_demo_png(tmp_path, capsys):
    out = tmp_path / "demo.png"
    code, stdout, err = run(capsys, "render", "-o", str(out), "--size", "160x90")
    assert code == 0, err
    assert stdout == ""
    image = read_image(out)
    assert image.shape == (90, 160, 4)
    assert image[..., :3].std() > 0.05  # not a blank frame
    assert [p.name for p in tmp_path.iterdir()] == ["demo.png"]  # no temporary left behind


def test_render_forward_exr_is_linear_float(tmp_path, capsys):
    out = tmp_path / "demo.exr"
    code, _, err = run(capsys, "render", "-o", str(out), "--size", "64x36", "--pipeline",
                       "forward")
    assert code == 0, err
    pixels, names, _ = read_channels(out)
    assert names == ["R", "G", "B", "A"] and pixels.shape == (36, 64, 4)
    assert pixels.dtype == np.float32 and pixels[..., 3].max() == 1.0


@pytest.mark.parametrize("args, fragment", [
    (["render", "missing.toml"], "missing.toml: scene file not found"),
    (["render", "--size", "0x10"], "--size: size 0x10 is impossible"),
    (["render", "--size", "big"], "--size: expected WIDTHxHEIGHT"),
    (["render", "--size", "1_60x9_0"], "--size: expected WIDTHxHEIGHT"),
    (["render", "--size", "+160x90"], "--size: expected WIDTHxHEIGHT"),
    (["render", "-o", "x.gif", "--frames", "2", "--fps", "5e-324"],
     "--fps: 5e-324 frames a second puts the last frame at no finite time"),
    (["render", "-o", "x.jpg"], "-o: output must end in .png, .exr, .mp4 or .gif"),
    (["render", "--pipeline", "raytrace"], "Invalid value for '--pipeline'"),
    (["render", "--frames", "0"], "Invalid value for '--frames'"),
    (["render", "-o", "folder.png"], "-o: output is a folder, not a file"),
])
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, monkeypatch, args, fragment):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "folder.png").mkdir()
    code, _, err = run(capsys, *args)
    assert code == 2
    assert fragment in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert [p.name for p in tmp_path.iterdir()] == ["folder.png"]
    assert list((tmp_path / "folder.png").iterdir()) == []


def test_a_budget_and_a_file_name_read_as_one_line_each(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", "1")
    code, _, err = run(capsys, "render", "-o", str(tmp_path / "x.png"), "--size", "64x36")
    # the meshes are counted first, before any is made
    assert code == 2 and "building 3 meshes of 10,240 triangles" in err and \
        "the budget is 1 byte (DEFERRED_TARGET_MEMORY)" in err, err
    monkeypatch.delenv("DEFERRED_TARGET_MEMORY")
    code, _, err = run(capsys, "render", str(tmp_path / "two\nlines.toml"))
    assert code == 2 and len(err.strip().splitlines()) == 1 and "two\\nlines.toml" in err


def test_no_command_prints_the_help_and_exits_0(capsys):
    code, out, err = run(capsys)
    assert code == 0 and err == ""
    assert out.startswith("Usage: deferred [OPTIONS] COMMAND") and "render" in out


def test_bad_scene_leaves_no_output(tmp_path, capsys):
    scene = tmp_path / "bad.toml"
    scene.write_text('[[object]]\nmesh = "builtin:sphere"\nmaterial = "standard"\n'
                     '[object.params]\nspecular_exponent = -4\n')
    out = tmp_path / "out.png"
    code, _, err = run(capsys, "render", str(scene), "-o", str(out))
    assert code == 2
    assert err.startswith("error: bad.toml: object[0].params.specular_exponent:")
    assert not out.exists()


def test_materials_and_info(capsys):
    code, out, _ = run(capsys, "materials")
    assert code == 0 and "standard" in out and "specular_exponent" in out
    code, out, _ = run(capsys, "info")
    assert code == 0 and "renderer" in out and "20 bytes per pixel" in out


def test_console_script_exit_code(tmp_path):
    result = subprocess.run([sys.executable, "-m", "deferred.cli", "render", "nope.toml"],
                            capture_output=True, text=True, cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.strip() == "error: nope.toml: scene file not found"


def test_python_argument_names_read_as_the_options_that_set_them(tmp_path, capsys, monkeypatch):
    """The Python API names its arguments (light_path, size, time, pipeline); through the
    command line the same problems name the options."""
    import deferred.render.setup as renderer_module
    from deferred.errors import InputError

    def refuse(*args, **kwargs):
        raise InputError("light path 'tiled' needs compute shaders (GL 4.3)", "light_path")

    monkeypatch.setattr(renderer_module, "resolve_light_path", refuse)
    code, _, err = run(capsys, "render", "-o", str(tmp_path / "x.png"), "--size", "32x18")
    assert code == 2 and err.strip() == \
        "error: --light-path: light path 'tiled' needs compute shaders (GL 4.3)", err
    monkeypatch.undo()
    code, _, err = run(capsys, "dump", "-o", str(tmp_path / "d"), "--size", "4096x4096")
    # a slow machine may print a progress line first ("starting the renderer (7 s)")
    errors = [line for line in err.splitlines() if line.startswith("error:")]
    assert code == 2 and len(errors) == 1 and errors[0].startswith("error: --size: "), err
    assert list(tmp_path.iterdir()) == []
