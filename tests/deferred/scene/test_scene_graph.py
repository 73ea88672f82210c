"""The scene graph: parents, local placements (Euler angles in an order, quaternions, per-axis
scale), world matrices, and what the renderer draws from them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from deferred import InputError, Renderer
from deferred.scene import Camera, Scene, scene_from_toml
from deferred.scene.transform import euler_matrix, model_matrix, quaternion_matrix

PIPELINES = ["deferred", "forward"]


def axis(name: str, degrees: float) -> np.ndarray:
    """A counter-clockwise rotation about one axis, written out (the reference)."""
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    matrix = {"X": [[1, 0, 0], [0, c, -s], [0, s, c]],
              "Y": [[c, 0, s], [0, 1, 0], [-s, 0, c]],
              "Z": [[c, -s, 0], [s, c, 0], [0, 0, 1]]}[name]
    return np.array(matrix, dtype=np.float64)


@pytest.mark.parametrize("order", ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"])
def test_euler_orders_turn_about_the_first_axis_first(order):
    angles = {"X": 20.0, "Y": -35.0, "Z": 50.0}
    expected = np.identity(3)
    for name in order:  # each later turn applied after (to the left of) the earlier ones
        expected = axis(name, angles[name]) @ expected
    got = euler_matrix((angles["X"], angles["Y"], angles["Z"]), order)
    np.testing.assert_allclose(got[:3, :3], expected, atol=1e-12)


def test_a_quaternion_is_the_rotation_about_its_axis():
    direction = np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])
    angle = math.radians(70.0)
    quaternion = (*(direction * math.sin(angle / 2)), math.cos(angle / 2))
    # Rodrigues' formula
    k = np.array([[0, -direction[2], direction[1]], [direction[2], 0, -direction[0]],
                  [-direction[1], direction[0], 0]])
    expected = np.identity(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k
    np.testing.assert_allclose(quaternion_matrix(quaternion)[:3, :3], expected, atol=1e-12)
    # not normalised: the same rotation
    np.testing.assert_allclose(quaternion_matrix(np.multiply(quaternion, 3.0)),
                               quaternion_matrix(quaternion), atol=1e-12)


HIERARCHY = """
size = [160, 120]
[camera]
position = [0.0, 0.0, 12.0]
target = [0.0, 0.0, 0.0]
fov = 40.0

[[light]]
type = "ambient"
color = [1.0, 1.0, 1.0]
ground = [1.0, 1.0, 1.0]
intensity = 1.0

[[group]]
name = "rig"
position = [-1.0, 0.5, 0.0]
rotation = [0.0, 0.0, 30.0]

[[object]]
name = "root"
parent = "rig"
mesh = "builtin:sphere"
scale = 0.3
params = { color = [1.0, 0.0, 0.0], specular_intensity = 0.0 }

[[group]]
name = "arm"
parent = "rig"
position = [2.0, 0.0, 0.0]
scale = [1.5, 0.5, 1.0]
quaternion = [0.0, 0.0, 0.25881905, 0.96592583]

[[object]]
name = "middle"
parent = "arm"
mesh = "builtin:sphere"
scale = 0.3
params = { color = [0.0, 1.0, 0.0], specular_intensity = 0.0 }

[[object]]
name = "leaf"
parent = "middle"
mesh = "builtin:sphere"
position = [3.0, 4.0, 0.0]
rotation = [10.0, 0.0, 20.0]
rotation_order = "ZYX"
scale = 2.5
params = { color = [0.0, 0.0, 1.0], specular_intensity = 0.0 }
"""


def project(camera: Camera, size: tuple[int, int], point: np.ndarray) -> np.ndarray:
    """The pixel (x from the left, y from the top, continuous) ``point`` lands on."""
    clip = camera.projection(size[0] / size[1]) @ camera.view() @ np.append(point, 1.0)
    ndc = clip[:3] / clip[3]
    return np.array([(ndc[0] + 1) / 2 * size[0], (1 - ndc[1]) / 2 * size[1]])


@pytest.mark.parametrize("pipeline", PIPELINES)
def test_a_three_level_hierarchy_puts_each_child_where_the_matrices_say(gl, pipeline):
    scene = scene_from_toml(HIERARCHY, "h.toml")
    rig, arm = scene.groups
    root, middle, leaf = scene.objects
    # world = T R S of each level, parent first, written out
    rig_world = model_matrix((-1.0, 0.5, 0.0), (0.0, 0.0, 30.0), 1.0)
    arm_world = rig_world @ model_matrix((2.0, 0.0, 0.0), (0, 0, 0), (1.5, 0.5, 1.0),
                                         quaternion=(0.0, 0.0, 0.25881905, 0.96592583))
    middle_world = arm_world @ np.diag([0.3, 0.3, 0.3, 1.0])
    leaf_world = middle_world @ model_matrix((3.0, 4.0, 0.0), (10.0, 0.0, 20.0), 2.5, "ZYX")
    expected = {"root": rig_world @ np.diag([0.3, 0.3, 0.3, 1.0]), "middle": middle_world,
                "leaf": leaf_world}
    with Renderer(scene, pipeline, gl=gl) as renderer:
        image = renderer.render(hdr=True).hdr
        for obj in (root, middle, leaf):
            np.testing.assert_allclose(renderer.state.object_state(obj).model,
                                       expected[obj.label], atol=1e-9)
    for channel, obj in enumerate((root, middle, leaf)):
        others = [c for c in range(3) if c != channel]
        mask = (image[..., channel] > 0.2) & (image[..., others].max(axis=-1) < 0.05)
        assert mask.sum() > 20, f"{obj.label} is not drawn"
        rows, columns = np.nonzero(mask)  # read back with the top row first
        centre = np.array([columns.mean() + 0.5, rows.mean() + 0.5])
        predicted = project(scene.camera, scene.size, expected[obj.label][:3, 3])
        assert np.linalg.norm(centre - predicted) < 1.0, (obj.label, centre, predicted)


SQUASHED = """
size = [96, 96]
tonemap = "none"
background = [0.0, 0.0, 0.0]
[camera]
position = [0.0, 0.0, 6.0]
target = [0.0, 0.0, 0.0]
fov = 30.0

