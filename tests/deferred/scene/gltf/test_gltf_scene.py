"""A glTF file as a scene: a two-level node hierarchy seen through the file's camera and lit by
its punctual lights, each node where the glTF transforms put it, each primitive in its own
colour, forward and deferred alike."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import psnr
from gltf_files import GltfBuilder, quaternion, sphere

from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene, scene_from_toml
from deferred.scene.objects import SceneObject

RED, GREEN, BLUE, MAGENTA = (1, 0, 0, 1), (0, 1, 0, 1), (0, 0, 1, 1), (1, 0, 1, 1)


def trs(translation=(0, 0, 0), rotation=(0, 0, 0, 1), scale=(1, 1, 1)) -> np.ndarray:
    """The glTF node matrix T R S, written out."""
    x, y, z, w = rotation
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.identity(4)
    m[:3, :3] = r * np.asarray(scale)
    m[:3, 3] = translation
    return m


RIG = dict(translation=(-0.7, -0.3, 0.0), rotation=quaternion((0, 0, 1), 30))
ARM = dict(translation=(1.1, 0.2, 0.0), rotation=quaternion((0, 0, 1), -20),
           scale=(1.4, 0.6, 1.0))
LEAF = dict(translation=(0.2, 1.6, 0.3))


def hierarchy_file(path, suffix=".glb"):
    """rig (red sphere) -> arm (green sphere) -> leaf (a mesh of two primitives: blue and
    magenta spheres either side of it); a camera node 6 units in front looking down -Z, a
    directional light along the view and a point light beside it."""
    gltf = GltfBuilder()
    small = sphere(0.18, 48, 24)
    mesh = {}
    for name, color in (("red", RED), ("green", GREEN)):
        positions, normals, uvs, faces = small
        mesh[name] = gltf.mesh(gltf.primitive(positions, normals, faces,
                                              gltf.material(color, name=name)), name=name)
    left, right = sphere(0.12, 48, 24, (-0.25, 0, 0)), sphere(0.12, 48, 24, (0.25, 0, 0))
    mesh["pair"] = gltf.mesh(
        gltf.primitive(left[0], left[1], left[3], gltf.material(BLUE, name="blue")),
        gltf.primitive(right[0], right[1], right[3], gltf.material(MAGENTA, name="magenta")),
        name="pair")
    leaf = gltf.node(name="leaf", mesh=mesh["pair"], **LEAF)
    arm = gltf.node(name="arm", mesh=mesh["green"], children=[leaf], **ARM)
    gltf.node(root=True, name="rig", mesh=mesh["red"], children=[arm], **RIG)
    camera = gltf.camera(math.radians(30.0), 0.5, 50.0, aspect=1.0, name="front")
    gltf.node(root=True, name="eye", camera=camera, translation=(0.0, 0.0, 6.0))
    sun = gltf.light(type="directional", intensity=1.5, color=[1, 1, 1], name="sun")
    gltf.node(root=True, name="sun", translation=(0, 0, 5), extensions={
        "KHR_lights_punctual": {"light": sun}})
    lamp = gltf.light(type="point", intensity=2.0, range=20.0, name="lamp")
    gltf.node(root=True, name="lamp", translation=(3, 3, 4), extensions={
        "KHR_lights_punctual": {"light": lamp}})
    out = path / f"hierarchy{suffix}"
    return gltf.save_glb(out) if suffix == ".glb" else gltf.save_gltf(out)


def project(camera, size, point) -> np.ndarray:
    """The pixel (x from the left, y from the top, continuous) ``point`` lands on."""
    clip = camera.projection(size[0] / size[1]) @ camera.view() @ np.append(point, 1.0)
    ndc = clip[:3] / clip[3]
    return np.array([(ndc[0] + 1) / 2 * size[0], (1 - ndc[1]) / 2 * size[1]])


def mask(image: np.ndarray, color) -> np.ndarray:
    on = [c for c in range(3) if color[c] > 0]
    off = [c for c in range(3) if color[c] == 0]
    return (image[..., on].min(axis=-1) > 0.15) & (image[..., off].max(axis=-1) < 0.04)


def test_the_file_is_read_as_a_scene_graph(tmp_path):
    scene = load_scene(hierarchy_file(tmp_path))
    labels = {node.label: node for node in scene.nodes()}
    assert {"rig", "arm", "leaf", "leaf/0", "leaf/1", "eye", "sun", "lamp"} <= set(labels)
    assert labels["arm"].parent is labels["rig"] and labels["leaf"].parent is labels["arm"]
    assert isinstance(labels["rig"], SceneObject) and not isinstance(labels["leaf"], SceneObject)
    assert labels["leaf/0"].parent is labels["leaf"]
    assert [type(light).name for light in scene.lights] == ["directional", "point"]
    assert scene.camera.parent is labels["eye"] and scene.camera.fov == pytest.approx(30.0)
    assert scene.size == (720, 720)  # the camera's aspect ratio
    # each primitive its own material
    colours = {obj.label: obj.material.params for obj in scene.objects}
    assert len({id(p) for p in colours.values()}) == 4


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_each_node_and_primitive_is_where_the_gltf_transforms_put_it(gl, tmp_path, suffix):
    scene = load_scene(hierarchy_file(tmp_path, suffix))
    scene.size = (192, 192)
    rig = trs(**RIG)
    arm = rig @ trs(**ARM)
    leaf = arm @ trs(**LEAF)
    centres = {"rig": rig[:3, 3], "arm": arm[:3, 3],
               "leaf/0": (leaf @ [-0.25, 0, 0, 1])[:3], "leaf/1": (leaf @ [0.25, 0, 0, 1])[:3]}
    colours = {"rig": RED, "arm": GREEN, "leaf/0": BLUE, "leaf/1": MAGENTA}
    with Renderer(scene, "deferred", gl=gl) as renderer:
        image = renderer.render(hdr=True).hdr
        state = renderer.state
        np.testing.assert_allclose(state.object_state(scene.find("leaf/1")).model,
                                   leaf, atol=1e-6)
        camera = state.camera
    np.testing.assert_allclose(camera.position, (0, 0, 6), atol=1e-9)
    for label, centre in centres.items():
        drawn = mask(image, colours[label])
        assert drawn.sum() > 30, f"{label} is not drawn in its colour"
        rows, columns = np.nonzero(drawn)
        seen = np.array([columns.mean() + 0.5, rows.mean() + 0.5])
        predicted = project(camera, scene.size, centre)
        assert np.linalg.norm(seen - predicted) < 1.0, (label, seen, predicted)


@pytest.mark.slow
def test_forward_and_deferred_agree_on_the_file(gl, tmp_path):
    path = hierarchy_file(tmp_path)
    images = []
    for pipeline in ("deferred", "forward"):
        scene = load_scene(path)
        scene.size = (160, 160)
        with Renderer(scene, pipeline, gl=gl) as renderer:
            images.append(renderer.render(hdr=True).image[..., :3] / 255.0)
    assert psnr(*images) >= 40.0


def test_a_toml_object_keeps_the_files_nodes_or_picks_one_and_overrides_materials(tmp_path):
    hierarchy_file(tmp_path)
    scene = scene_from_toml("""
