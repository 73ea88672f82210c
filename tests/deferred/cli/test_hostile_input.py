"""Issue #11, a hostile review's findings: each bad input exits 2 with one short line naming the
culprit, before any output, and quickly (no hang on values within the documented ranges)."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest

from deferred.cli import main
from deferred.io.images import write_image

SPHERE = """size = [48, 32]
[[object]]
name = "ball"
mesh = "{mesh}"
material = "{material}"
[object.params]
{params}
[[light]]
type = "directional"
{extra}
"""


def scene(mesh="builtin:sphere", material="standard", params="", extra="") -> str:
    return SPHERE.format(mesh=mesh, material=material, params=params, extra=extra)


def nan_exr(folder):
    pixels = np.full((8, 8, 4), 0.5, np.float32)
    pixels[3, 4, 1] = np.nan
    write_image(folder / "nan.exr", pixels)


def negative_exr(folder):
    write_image(folder / "negative.exr", np.full((8, 8, 3), -5.0, np.float32))


def fifo(folder):
    os.mkfifo(folder / "pipe.png")


def folder_texture(folder):
    (folder / "textures").mkdir()


def fifo_material_library(folder):
    (folder / "tri.obj").write_text("mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    os.mkfifo(folder / "lib.mtl")


# (id, scene text, command after "render s.toml -o out.png" or a whole command, setup,
#  fragments of the one line)
CASES = [
    ("deep-toml", "x = " + "[" * 5000 + "]" * 5000 + "\n", None, None,
     ["s.toml", "nested too deep"]),
    ("nan-texture", scene(params='texture = "nan.exr"'), None, nan_exr,
     ["object[0].params.texture", "NaN, infinite or negative", "pixel 4, 3"]),
    ("negative-texture", scene(params='texture = "negative.exr"'), None, negative_exr,
     ["object[0].params.texture", "NaN, infinite or negative"]),
    ("fifo-texture", scene(params='texture = "pipe.png"'), None, fifo,
     ["object[0].params.texture", "not a regular file"]),
    ("folder-texture", scene(params='texture = "textures"'), None, folder_texture,
     ["object[0].params.texture", "is a folder"]),
    ("empty-texture-name", scene(params='texture = ""'), None, None,
     ["object[0].params.texture", "is empty; name the texture file"]),
    ("fifo-mesh", scene(mesh="pipe.png"), None, fifo, ["object[0].mesh", "not a regular file"]),
    ("huge-builtin", scene(mesh="builtin:sphere?segments=4096&rings=4096"), None, None,
     ["object[0].mesh", "33,554,432 triangles"]),
    ("huge-builtin-radius", scene(mesh="builtin:sphere?radius=1e30"), None, None,
     ["object[0].mesh", "'radius' must be greater than 0 and at most"]),
    ("control-character-name", scene().replace('name = "ball"', 'name = "a\\nb"'), None, None,
     ["object[0].name", "no control characters"]),
    ("line-break-mesh-name", scene(mesh="a\\nb.obj"), None, None,
     ["object[0].mesh", "mesh file not found", "a\\nb.obj"]),
    ("depth-range", scene(extra="[camera]\nnear = 1e-9\nfar = 100.0"), None, None,
     ["s.toml: camera", "far / near is 1e+11"]),
    ("revie-fins-event", scene(material="revie_fur", params="shells = 4\nfins = true",
                               extra='[[event]]\ntime = 1.0\nobject = "ball"\n'
                                     'params = {fins = false}'), None, None,
     ["event[0].params.fins", "would change the object's passes", "-ball.fins"]),
    ("shell-fur-droplets", scene(material="shell_fur", params="droplets = 100000"), None, None,
     ["object[0].params.droplets", "less than or equal to 10000"]),
    ("shell-fur-settle", scene(material="shell_fur", params="settle = 60.0\ntime_step = 1e-7"),
     None, None, ["object[0].params", "settle / time_step is 600,000,000 steps"]),
    ("shell-fur-far-time", scene(material="shell_fur"), ["--time", "1000000"], None,
     ["--time", "simulation steps", "the most is 100,000"]),
    ("huge-array-message", scene(extra="[camera]\nposition = [" + "1.0, " * 200000 + "1.0]"),
     None, None, ["camera.position", "at most 3 items"]),
    ("unknown-object-among-many", "".join(
        f'[[object]]\nname = "{"n" * 300}{k}"\nmesh = "builtin:sphere"\n' for k in range(50))
     + '[[event]]\ntime = 1.0\nobject = "nobody"\nparams = {}\n', None, None,
     ["event[0].object", "no object named 'nobody'", "(50 in all)"]),
    ("frames-too-many", scene(), ["--frames", "100000000"], None, ["--frames"]),
    ("output-folder-name-too-long", scene(), ["-o", "d" * 300 + "/out.png"], None,
     ["-o", "folder name longer than 255 bytes"]),
    # issue #22
    ("droplets-covering-the-mask", scene(material="shell_fur", params="droplets = 10000\n"
                                         "droplet_radius = 100.0\nmask_size = 4096"),
     None, None, ["object[0].params.droplets", "wetness-mask texels", "the most is 400,000,000"]),
    ("many-droplets-of-radius-1", scene(material="shell_fur", params="droplets = 10000\n"
                                        "droplet_radius = 1.0\nmask_size = 4096"),
     None, None, ["object[0].params.droplets", "10,000 droplets by t = 0 s"]),
    ("droplets-falling", scene(material="shell_fur", params="droplets = 20",
                               extra='[[event]]\ntime = 1.0\nobject = "ball"\n'
                                     'params = {droplets = 5}'), None, None,
     ["event[0].params.droplets", "may rise on a timeline, not fall"]),
    ("gif-frames-past-the-budget", scene(), ["--size", "4096x4096", "--frames", "100000", "-o",
                                             "x.gif"], None,
     ["--frames", "100,000 frames of 4096x4096 held for a GIF take 3.1 TiB"]),
    ("dump-past-the-budget", scene(), ["dump", "s.toml", "-o", "dump", "--size", "4096x4096"],
     None, ["--size: a dump of 4096x4096 holds", "--passes to capture fewer passes"]),
    ("size-with-underscores", scene(), ["--size", "1_60x9_0"], None, ["--size"]),
    ("fps-whose-last-frame-overflows", scene(), ["--fps", "5e-324", "--frames", "3"], None,
     ["--fps", "no finite time"]),
    ("scale-too-small", scene().replace('material = "standard"',
                                        'material = "standard"\nscale = 1e-300'), None, None,
     ["object[0]", "scale must be at least 1e-06"]),
    ("wind-one-short", scene(material="shell_fur", params="wind = [1.0, 2.0]"), None, None,
     ["object[0].params.wind", "expected more than the 2 values given"]),
    ("fifo-material-library", scene(mesh="tri.obj"), None, fifo_material_library,
     ["object[0].mesh", "lib.mtl", "not a regular file"]),
]


@pytest.mark.parametrize("scene_text, options, setup, fragments",
                         [case[1:] for case in CASES], ids=[case[0] for case in CASES])
def test_hostile_input_exits_2_with_one_short_line(tmp_path, capsys, monkeypatch, scene_text,
                                                   options, setup, fragments):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(scene_text)
    if setup is not None:
        setup(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    args = ["render", "s.toml", "-o", "out.png", *(options or [])]
    if options and "-o" in options:
        args = ["render", "s.toml", *options]
    if options and options[0] == "dump":
        args = options
    start = time.perf_counter()
    code = main(args)
    elapsed = time.perf_counter() - start
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert len(lines[0]) < 600, lines[0][:200]  # never the whole input echoed back
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # no output, nothing changed
    assert elapsed < 20.0


def test_a_bad_memory_budget_variable_is_named(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(scene())
    for value in ("banana", "-1", "nan"):
        monkeypatch.setenv("DEFERRED_TARGET_MEMORY", value)
        assert main(["render", "s.toml", "-o", "out.png"]) == 2
        err = capsys.readouterr().err
        assert err.startswith("error: DEFERRED_TARGET_MEMORY: must be a whole number of bytes")
    assert not (tmp_path / "out.png").exists()


@pytest.mark.parametrize("args, fragment", [
    (["bench", "--runs", "999999999"], "Invalid value for '--runs'"),
    (["bench", "--warmup", "999999999"], "Invalid value for '--warmup'"),
    (["dump", "--passes", "", "-o", "d"], "--passes: names no pass"),
    (["render", "/dev/null", "-o", "out.png"], "scene file is not a regular file"),
])
def test_hostile_options_exit_2(tmp_path, capsys, monkeypatch, args, fragment):
    monkeypatch.chdir(tmp_path)
    assert main(args) == 2
    err = capsys.readouterr().err
    assert fragment in err and len(err.strip().splitlines()) == 1, err
    assert list(tmp_path.iterdir()) == []

