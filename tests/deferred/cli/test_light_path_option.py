"""--light-path names a path of --pipeline's (the forward pipeline's are naive and tiled); the
line a command ends with says which path ran."""

from __future__ import annotations

import pytest
from command_line import assert_one_line_error, run

SCENE = '[[object]]\nmesh = "builtin:sphere"\nmaterial = "standard"\n\n' \
        '[[light]]\ntype = "point"\nposition = [0.0, 2.0, 2.0]\n'


@pytest.mark.parametrize("pipeline, path, theirs", [
    ("forward", "volumes", "naive and tiled"),
    ("forward", "clustered", "naive and tiled"),
    ("deferred", "naive", "volumes, tiled and clustered"),
])
@pytest.mark.parametrize("command", ["render", "dump"])
def test_another_pipelines_light_path_is_refused(tmp_path, capfd, command, pipeline, path,
                                                 theirs):
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE)
    out = tmp_path / ("out.png" if command == "render" else "dump")
    code, _, err = run(capfd, command, scene, "-o", out, "--size", "32x24", "--pipeline",
                       pipeline, "--light-path", path)
    assert_one_line_error(code, err, f"--light-path: '{path}' is a light path of the ",
                          f"the {pipeline} pipeline's are {theirs}")
    assert not out.exists()


@pytest.mark.parametrize("command", ["render", "dump"])
def test_the_output_line_says_which_light_path_ran(tmp_path, capfd, command):
    """A scene's light path is a preference: the other pipeline runs its equivalent, and says
    so."""
    scene = tmp_path / "scene.toml"
    scene.write_text('light_path = "volumes"\n' + SCENE)
    out = tmp_path / ("out.png" if command == "render" else "dump")
    code, _, err = run(capfd, command, scene, "-o", out, "--size", "32x24", "--pipeline",
                       "forward")
    assert code == 0, err
    assert "forward, naive lights" in err.strip().splitlines()[-1], err
