"""A glTF asset placed in a scene: its nodes as the scene graph's groups and objects, its
primitives drawn with their materials, its cameras, lights, skins and an animation.

- :func:`add_gltf` puts the asset's default scene (or one node's subtree) under a parent: every
  node a :class:`~deferred.scene.nodes.SceneNode` with its local placement and its parent, a
  node with one primitive a :class:`~deferred.scene.objects.SceneObject` itself, a node with
  several a group whose objects are labelled ``<node>/<k>``; a material given overrides every
  primitive's.
- :func:`fill_scene` makes ``deferred render model.glb``'s scene: the asset, the file's camera
  (the first, or the one named) or one framing the scene's bounds, the file's lights or, where
  it has none, the built-in sky's ``environment`` light, and the first animation (or the one
  named).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from deferred.errors import InputError
from deferred.interfaces import registry
from deferred.interfaces.light import Light
from deferred.interfaces.material import Material
from deferred.scene.camera import MAX_DEPTH_RANGE, Camera
from deferred.scene.gltf.animation import GltfAnimation
from deferred.scene.gltf.asset import GltfAsset, GltfNode, read_gltf
from deferred.scene.gltf.materials import DEFAULT_MATERIAL, make_material
from deferred.scene.nodes import SceneNode
from deferred.scene.objects import SceneObject
from deferred.scene.skin import Skin, skin_positions

NO_ANIMATION = "none"


@dataclass
class PlacedAsset:
    """What :func:`add_gltf` made: each placed node's label by node index, the objects, and
    the nodes carrying a camera (in the file's order)."""

    asset: GltfAsset
    labels: dict[int, str] = field(default_factory=dict)
    nodes: dict[int, SceneNode] = field(default_factory=dict)
    objects: list[SceneObject] = field(default_factory=list)
    cameras: list[tuple[int, GltfNode]] = field(default_factory=list)  # (camera, node)
    skinned: list[tuple[SceneObject, int]] = field(default_factory=list)  # (object, skin)
    lights: list[Light] = field(default_factory=list)
    animation: GltfAnimation | None = None


def add_gltf(scene: Any, asset: GltfAsset, parent: SceneNode | str | None = None,
             material: Material | None = None, node: str | None = None,
             where: str | None = None, prefix: str = "") -> PlacedAsset:
    """Place ``asset`` in ``scene`` (a :class:`~deferred.scene.scene.Scene`) under ``parent``:
    see the module documentation. ``node`` picks one node (by name) and its subtree;
    ``prefix`` starts every label; ``where`` names the scene key in errors."""
    roots = asset.roots
    if node is not None:
        found = asset.node_named(node)
        if found is None:
            names = [n.name for n in asset.nodes if n.name][:10]
            raise InputError(f"{asset.name} has no node named {node[:80]!r} (its nodes: "
                             f"{', '.join(names) or 'none named'})", where or asset.name)
        roots = [found.index]
    placed = PlacedAsset(asset)
    taken = {n.label for n in scene.nodes()}
    materials: dict[int | None, Material] = {}
    for index in asset.subtree(roots):
        gltf_node = asset.nodes[index]
        label = _label(prefix, gltf_node, taken)
        parent_node = placed.nodes.get(asset.parents.get(index), parent) \
            if index not in roots else parent
        primitives = asset.meshes.get(gltf_node.mesh, []) if gltf_node.mesh is not None else []
        if len(primitives) == 1:
            made: SceneNode = _object(scene, asset, label, primitives[0], gltf_node, parent_node,
                                      material, materials, placed)
        else:
            made = SceneNode(label, gltf_node.transform, parent=parent_node,
                             where=f"{asset.name}: {gltf_node.where}")
            scene.groups.append(made)
            for k, primitive in enumerate(primitives):
                _object(scene, asset, _label(f"{label}/", None, taken, str(k)), primitive, None,
                        made, material, materials, placed)
        if gltf_node.matrix is not None:
            made.model = gltf_node.matrix
        placed.labels[index] = label
        placed.nodes[index] = made
        if gltf_node.camera is not None:
            placed.cameras.append((gltf_node.camera, gltf_node))
        if gltf_node.light is not None:
            placed.lights.append(_light(scene, asset, gltf_node.light, made))
    _bind_skins(asset, placed)
    scene.touch()
    return placed


def _label(prefix: str, node: GltfNode | None, taken: set[str], stem: str | None = None) -> str:
    base = prefix + (stem if stem is not None else node.name or f"node{node.index}")
    label = base
    if label in taken:
        label = f"{base}#{node.index}" if node is not None else f"{base}#"
        count = 1
        while label in taken:
            count += 1
            label = f"{base}#{count}"
    taken.add(label)
    return label


def _object(scene: Any, asset: GltfAsset, label: str, primitive, gltf_node: GltfNode | None,
            parent: SceneNode | str | None, material: Material | None,
            materials: dict[int | None, Material], placed: PlacedAsset) -> SceneObject:
    if material is None:
        if primitive.material not in materials:
            spec = DEFAULT_MATERIAL if primitive.material is None else \
                asset.materials[primitive.material]
            materials[primitive.material] = make_material(spec, asset.document)
        material = materials[primitive.material]
    mesh = primitive.mesh
    if mesh.joints is not None:  # each skinned object deforms its own copy
        mesh = replace(mesh)
    transform = gltf_node.transform if gltf_node is not None else None
    obj = SceneObject(label, mesh, material, transform=transform, parent=parent,
                      where=f"{asset.name}: {primitive.where}")
    if gltf_node is not None and gltf_node.skin is not None and mesh.joints is not None:
        placed.skinned.append((obj, gltf_node.skin))
    scene.objects.append(obj)
    placed.objects.append(obj)
    return obj


def _bind_skins(asset: GltfAsset, placed: PlacedAsset) -> None:
    """Each skinned object's skin, its joints the placed nodes (a joint outside the placed
    subtree is an error naming the skin)."""
    for obj, index in placed.skinned:
        skin = asset.skins[index]
        missing = [joint for joint in skin.joints if joint not in placed.nodes]
        if missing:
            raise InputError(f"skins[{index}]'s joint nodes[{missing[0]}] is not among the "
                             "nodes placed (pick a node above the skeleton)",
                             f"{asset.name}: skins[{index}].joints")
        obj.skin = Skin(tuple(placed.nodes[j] for j in skin.joints), skin.inverse_binds,
                        skin.name)


def _light(scene: Any, asset: GltfAsset, index: int, node: SceneNode) -> Light:
    """A ``KHR_lights_punctual`` light as the framework's, placed by its node (it shines
    along the node's -Z)."""
    light = asset.lights[index]
    values: dict[str, Any] = {"color": light.color, "intensity": light.intensity}
    if light.kind == "directional":
        values["direction"] = (0.0, 0.0, -1.0)
    else:
        values["position"] = (0.0, 0.0, 0.0)
        # unbounded: where the light falls to a thousandth (inverse square)
        values["radius"] = light.range or max(1.0, math.sqrt(light.intensity * 1000.0))
        if light.kind == "spot":
            values.update(direction=(0.0, 0.0, -1.0), inner_angle=min(light.inner, 89.0),
                          outer_angle=max(light.outer, min(light.inner, 89.0) + 1e-3))
    made = registry.lights.get(light.kind).from_dict(
        values, f"{asset.name}: extensions.KHR_lights_punctual.lights[{index}]")
    made.parent = node
    scene.lights.append(made)
    name = light.name
    # a track may name it (light:NAME) where the name may be a light's (Scene.add_light's
    # rule: printable, not a number, not taken); else the light has no name
    if name.isprintable() and not name.isdigit() and len(name) <= 1000 and \
            name not in scene.light_names:
        scene.light_names[name] = made
    return made


def choose_animation(asset: GltfAsset, choice: str | int | None,
                     where: str = "--animation") -> GltfAnimation | None:
    """The animation ``choice`` names (a name or an index), the first where None, none for
    ``"none"``; ``InputError`` naming the ones there are."""
    animations = asset.animations
    if choice == NO_ANIMATION or not animations and choice is None:
        return None
    if choice is None:
        return animations[0]
    for animation in animations:
        if animation.name == choice:
            return animation
    text = str(choice)
    if text.isdigit() and int(text) < len(animations):
        return animations[int(text)]
    have = ", ".join(f"{i}: {a.name[:40]}" for i, a in enumerate(animations[:10])) or "none"
    raise InputError(f"{asset.name} has no animation {text[:80]!r} (its animations: {have})",
                     where)


def animate(placed: PlacedAsset, animation: GltfAnimation | None) -> None:
    """Put ``animation``'s tracks on the placed nodes it moves (morph weights warned)."""
    placed.animation = animation
    if animation is None:
        return
    for index, track in animation.tracks(placed.labels).items():
        node = placed.nodes[index]
        node.tracks = (*node.tracks, track)
    if animation.morph_nodes:
        names = ", ".join(placed.labels.get(i, f"nodes[{i}]") for i in animation.morph_nodes)
        placed.asset.document.warn(f"{animation.where} ({animation.name}) moves morph target "
                                   f"weights of {names}: morph targets are not drawn")


def scene_bounds(scene: Any, time: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(least, greatest) world corner of the scene's objects at ``time`` (skinned ones as
    their joints pose them)."""
    lows, highs = [], []
    for obj in scene.objects:
        world = scene.world_at(obj, time)
        mesh = obj.mesh
        if getattr(obj, "skin", None) is not None:
            joint_worlds = [scene.world_at(joint, time) for joint in obj.skin.joints]
            points = skin_positions(mesh.positions, mesh.joints, mesh.weights,
                                    obj.skin.matrices(world, joint_worlds))
        else:
            low, high = mesh.bounds()
            points = np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1])
                               for z in (low[2], high[2])], np.float64)
        moved = points @ world[:3, :3].T + world[:3, 3]
        lows.append(moved.min(axis=0))
        highs.append(moved.max(axis=0))
    if not lows:
        return np.full(3, -1.0), np.full(3, 1.0)
    return np.min(lows, axis=0), np.max(highs, axis=0)


def framing_camera(scene: Any, fov: float = 40.0) -> Camera:
    """A camera seeing the whole scene: looking at its bounds' centre from the front (+Z),
    a little above and to the right, far enough for the bounding sphere to fit."""
    low, high = scene_bounds(scene)
    centre = (low + high) / 2.0
    radius = max(float(np.linalg.norm(high - low)) / 2.0, 1e-3)
    aspect = scene.size[0] / scene.size[1]
    half = math.radians(fov) / 2.0
    half = min(half, math.atan(math.tan(half) * aspect))
    distance = radius / math.sin(half) * 1.05
    direction = np.array([0.45, 0.35, 1.0])
    direction /= np.linalg.norm(direction)
    position = centre + direction * distance
    near = max(distance - radius * 1.5, radius * 1e-3)
    far = min(distance + radius * 2.0, near * MAX_DEPTH_RANGE / 10)
    return Camera(tuple(float(v) for v in position), tuple(float(v) for v in centre),
                  (0.0, 1.0, 0.0), fov, near, far)


def file_camera(scene: Any, placed: PlacedAsset, choice: str | None) -> Camera | None:
    """The camera of the file ``choice`` names (a camera's or its node's name, or an index),
    the first where None; None where the file has none (``InputError`` for a name it lacks)."""
    cameras = placed.cameras
    asset = placed.asset
    if not cameras:
        if choice is not None:
            raise InputError(f"{asset.name} has no camera", "--camera")
        return None
    chosen = cameras[0] if choice is None else next(
        (c for c in cameras if choice in (asset.cameras[c[0]].name, c[1].name)), None)
    if chosen is None and choice.isdigit() and int(choice) < len(cameras):
        chosen = cameras[int(choice)]
    if chosen is None:
        have = ", ".join(asset.cameras[i].name[:40] for i, _ in cameras[:10])
        raise InputError(f"{asset.name} has no camera {choice[:80]!r} (its cameras: {have})",
                         "--camera")
    camera = asset.cameras[chosen[0]]
    far = camera.far
    if far is None:  # infinite: far enough for the whole scene
        low, high = scene_bounds(scene)
        far = max(float(np.linalg.norm(high - low)) * 4.0, camera.near * 100.0)
    far = min(far, camera.near * MAX_DEPTH_RANGE / 10)
    if camera.aspect is not None:
        scene.size = (max(16, int(round(scene.size[1] * camera.aspect))), scene.size[1])
    return Camera((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0), camera.fov,
                  camera.near, far, parent=placed.nodes[chosen[1].index])


def default_lights(scene: Any) -> None:
    """The light of a file without lights: an ``environment`` light of the built-in sky."""
    scene.lights.append(registry.lights.get("environment").from_dict({}, "default light"))


def fill_scene(scene: Any, path: Path, camera: str | None = None,
               animation: str | int | None = None) -> Any:
    """``deferred render model.glb``'s scene (see the module documentation), made in the
    empty ``scene`` (a :class:`~deferred.scene.scene.Scene`)."""
    asset = read_gltf(path)
    placed = add_gltf(scene, asset)
    animate(placed, choose_animation(asset, animation))
    chosen = file_camera(scene, placed, camera)
    scene.camera = chosen or framing_camera(scene)
    if not placed.lights:
        default_lights(scene)
    return scene


def flat_mesh(path: Path, where: str | None = None) -> Any:
    """The glTF file's default scene as one mesh in its root's space, at rest (each
    primitive moved by its node's world matrix): a glTF file where one mesh is asked for
    (``Scene.add_object("model.glb")``)."""
    from deferred.gl.meshes import MeshData

    asset = read_gltf(path, where)
    worlds: dict[int, np.ndarray] = {}
    parts: dict[str, list[np.ndarray]] = {key: [] for key in
                                          ("positions", "normals", "uvs", "tangents",
                                           "binormals", "comb", "indices")}
    offset = 0
    for index in asset.subtree():
        node = asset.nodes[index]
        local = node.matrix if node.matrix is not None else node.transform.matrix()
        parent = asset.parents.get(index)
        world = worlds[index] = local if parent is None else worlds[parent] @ local
        linear = world[:3, :3]
        normal_matrix = np.linalg.inv(linear).T
        for primitive in asset.meshes.get(node.mesh, []) if node.mesh is not None else []:
            mesh = primitive.mesh
            parts["positions"].append(mesh.positions @ linear.T + world[:3, 3])
            for key, matrix in (("normals", normal_matrix), ("tangents", linear),
                                ("binormals", linear)):
                turned = getattr(mesh, key) @ matrix.T
                parts[key].append(turned / np.maximum(np.linalg.norm(turned, axis=1,
                                                                     keepdims=True), 1e-12))
            parts["uvs"].append(mesh.uvs)
            parts["comb"].append(mesh.comb)
            parts["indices"].append(mesh.indices.astype(np.int64) + offset)
            offset += mesh.vertex_count
    if not offset:
        raise InputError(f"{asset.name} has no triangles in its default scene",
                         where or asset.name)
    joined = {key: np.concatenate(values).astype(np.float32 if key != "indices" else np.uint32)
              for key, values in parts.items()}
    return MeshData(name=path.name, sources=(path, *asset.document.sources), **joined)