[[light]]
type = "directional"
direction = [-0.4, -0.6, -0.7]
intensity = 1.0

[[group]]
name = "squash"
scale = [1.2, 0.4, 1.2]
rotation = [0.0, 0.0, 25.0]

[[object]]
parent = "squash"
mesh = "builtin:sphere?segments=192&rings=96"
params = { color = [1.0, 1.0, 1.0], specular_intensity = 0.0 }
"""


def ellipsoid_reference(scene: Scene, size: int) -> tuple[np.ndarray, np.ndarray]:
    """(radiance, hit) per pixel centre: rays from the camera against the ellipsoid the group
    makes of the unit sphere, lit by the directional light with the normal the surface really
    has (the inverse transpose), in numpy."""
    world = model_matrix((0, 0, 0), (0.0, 0.0, 25.0), (1.2, 0.4, 1.2))
    inverse = np.linalg.inv(world)
    camera = scene.camera
    view_projection = camera.projection(1.0) @ camera.view()
    unproject = np.linalg.inv(view_projection)
    pixels = (np.arange(size) + 0.5) / size * 2 - 1
    ndc_x, ndc_y = np.meshgrid(pixels, -pixels)  # the composite is read top row first
    far = np.stack([ndc_x, ndc_y, np.ones_like(ndc_x), np.ones_like(ndc_x)], -1) @ unproject.T
    far = far[..., :3] / far[..., 3:]
    origin = np.asarray(camera.position, np.float64)
    direction = far - origin
    # into the sphere's space: |o + t d| = 1
    o = inverse[:3, :3] @ origin + inverse[:3, 3]
    d = direction @ inverse[:3, :3].T
    a, b, c = (d * d).sum(-1), 2 * (d @ o), o @ o - 1.0
    disc = b * b - 4 * a * c
    hit = disc > 0
    t = (-b - np.sqrt(np.where(hit, disc, 0.0))) / (2 * a)
    local = o + t[..., None] * d
    normal = local @ inverse[:3, :3]  # the inverse transpose applied to the sphere's normal
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    light = -np.array([-0.4, -0.6, -0.7]) / np.linalg.norm([-0.4, -0.6, -0.7])
    radiance = np.clip(normal @ light, 0.0, None)
    return np.where(hit, radiance, 0.0), hit


@pytest.mark.parametrize("pipeline", PIPELINES)
def test_normals_under_non_uniform_scale_stay_perpendicular(gl, pipeline):
    scene = scene_from_toml(SQUASHED, "squash.toml")
    reference, hit = ellipsoid_reference(scene, 96)
    with Renderer(scene, pipeline, gl=gl) as renderer:
        rendered = renderer.render(hdr=True).hdr[..., 0]
    # away from the silhouette, where the tessellated sphere and the ellipsoid cover alike
    inner = hit & np.roll(hit, 2, 0) & np.roll(hit, -2, 0) & np.roll(hit, 2, 1) & \
        np.roll(hit, -2, 1)
    error = np.abs(rendered - reference)[inner]
    assert inner.sum() > 1000
    assert error.mean() < 0.01 and np.percentile(error, 99) < 0.04, \
        (error.mean(), np.percentile(error, 99))
    # the model matrix used for the normals (not its inverse transpose) is far off
    wrong = model_matrix((0, 0, 0), (0.0, 0.0, 25.0), (1.2, 0.4, 1.2))
    assert not np.allclose(wrong[:3, :3], np.linalg.inv(wrong[:3, :3]).T, atol=0.1)


# -- errors --------------------------------------------------------------------------------------

def with_parent(parent: str, extra: str = "") -> str:
    return f"""
[[group]]
name = "a"
parent = "{parent}"

