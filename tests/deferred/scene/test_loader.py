import numpy as np
import pytest

from deferred.errors import InputError
from deferred.scene.loader import load_scene, scene_from_toml
from deferred.scene.size import parse_size

GOOD = """
size = [320, 200]
[camera]
position = [0.0, 1.0, 4.0]
target = [0.0, 0.5, 0.0]
fov = 45.0

[[object]]
mesh = "builtin:torus"
material = "standard"
position = [0.0, 0.5, 0.0]
rotation = [0.0, 30.0, 0.0]
scale = 1.0
[object.params]
color = [0.5, 0.2, 0.1]

[[light]]
type = "point"
position = [2.0, 3.0, 2.0]
color = [1.0, 0.9, 0.8]
intensity = 20.0
radius = 10.0
"""


def error_of(text: str) -> str:
    with pytest.raises(InputError) as info:
        scene_from_toml(text, name="s.toml")
    return str(info.value)


def test_design_example_loads():
    scene = scene_from_toml(GOOD, name="s.toml")
    assert scene.size == (320, 200)
    assert [o.label for o in scene.objects] == ["torus0"]
    assert scene.objects[0].material.params.color == (0.5, 0.2, 0.1)
    assert scene.lights[0].params.radius == 10.0


def test_builtin_demo_scene_loads():
    scene = load_scene()
    assert scene.objects and scene.lights


@pytest.mark.parametrize("edit, expected", [
    (lambda t: t.replace("size = [320, 200]", "size = [320, 0]"), "s.toml: size: size 320x0"),
    (lambda t: t.replace("fov = 45.0", "fov = 400.0"), "s.toml: camera.fov: "),
    (lambda t: t.replace('material = "standard"', 'material = "no_such_material"'),
     "s.toml: object[0].material: unknown material 'no_such_material'"),
    (lambda t: t.replace("color = [0.5, 0.2, 0.1]", "shininess = 3"),
     "s.toml: object[0].params.shininess: unknown parameter"),
    (lambda t: t.replace("color = [0.5, 0.2, 0.1]", "specular_intensity = 3.0"),
     "s.toml: object[0].params.specular_intensity: Input should be less than or equal to 1"),
    (lambda t: t.replace('type = "point"', 'type = "laser"'),
     "s.toml: light[0].type: unknown light 'laser'"),
    (lambda t: t.replace("radius = 10.0", "radius = -1.0"),
     "s.toml: light[0].radius: Input should be greater than 0"),
    (lambda t: t.replace('mesh = "builtin:torus"', 'mesh = "nope.obj"'),
     "s.toml: object[0].mesh: mesh file not found"),
    (lambda t: t.replace("[camera]", "[camera]\nzoom = 2"),
     "s.toml: camera.zoom: unknown parameter"),
    (lambda t: t + "\n[[object]]\nmaterial = 'standard'\n", "s.toml: object[1].mesh: missing"),
    (lambda t: t.replace("scale = 1.0", "scale = 0.0"), "s.toml: object[0]: "),
    (lambda t: t.replace("size = [320, 200]", "size = [320, 200"), "s.toml: malformed TOML"),
    (lambda t: t.replace("fov = 45.0", "fov = 45.0\nup = [0.0, -0.5, -4.0]"),
     "s.toml: camera: up is parallel to the view direction"),
    (lambda t: t.replace('type = "point"', 'type = "ambient"\nup = [0, 0, 0]').replace(
        "radius = 10.0", "").replace("position = [2.0, 3.0, 2.0]", ""),
     "s.toml: light[0].up: must not be the zero vector"),
])
def test_validation_errors_name_file_key_and_problem(edit, expected):
    message = error_of(edit(GOOD))
    assert message.startswith(expected), message
    assert "\n" not in message


