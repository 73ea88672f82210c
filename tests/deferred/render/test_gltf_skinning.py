"""Skins on the GPU: a two-bone cylinder bent 90 degrees by its joints, its deformed vertices
read back from the transform feedback where the joint matrices put them, drawn there, and its
motion vectors following the bend."""

from __future__ import annotations

import numpy as np
import pytest
from gltf_files import GltfBuilder, cylinder, quaternion

from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene
from deferred.scene.skin import skin_positions
from deferred.scene.transform import quaternion_matrix

RADIUS, LENGTH = 0.2, 2.0


def bent_cylinder(tmp_path, animated: bool = False):
    """A cylinder along +Y from 0 to 2, the lower half following bone 0 (at the origin), the
    upper half bone 1 (at y = 1, turned 90 degrees about Z), blended over y in [0.8, 1.2]."""
    gltf = GltfBuilder()
    positions, normals, faces = cylinder(RADIUS, LENGTH, 24, 40)
    upper = np.clip((positions[:, 1] - 0.8) / 0.4, 0.0, 1.0)
    weights = np.stack([1.0 - upper, upper, np.zeros_like(upper), np.zeros_like(upper)], 1)
    joints = np.tile([0, 1, 0, 0], (len(positions), 1))
    primitive = gltf.primitive(positions, normals, faces, gltf.material((0.9, 0.9, 0.9, 1)),
                               JOINTS_0=joints, WEIGHTS_0=weights)
    bend = quaternion((0, 0, 1), 90)
    elbow = gltf.node(name="elbow", translation=(0, 1, 0),
                      rotation=None if animated else bend)
    shoulder = gltf.node(root=True, name="shoulder", children=[elbow])
    binds = np.stack([np.identity(4), np.linalg.inv(_translation((0, 1, 0)))])
    gltf.doc["skins"] = [{"joints": [shoulder, elbow], "name": "arm",
                          "inverseBindMatrices": gltf.accessor(
                              binds.transpose(0, 2, 1).reshape(2, 16), kind="MAT4")}]
    gltf.node(root=True, name="body", mesh=gltf.mesh(primitive), skin=0,
              translation=(5, 5, 5))  # a skinned mesh's own node does not move it
    if animated:
        gltf.animation([(elbow, "rotation", [0.0, 1.0],
                         [quaternion((0, 0, 1), 0), bend], "LINEAR")], name="bend")
    return gltf.save_glb(tmp_path / "arm.glb"), positions


def _translation(offset) -> np.ndarray:
    matrix = np.identity(4)
    matrix[:3, 3] = offset
    return matrix


def deformed(renderer, obj) -> np.ndarray:
    """The object's skinned surface as the transform feedback left it, in world space."""
    gpu = renderer.resources.gpu_mesh(obj.mesh)
    surface = np.frombuffer(gpu.surface_vbo.read(), np.float32).reshape(-1, 12)
    model = renderer.state.object_state(obj).model
    return surface[:, :3] @ model[:3, :3].T + model[:3, 3]


def test_the_bent_cylinder_is_where_the_joint_matrices_put_it(gl, tmp_path):
    path, rest = bent_cylinder(tmp_path)
    scene = load_scene(path)
    scene.size = (96, 96)
    body = scene.find("body")
    with Renderer(scene, "deferred", gl=gl) as renderer:
        renderer.render(readback=False)
        on_gpu = deformed(renderer, body)
        state = renderer.state.object_state(body)
        expected = skin_positions(rest, body.mesh.joints, body.mesh.weights,
                                  state.skin_matrices)
        expected = expected @ state.model[:3, :3].T + state.model[:3, 3]
    np.testing.assert_allclose(on_gpu, expected, atol=1e-5)
    # written out: below the blend, bone 0 leaves the vertices at rest; above it, bone 1 turns
    # them 90 degrees about Z around the elbow at (0, 1, 0)
    lower, upper = rest[:, 1] <= 0.8, rest[:, 1] >= 1.2
    np.testing.assert_allclose(on_gpu[lower], rest[lower], atol=1e-5)
    turned = (rest[upper] - [0, 1, 0]) @ quaternion_matrix(
        quaternion((0, 0, 1), 90))[:3, :3].T + [0, 1, 0]
    np.testing.assert_allclose(on_gpu[upper], turned, atol=1e-5)
    tip = on_gpu[rest[:, 1] == LENGTH]
    np.testing.assert_allclose(tip[:, 0], -1.0, atol=1e-5)  # the tip points along -X


def test_the_bent_cylinder_is_drawn_bent(gl, tmp_path):
    path, _ = bent_cylinder(tmp_path)
    scene = load_scene(path)
    scene.size = (96, 96)
    scene.camera = type(scene.camera)((-0.3, 0.8, 6.0), (-0.3, 0.8, 0.0), (0.0, 1.0, 0.0),
                                      40.0, 1.0, 20.0)
    with Renderer(scene, "deferred", gl=gl) as renderer:
        image = renderer.render(hdr=True).hdr
        camera = renderer.state.camera

    def pixel(point):
        clip = camera.projection(1.0) @ camera.view() @ np.append(point, 1.0)
        ndc = clip[:3] / clip[3]
        return int((ndc[0] + 1) / 2 * 96), int((1 - ndc[1]) / 2 * 96)

    lit = image[..., :3].max(axis=-1) > 0.05
    for point in ((0.0, 0.4, 0.0), (-0.6, 1.0, 0.0)):  # the upright part, the bent part
        x, y = pixel(point)
        assert lit[y, x], point
    x, y = pixel((0.0, 1.8, 0.0))  # where the tip would be unbent: empty
    assert not lit[y, x]


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_an_animated_skin_moves_and_its_motion_vectors_follow(gl, tmp_path, pipeline):
    path, rest = bent_cylinder(tmp_path, animated=True)
    scene = load_scene(path)
    scene.size = (96, 96)
    scene.effects.append(__import__("deferred.interfaces.registry", fromlist=["effects"])
                         .effects.get("taa").from_dict({}, "taa"))
    scene.camera = type(scene.camera)((-0.3, 0.8, 6.0), (-0.3, 0.8, 0.0), (0.0, 1.0, 0.0),
                                      40.0, 1.0, 20.0)
    body = scene.find("body")
    with Renderer(scene, pipeline, gl=gl) as renderer:
        renderer.render(readback=False, time=0.5)
        half = deformed(renderer, body)
        renderer.render(readback=False, time=0.5 + 1 / 24)
        motion = renderer.targets.read("motion")
    tip = half[rest[:, 1] == LENGTH].mean(axis=0)
    expected = (np.array([0, 1, 0]) + quaternion_matrix(quaternion((0, 0, 1), 45))[:3, :3]
                @ [0, 1, 0])
    np.testing.assert_allclose(tip, expected, atol=0.02 + RADIUS)
    # the moving upper half has motion; the still lower half (bone 0) has none
    moving = np.abs(motion[..., :2]).max(axis=-1)
    assert moving.max() > 0.3