[[object]]
name = "b"
mesh = "builtin:cube"
parent = "a"
{extra}
"""


def test_an_unknown_parent_is_one_line_naming_the_key():
    with pytest.raises(InputError) as caught:
        scene_from_toml(with_parent("nowhere"), "s.toml")
    message = str(caught.value)
    assert "\n" not in message
    assert message.startswith("s.toml: group[0].parent: no object or group named 'nowhere'")


def test_a_cycle_of_parents_is_refused():
    with pytest.raises(InputError, match=r"^s\.toml: object\[0\]\.parent: the parents form a "
                                         r"cycle \(b -> a -> b\)"):
        scene_from_toml(with_parent("b"), "s.toml")
    scene = Scene()
    ball = scene.add_object("builtin:sphere", label="ball")
    with pytest.raises(InputError, match="cycle"):
        scene.add_group("g", parent="g")
    ball.parent = ball
    with pytest.raises(InputError, match=r"^ball\.parent: the parents form a cycle"):
        scene.world_at(ball, 0.0)


def test_a_light_and_the_camera_hang_from_nodes():
    text = HIERARCHY.replace('[camera]\n', '[camera]\nparent = "rig"\n').replace(
        'type = "ambient"', 'type = "point"\nparent = "leaf"\nposition = [1.0, 0.0, 0.0]\n'
        'radius = 20.0\n').replace('ground = [1.0, 1.0, 1.0]\n', '')
    scene = scene_from_toml(text, "h.toml")
    from deferred.scene.timeline import SceneEvaluator

    state = SceneEvaluator(scene).evaluate(0.0)
    rig = model_matrix((-1.0, 0.5, 0.0), (0.0, 0.0, 30.0), 1.0)
    arm = rig @ model_matrix((2.0, 0.0, 0.0), (0, 0, 0), (1.5, 0.5, 1.0),
                             quaternion=(0.0, 0.0, 0.25881905, 0.96592583))
    leaf = arm @ np.diag([0.3, 0.3, 0.3, 1.0]) @ \
        model_matrix((3.0, 4.0, 0.0), (10.0, 0.0, 20.0), 2.5, "ZYX")
    np.testing.assert_allclose(state.camera.position, (rig @ [0, 0, 12, 1])[:3], atol=1e-9)
    np.testing.assert_allclose(state.camera.target, rig[:3, 3], atol=1e-9)
    np.testing.assert_allclose(state.lights[0].params.position, (leaf @ [1, 0, 0, 1])[:3],
                               atol=1e-9)
    assert scene.lights[0].params.position == (1.0, 0.0, 0.0)  # the scene's own, untouched
    with pytest.raises(InputError, match=r"^h\.toml: light\[0\]\.parent: no object or group "
                                         r"named 'nobody'"):
        scene_from_toml(text.replace('parent = "leaf"', 'parent = "nobody"'), "h.toml")


def test_placement_keys_are_checked():
    with pytest.raises(InputError, match="give rotation .* or quaternion, not both"):
        scene_from_toml('[[object]]\nmesh = "builtin:cube"\nrotation = [0, 10, 0]\n'
                        'quaternion = [0, 0, 0, 1]\n', "s.toml")
    with pytest.raises(InputError, match=r"object\[0\]\.quaternion: .*length > 0"):
        scene_from_toml('[[object]]\nmesh = "builtin:cube"\nquaternion = [0, 0, 0, 0]\n',
                        "s.toml")
    with pytest.raises(InputError, match=r"object\[0\]\.rotation_order"):
        scene_from_toml('[[object]]\nmesh = "builtin:cube"\nrotation_order = "XXY"\n',
                        "s.toml")
    scene = Scene()
    ball = scene.add_object("builtin:sphere", label="ball")
    with pytest.raises(InputError, match=r"^ball: scale: must be at least 1e-06"):
        ball.scale = (1.0, 0.0, 1.0)
    ball.quaternion = (0.0, 0.0, 0.0, 2.0)
    assert ball.rotation == (0.0, 0.0, 0.0)
    np.testing.assert_allclose(ball.model, np.identity(4), atol=1e-12)


def test_a_deep_hierarchy_and_a_long_cycle():
    """Two thousand nested groups place their child (no recursion limit); a cycle through
    thirty nodes is said in one short line."""
    scene = Scene()
    groups = [scene.add_group(f"g{index}", position=(0.001, 0.0, 0.0)) for index in range(2000)]
    for child, parent in zip(groups[1:], groups, strict=False):
        child.parent = parent
    ball = scene.add_object("builtin:sphere", label="ball", parent=groups[-1])
    assert scene.world_at(ball, 0.0)[0, 3] == pytest.approx(2.0)
    groups[0].parent = groups[29]
    with pytest.raises(InputError) as caught:
        scene.world_at(ball, 0.0)
    message = str(caught.value)
    assert "the parents form a cycle" in message and "(30 nodes)" in message
    assert len(message) < 300 and "\n" not in message
