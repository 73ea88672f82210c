"""glTF animations on the scene timeline: a node at time t where its channel puts it, for each
interpolation (STEP, LINEAR with quaternion slerp, CUBICSPLINE), drawn there too."""

from __future__ import annotations

import numpy as np
import pytest
from gltf_files import GltfBuilder, quaternion, sphere

from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene
from deferred.scene.transform import quaternion_matrix

TIMES = [0.0, 1.0, 2.5]
POSITIONS = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 3.0, -1.0]]
# CUBICSPLINE keys: (in-tangent, value, out-tangent) each
CUBIC = [[[0, 0, 0], [0, 0, 0], [1, 2, 0]],
         [[-1, 0, 0], [2, 0, 0], [0, 3, 1]],
         [[0, 1, 0], [2, 3, -1], [0, 0, 0]]]


def moving_file(tmp_path, interpolation: str, path="translation", values=None, name="a.glb"):
    gltf = GltfBuilder()
    positions, normals, uvs, faces = sphere(0.2, 24, 12)
    mover = gltf.node(root=True, name="mover", mesh=gltf.mesh(gltf.primitive(
        positions, normals, faces, gltf.material((1, 0, 0, 1)))),
        children=[gltf.node(name="child", translation=(0, 1, 0))])
    if values is None:
        values = np.array(CUBIC if interpolation == "CUBICSPLINE" else POSITIONS, float)
    values = np.asarray(values, float).reshape(-1, np.asarray(values).shape[-1])
    gltf.animation([(mover, path, TIMES, values, interpolation)], name=f"{interpolation}")
    gltf.animation([(mover, "translation", [0.0, 1.0], [[0, 0, 0], [0, -5, 0]], "LINEAR")],
                   name="drop")
    return gltf.save_glb(tmp_path / name)


def hermite(p0, m0, p1, m1, span, s):
    """The glTF cubic spline (appendix C) written out."""
    return ((2 * s**3 - 3 * s**2 + 1) * np.asarray(p0) + span * (s**3 - 2 * s**2 + s) *
            np.asarray(m0) + (-2 * s**3 + 3 * s**2) * np.asarray(p1) +
            span * (s**3 - s**2) * np.asarray(m1))


@pytest.mark.parametrize("interpolation, time, expected", [
    ("LINEAR", 0.5, [1.0, 0.0, 0.0]),
    ("LINEAR", 1.75, [2.0, 1.5, -0.5]),
    ("LINEAR", 9.0, POSITIONS[-1]),
    ("STEP", 0.99, POSITIONS[0]),
    ("STEP", 1.0, POSITIONS[1]),
    ("STEP", 2.4, POSITIONS[1]),
    ("CUBICSPLINE", 0.25, hermite(CUBIC[0][1], CUBIC[0][2], CUBIC[1][1], CUBIC[1][0], 1.0,
                                  0.25)),
    ("CUBICSPLINE", 1.6, hermite(CUBIC[1][1], CUBIC[1][2], CUBIC[2][1], CUBIC[2][0], 1.5,
                                 0.4)),
])
def test_a_translation_channel_puts_the_node_where_it_says(tmp_path, interpolation, time,
                                                           expected):
    scene = load_scene(moving_file(tmp_path, interpolation))
    mover, child = scene.find("mover"), scene.find("child")
    np.testing.assert_allclose(scene.world_at(mover, time)[:3, 3], expected, atol=1e-9)
    # the child moves with it
    np.testing.assert_allclose(scene.world_at(child, time)[:3, 3],
                               np.add(expected, [0, 1, 0]), atol=1e-9)


def test_rotations_turn_by_slerp_along_the_shorter_arc(tmp_path):
    keys = [quaternion((0, 1, 0), 0), quaternion((0, 1, 0), 90), quaternion((0, 1, 0), 170)]
    keys[2] = [-v for v in keys[2]]  # the same rotation: slerp takes the shorter arc anyway
    scene = load_scene(moving_file(tmp_path, "LINEAR", "rotation", keys))
    mover = scene.find("mover")
    turned = scene.world_at(mover, 0.5)[:3, :3]
    np.testing.assert_allclose(turned, quaternion_matrix(quaternion((0, 1, 0), 45))[:3, :3],
                               atol=1e-9)
    between = scene.world_at(mover, 1.0 + 1.5 * 0.5)[:3, :3]
    np.testing.assert_allclose(between, quaternion_matrix(quaternion((0, 1, 0), 130))[:3, :3],
                               atol=1e-9)


