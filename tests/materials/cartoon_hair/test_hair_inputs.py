"""cartoon_hair's inputs: nonsense refused in one line naming the file and the key (strand
points beyond +-1e6, a number of more digits than Python reads, a negative collision sphere, a
taper leaving the tube no radius, a keyframe or ramp image that does not fit), and sound strand
files loaded whatever their strands' points add up to."""

from __future__ import annotations

import json

import numpy as np
import pytest
from command_line import assert_one_line_error, run

SCENE = """\
[camera]
position = [0.0, 1.0, 3.0]
target = [0.0, 1.0, 0.0]

[[object]]
mesh = "builtin:head"
material = "cartoon_hair"
[object.params]
"""


def write_scene(folder, **params):
    text = SCENE + "".join(f"{key} = {json.dumps(value)}\n" for key, value in params.items())
    (folder / "scene.toml").write_text(text)
    return folder / "scene.toml"


def strands_json(count: int, points: int, scale: float = 1.0) -> str:
    rng = np.random.default_rng(3)
    roots = rng.uniform(-0.3, 0.3, (count, 2))
    strands = [[[x, 1.0 + 0.02 * k, z + 0.01 * k * scale] for k in range(points)]
               for x, z in roots]
    return json.dumps({"strands": strands})


def test_a_file_of_600_strands_of_8_points_renders(tmp_path, capfd):
    (tmp_path / "hair.json").write_text(strands_json(600, 8))
    scene = write_scene(tmp_path, strands_file="hair.json")
    code, _, err = run(capfd, "render", scene, "-o", tmp_path / "out.png", "--size", "32x24")
    assert code == 0, err


@pytest.mark.parametrize("text, says", [
    ('{"strands": [[[0, 0, 0], [0, 1e300, 0], [0, 2e300, 0]]]}',
     "strand 0 point 1 has y = 1e+300, beyond +-1e+06"),
    ('{"strands": [[[0, 0, 0], [0, 1, 0], [0, -2000000, 0]]]}',
     "strand 0 point 2 has y = -2e+06, beyond +-1e+06"),
    ('{"strands": [[[0, 0, 0], [0, 1, 0],\n [0, ' + "7" * 5000 + ', 0]]]}',
     "line 2, column 6: a number of 5,000 digits (at most 4,300 are read)"),
])
def test_nonsense_strand_files_are_refused_naming_file_and_key(tmp_path, capfd, text, says):
    (tmp_path / "hair.json").write_text(text)
    scene = write_scene(tmp_path, strands_file="hair.json")
    code, _, err = run(capfd, "render", scene, "-o", tmp_path / "out.png", "--size", "32x24")
    assert_one_line_error(code, err, "scene.toml: object[0].params.strands_file: ", says)
    assert "warning" not in err and not (tmp_path / "out.png").exists()


@pytest.mark.parametrize("params, says", [
    ({"collision_spheres": [[0.0, 1.0, 0.0, 0.5], [0.0, 0.0, 0.0, -0.2]]},
     "object[0].params.collision_spheres: sphere 1 has radius -0.2; a radius is >= 0"),
    ({"taper": [0.0, 0.0, -1.0]}, "object[0].params.taper: gives the tube no radius anywhere"),
    ({"taper": [0.0, -2.0, 0.0]}, "object[0].params.taper: gives the tube no radius anywhere"),
])
def test_nonsense_hair_parameters_are_refused(tmp_path, capfd, params, says):
    scene = write_scene(tmp_path, **params)
    code, _, err = run(capfd, "render", scene, "-o", tmp_path / "out.png", "--size", "32x24")
    assert_one_line_error(code, err, says)


def test_a_taper_negative_near_the_tip_only_is_accepted(tmp_path, capfd):
    scene = write_scene(tmp_path, taper=[0.0, -2.0, 1.0])  # 0 from half way: a short cone
    code, _, err = run(capfd, "render", scene, "-o", tmp_path / "out.png", "--size", "32x24")
    assert code == 0, err


def write_images(folder):
    import OpenImageIO as oiio

    def write(name, pixels, kind):
        out = oiio.ImageOutput.create(str(folder / name))
        out.open(str(folder / name), oiio.ImageSpec(pixels.shape[1], pixels.shape[0],
                                                    pixels.shape[2], kind))
        out.write_image(pixels)
        out.close()

    nan = np.ones((4, 16, 3), np.float32)
    nan[1, 2, 0] = np.nan
    write("nan.exr", nan, oiio.FLOAT)
    write("wide.png", np.zeros((1, 20000, 3), np.uint8), oiio.UINT8)


@pytest.mark.parametrize("params, says", [
    ({"ramp_image": "nope.png"}, "object[0].params.ramp_image: ramp image not found"),
    ({"ramp_image": "nan.exr"},
     "object[0].params.ramp_image: image nan.exr has a value that is NaN"),
    ({"ramp_image": "wide.png"}, "object[0].params.ramp_image: image wide.png is 20000x1"),
    ({"strands": 20, "keyframes": ["pose.json"], "key_times": [0.0]},
     "object[0].params.keyframes[0]: pose.json has 1 strand; the hair has 20 (strands)"),
    ({"strands_file": "hair.json", "keyframes": ["hair.json", "pose.json"],
      "key_times": [0.0, 1.0]},
     "object[0].params.keyframes[1]: pose.json has 1 strand; the hair has 3 (strands_file)"),
])
def test_file_errors_carry_the_scene_key(tmp_path, capfd, params, says):
    write_images(tmp_path)
    (tmp_path / "pose.json").write_text(strands_json(1, 3))
    (tmp_path / "hair.json").write_text(strands_json(3, 4))
    scene = write_scene(tmp_path, **params)
    code, _, err = run(capfd, "render", scene, "-o", tmp_path / "out.png", "--size", "32x24")
    assert_one_line_error(code, err, f"error: scene.toml: {says}")


def test_a_material_made_in_python_names_the_key_alone(tmp_path):
    from deferred.errors import InputError
    from deferred.materials.cartoon_hair import CartoonHairMaterial

    material = CartoonHairMaterial(CartoonHairMaterial.Params(ramp_image="nope.exr"), tmp_path)
    with pytest.raises(InputError, match="^ramp_image: "):
        material.xtoon_ramp().texels()