def test_scene_file_paths(tmp_path):
    with pytest.raises(InputError, match="scene file not found"):
        load_scene(tmp_path / "missing.toml")
    (tmp_path / "mesh.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "scene.toml").write_text(
        GOOD.replace('mesh = "builtin:torus"', 'mesh = "mesh.obj"'))
    scene = load_scene(tmp_path / "scene.toml")  # the mesh path is relative to the scene file
    assert scene.objects[0].mesh.name == "mesh.obj"


def test_texture_path_is_checked_relative_to_the_scene(tmp_path):
    text = GOOD.replace("color = [0.5, 0.2, 0.1]", 'texture = "wood.png"')
    (tmp_path / "scene.toml").write_text(text)
    with pytest.raises(InputError, match=r"object\[0\]\.params\.texture: texture file not found"):
        load_scene(tmp_path / "scene.toml")


@pytest.mark.parametrize("text", ["100", "10x", "axb", "0x10", "20000x10"])
def test_bad_sizes(text):
    with pytest.raises(InputError, match="--size"):
        parse_size(text)


def shared_standard_scene(event: dict | None):
    """Two spheres side by side drawn with one standard Material instance (the Python API
    shares an instance where it is given one); ``event`` changes the left one's from 0.25 s."""
    from deferred.interfaces.registry import materials
    from deferred.lights.directional import DirectionalLight
    from deferred.scene.camera import Camera
    from deferred.scene.scene import Scene

    scene = Scene(camera=Camera(position=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0)),
                  size=(64, 32))
    scene.lights = [DirectionalLight.from_dict({"direction": [0.0, 0.0, -1.0]})]
    material = materials.get("standard").from_dict({"color": [0.8, 0.2, 0.2]})
    left = scene.add("builtin:sphere", material, position=(-1.5, 0.0, 0.0))
    right = scene.add("builtin:sphere", material, position=(1.5, 0.0, 0.0))
    if event:
        scene.add_event(left, 0.25, event)
    return scene, left, right


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_an_event_on_one_object_leaves_another_sharing_its_material_alone(render, pipeline):
    plain, _, _ = shared_standard_scene(None)
    scene, left, right = shared_standard_scene({"color": [0.1, 0.7, 0.1]})
    shared = right.material
    before, _ = render(plain, pipeline, time=0.5)
    after, _ = render(scene, pipeline, time=0.5)
    half = before.hdr.shape[1] // 2
    np.testing.assert_array_equal(before.hdr[:, half:], after.hdr[:, half:])  # the right one
    assert np.abs(before.hdr[:, :half] - after.hdr[:, :half]).max() > 0.1  # the left one
    assert right.material is shared and left.material is shared  # the scene is not written
    assert shared.params.color == (0.8, 0.2, 0.2)
    assert left.params_at(0.5).color == (0.1, 0.7, 0.1)


def test_a_camera_pulled_back_keeps_its_direction_and_scales_its_distance():
    from deferred.scene.camera import Camera

    camera = Camera(position=(1.0, 2.0, 4.0), target=(1.0, 0.5, 0.0), fov=30.0)
    far = camera.pulled_back(3.0)
    offset, far_offset = (np.subtract(c.position, c.target) for c in (camera, far))
    np.testing.assert_allclose(far_offset, 3.0 * offset)
    assert (far.target, far.up, far.fov) == (camera.target, camera.up, camera.fov)


@pytest.mark.parametrize("text", ["", 'size = [64, 48]\n\n[[light]]\ntype = "ambient"\n'])
def test_a_scene_file_without_objects_renders_its_background_with_a_warning(tmp_path, capsys,
                                                                            text):
    """Valid (a background plate, the frame's fixed cost), but most likely a mistake: said."""
    from command_line import run

    (tmp_path / "empty.toml").write_text(text)
    code, _, err = run(capsys, "render", tmp_path / "empty.toml", "-o", tmp_path / "out.png",
                       "--size", "32x24")
    assert code == 0 and (tmp_path / "out.png").exists(), err
    assert err.splitlines()[0] == ("warning: empty.toml: the scene has no [[object]]: the image "
                                   "is its background alone")