def test_a_cubic_rotation_is_normalised(tmp_path):
    value = [quaternion((1, 0, 0), 0), quaternion((1, 0, 0), 60), quaternion((1, 0, 0), 120)]
    zero = [0.0, 0.0, 0.0, 0.0]
    keys = [[zero, v, zero] for v in value]
    scene = load_scene(moving_file(tmp_path, "CUBICSPLINE", "rotation", keys))
    world = scene.world_at(scene.find("mover"), 0.5)
    # Hermite between the keys with zero tangents is the keys' average at s = 1/2, normalised
    expected = np.add(value[0], value[1]) / 2
    expected /= np.linalg.norm(expected)
    np.testing.assert_allclose(world[:3, :3], quaternion_matrix(expected)[:3, :3], atol=1e-9)
    assert abs(np.linalg.det(world[:3, :3]) - 1.0) < 1e-9


def test_scale_channels(tmp_path):
    scene = load_scene(moving_file(tmp_path, "LINEAR", "scale",
                                   [[1, 1, 1], [2, 3, 4], [0, 0, 0]]))
    world = scene.world_at(scene.find("mover"), 0.5)
    np.testing.assert_allclose(np.linalg.norm(world[:3, :3], axis=0), [1.5, 2.0, 2.5])
    # a scale of zero (glTF's way to hide a node) is drawn vanishingly small, not singular
    assert np.all(np.isfinite(np.linalg.inv(scene.world_at(scene.find("mover"), 9.0))))


def test_the_animation_is_chosen_by_name_or_index_or_none(tmp_path):
    path = moving_file(tmp_path, "LINEAR")
    at = {}
    for choice in (None, "drop", "1", "none"):
        scene = load_scene(path, animation=choice)
        at[choice] = scene.world_at(scene.find("mover"), 1.0)[:3, 3]
    np.testing.assert_allclose(at[None], POSITIONS[1])
    np.testing.assert_allclose(at["drop"], [0, -5, 0])
    np.testing.assert_allclose(at["1"], [0, -5, 0])
    np.testing.assert_allclose(at["none"], [0, 0, 0])


def test_the_animated_node_is_drawn_where_the_channel_puts_it(gl, tmp_path):
    scene = load_scene(moving_file(tmp_path, "LINEAR"), animation="LINEAR")
    scene.size = (128, 96)
    scene.camera = type(scene.camera)((1.0, 1.0, 8.0), (1.0, 1.0, 0.0), (0.0, 1.0, 0.0), 40.0,
                                      0.5, 50.0)
    with Renderer(scene, "deferred", gl=gl) as renderer:
        for time, expected in ((0.5, [1.0, 0.0, 0.0]), (1.75, [2.0, 1.5, -0.5])):
            image = renderer.render(hdr=True, time=time).hdr
            drawn = (image[..., 0] > 0.1) & (image[..., 1] < 0.05)
            rows, columns = np.nonzero(drawn)
            seen = np.array([columns.mean() + 0.5, rows.mean() + 0.5])
            camera = renderer.state.camera
            clip = camera.projection(128 / 96) @ camera.view() @ np.append(expected, 1.0)
            ndc = clip[:3] / clip[3]
            predicted = np.array([(ndc[0] + 1) / 2 * 128, (1 - ndc[1]) / 2 * 96])
            assert np.linalg.norm(seen - predicted) < 1.0, (time, seen, predicted)


def test_bad_channels_are_named(tmp_path):
    from deferred.errors import InputError

    with pytest.raises(InputError, match=r"a.glb: accessors\[\d+\]: 5 values for 3 keys \(3 "
                                         r"a key: in-tangent, value, out-tangent\)"):
        load_scene(moving_file(tmp_path, "CUBICSPLINE", values=np.zeros((5, 3))))
    with pytest.raises(InputError, match=r"animations\[0\]\.samplers\[0\]\.interpolation: "
                                         r"unknown interpolation 'SMOOTH'"):
        load_scene(moving_file(tmp_path, "SMOOTH", values=np.zeros((3, 3)), name="b.glb"))