[[object]]
name = "whole"
mesh = "hierarchy.glb"
position = [0, 0, -3]

[[object]]
name = "one"
mesh = "hierarchy.glb"
node = "arm"
material = "standard"
params = { color = [0.2, 0.3, 0.4] }
""", "s.toml", tmp_path)
    whole, one = scene.find("whole"), scene.find("one")
    assert scene.find("whole/leaf/1").parent is scene.find("whole/leaf")
    assert scene.find("whole/rig").parent is whole
    assert scene.find("one/arm").parent is one
    with pytest.raises(Exception, match="no object or group named 'one/rig'"):
        scene.find("one/rig")
    overridden = [obj for obj in scene.objects if obj.label.startswith("one/")]
    assert {obj.material.params.color for obj in overridden} == {(0.2, 0.3, 0.4)}
    assert len(overridden) == 3  # arm, leaf's two primitives
    # the file's lights come along, hung from their nodes under the object
    assert len(scene.lights) == 2
    np.testing.assert_allclose(scene.world_at(scene.find("whole/rig"), 0.0),
                               trs((0, 0, -3)) @ trs(**RIG), atol=1e-12)


def test_without_a_camera_one_frames_the_scene_and_a_default_light_shines(tmp_path, gl):
    gltf = GltfBuilder()
    positions, normals, uvs, faces = sphere(3.0, 32, 16)
    gltf.node(root=True, mesh=gltf.mesh(gltf.primitive(positions, normals, faces,
                                                       gltf.material(GREEN))),
              translation=(100, 50, 0))
    scene = load_scene(gltf.save_glb(tmp_path / "far.glb"))
    scene.size = (96, 64)
    assert scene.camera.parent is None and scene.lights
    np.testing.assert_allclose(scene.camera.target, (100, 50, 0), atol=1e-6)
    with Renderer(scene, "deferred", gl=gl) as renderer:
        image = renderer.render(hdr=True).hdr
    drawn = image[..., 1] > 0.1
    rows, columns = np.nonzero(drawn)
    # the whole sphere in view, not cut by an edge, and filling a good part of it
    assert rows.min() > 0 and rows.max() < 63 and columns.min() > 0 and columns.max() < 95
    assert drawn.mean() > 0.1  # the box's corners are in view too


def test_camera_and_animation_choices_are_checked(tmp_path):
    path = hierarchy_file(tmp_path)
    assert load_scene(path, camera="front").camera.fov == pytest.approx(30.0)
    assert load_scene(path, camera="eye").camera.parent.label == "eye"
    with pytest.raises(Exception, match=r"--camera: hierarchy.glb has no camera 'side' \(its "
                                        r"cameras: front\)"):
        load_scene(path, camera="side")
    with pytest.raises(Exception, match="--animation: hierarchy.glb has no animation 'walk'"):
        load_scene(path, animation="walk")
    with pytest.raises(Exception, match="--camera chooses among a glTF file's"):
        load_scene(None, camera="front")
