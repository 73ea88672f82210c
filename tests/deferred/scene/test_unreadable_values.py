"""Values a parser or a library would turn into something else: a TOML integer of more digits
than Python reads, NaN vertex colours in a PLY or an OBJ (trimesh makes them 0). One line
naming the file, exit 2."""

from __future__ import annotations

import pytest
from command_line import assert_one_line_error, run

PLY_HEADER = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              "property float z\nproperty float red\nproperty float green\nproperty float blue\n"
              "element face 1\nproperty list uchar int vertex_indices\nend_header\n")


def test_a_number_of_5000_digits_in_a_scene_is_one_line(tmp_path, capfd):
    scene = tmp_path / "scene.toml"
    scene.write_text('[[object]]\nmesh = "builtin:sphere"\nmaterial = "standard"\n'
                     "[object.params]\nspecular_exponent = " + "1" * 5000 + "\n")
    code, _, err = run(capfd, "render", scene, "-o", tmp_path / "out.png", "--size", "32x24")
    assert_one_line_error(code, err, "scene.toml: malformed TOML: line 5, column 21: a number "
                          "of 5,000 digits (at most 4,300 are read)")


@pytest.mark.parametrize("name, text", [
    ("nan.ply", PLY_HEADER + "0 0 0 nan 0.5 0.5\n1 0 0 0.5 0.5 0.5\n0 1 0 0.5 0.5 0.5\n"
                             "3 0 1 2\n"),
    ("inf.ply", PLY_HEADER + "0 0 0 0.5 0.5 0.5\n1 0 0 0.5 inf 0.5\n0 1 0 0.5 0.5 0.5\n"
                             "3 0 1 2\n"),
    ("nan_uv.obj", "v 0 0 0 nan 0.5 0.5\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0 0.5 0.5 0.5\n"
                   "vt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n"),
])
def test_vertex_colours_that_are_not_numbers_name_the_file(tmp_path, capfd, name, text):
    (tmp_path / name).write_text(text)
    scene = tmp_path / "scene.toml"
    scene.write_text(f'[[object]]\nmesh = "{name}"\nmaterial = "standard"\n')
    code, _, err = run(capfd, "render", scene, "-o", tmp_path / "out.png", "--size", "32x24")
    assert_one_line_error(code, err, f"scene.toml: object[0].mesh: mesh {name} has a vertex "
                          "colour that is not a finite number")
    assert not (tmp_path / "out.png").exists()
