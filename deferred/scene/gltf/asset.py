"""A glTF file read into what the framework builds a scene from (:class:`GltfAsset`): the
default scene's node tree (each node's local placement, its mesh's primitives, camera, light and
skin), the materials as ``pbr`` values, the cameras, the ``KHR_lights_punctual`` lights, the
skins and the animations. The node graph is checked to be a forest (a node with two parents or a
cycle is an error naming the JSON path) before anything is built from it."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from deferred.scene.gltf.accessors import read_accessor
from deferred.scene.gltf.animation import GltfAnimation, read_animation
from deferred.scene.gltf.document import GltfDocument, open_gltf
from deferred.scene.gltf.images import ImageFiles
from deferred.scene.gltf.materials import GltfMaterial, read_material
from deferred.scene.gltf.primitives import GltfPrimitive, read_primitives
from deferred.scene.transform import MIN_SCALE, Transform


@dataclass
class GltfNode:
    """A node: its index, name, local placement (``transform``; a matrix node's is its
    decomposition and ``matrix`` the matrix itself), children, and what it carries."""

    index: int
    name: str | None
    transform: Transform
    matrix: np.ndarray | None
    children: list[int]
    mesh: int | None = None
    camera: int | None = None
    light: int | None = None
    skin: int | None = None

    @property
    def where(self) -> str:
        return f"nodes[{self.index}]"


@dataclass
class GltfCamera:
    """A camera: vertical field of view in degrees, its aspect ratio (None: the image's),
    near and far (None: infinite), and its type (``orthographic`` is drawn as perspective)."""

    name: str
    kind: str
    fov: float
    aspect: float | None
    near: float
    far: float | None


@dataclass
class GltfLight:
    """A ``KHR_lights_punctual`` light: type, colour, intensity (candela or lux), range (None:
    unbounded) and a spot's cone half-angles in degrees."""

    name: str
    kind: str
    color: tuple[float, float, float]
    intensity: float
    range: float | None
    inner: float = 0.0
    outer: float = 45.0


@dataclass
class GltfSkin:
    """A skin: its joints (node indices) and their inverse bind matrices (J, 4, 4)."""

    name: str
    joints: list[int]
    inverse_binds: np.ndarray


@dataclass
class GltfAsset:
    """Everything the framework reads of a glTF file (see the module documentation)."""

    document: GltfDocument
    nodes: list[GltfNode]
    roots: list[int]
    meshes: dict[int, list[GltfPrimitive]]
    materials: list[GltfMaterial]
    cameras: list[GltfCamera]
    lights: list[GltfLight]
    skins: list[GltfSkin]
    animations: list[GltfAnimation]
    parents: dict[int, int] = field(default_factory=dict)

    @property
    def path(self) -> Path:
        return self.document.path

    @property
    def name(self) -> str:
        return self.document.name

    def subtree(self, roots: list[int] | None = None) -> list[int]:
        """The nodes under ``roots`` (the scene's by default), parents before children."""
        order, stack = [], list(reversed(self.roots if roots is None else roots))
        while stack:
            index = stack.pop()
            order.append(index)
            stack.extend(reversed(self.nodes[index].children))
        return order

    def node_named(self, name: str) -> GltfNode | None:
        return next((node for node in self.nodes if node.name == name), None)


def read_gltf(path: Path, where: str | None = None) -> GltfAsset:
    """Read the glTF file ``path``: every problem an ``InputError`` naming the file and the
    JSON path (``where``, a scene key, said first where given)."""
    document = open_gltf(path, where)
    try:
        return _read(document)
    except Exception as exc:
        from deferred.errors import InputError

        if where is None or not isinstance(exc, InputError):
            raise
        raise InputError(str(exc), where) from None


def _read(document: GltfDocument) -> GltfAsset:
    gltf = document.gltf
    nodes = [_node(document, index, raw) for index, raw in
             enumerate(document.raw.get("nodes") or [])]
    parents = _forest(document, nodes)
    roots = _roots(document, nodes, parents)
    asset = GltfAsset(document, nodes, roots, {}, [], [], [], [], [], parents)
    used = asset.subtree()
    for index in used:
        node = nodes[index]
        if node.mesh is not None and node.mesh not in asset.meshes:
            document.entry("meshes", node.mesh, f"{node.where}.mesh")
            asset.meshes[node.mesh] = read_primitives(document, node.mesh)
    images = ImageFiles(document)
    asset.materials = [read_material(document, images, index)
                       for index in range(len(gltf.materials or []))]
    asset.cameras = [_camera(document, index, raw)
                     for index, raw in enumerate(document.raw.get("cameras") or [])]
    asset.lights = _lights(document)
    asset.skins = [_skin(document, index, raw)
                   for index, raw in enumerate(document.raw.get("skins") or [])]
    for index in used:
        _check_references(asset, nodes[index])
    asset.animations = [read_animation(document, index, raw, len(nodes))
                        for index, raw in enumerate(document.raw.get("animations") or [])]
    return asset


def _whole_or_none(document: GltfDocument, raw: dict, key: str, where: str) -> int | None:
    value = raw.get(key)
    if value is not None and (not isinstance(value, int) or isinstance(value, bool)
                              or value < 0):
        raise document.error(f"expected an index (a whole number >= 0), got {value!r:.40}",
                             f"{where}.{key}")
    return value


def _node(document: GltfDocument, index: int, raw: Any) -> GltfNode:
    where = f"nodes[{index}]"
    if not isinstance(raw, dict):
        raise document.error("expected an object", where)
    children = raw.get("children") or []
    if not isinstance(children, list) or not all(
            isinstance(c, int) and not isinstance(c, bool) for c in children):
        raise document.error("expected a list of node indices", f"{where}.children")
    light = ((raw.get("extensions") or {}).get("KHR_lights_punctual") or {}).get("light")
    matrix = None
    if raw.get("matrix") is not None:
        values = _numbers(document, raw["matrix"], 16, f"{where}.matrix")
        matrix = np.array(values, np.float64).reshape(4, 4).T  # column-major in the file
        transform = _matrix_transform(document, matrix, f"{where}.matrix")
    else:
        translation = _numbers(document, raw.get("translation", (0, 0, 0)), 3,
                               f"{where}.translation")
        rotation = _numbers(document, raw.get("rotation", (0, 0, 0, 1)), 4,
                            f"{where}.rotation")
        if math.hypot(*rotation) < 1e-9:
            raise document.error("a rotation quaternion of length 0", f"{where}.rotation")
        scale = _numbers(document, raw.get("scale", (1, 1, 1)), 3, f"{where}.scale")
        transform = Transform.model_construct(position=translation, rotation=(0.0, 0.0, 0.0),
                                              rotation_order="XYZ", quaternion=rotation,
                                              scale=safe_scale(scale))
    name = raw.get("name") if isinstance(raw.get("name"), str) else None
    return GltfNode(index, name, transform, matrix, list(children),
                    _whole_or_none(document, raw, "mesh", where),
                    _whole_or_none(document, raw, "camera", where),
                    light, _whole_or_none(document, raw, "skin", where))


def safe_scale(scale) -> tuple[float, float, float]:
    """A glTF scale with each axis at least ``MIN_SCALE`` in size (0 hides a node in glTF; the
    framework's normal matrix needs an inverse), its sign kept."""
    return tuple(math.copysign(max(abs(float(s)), MIN_SCALE), float(s) or 1.0) for s in scale)


def _numbers(document: GltfDocument, value: Any, count: int, where: str) -> tuple[float, ...]:
    if not isinstance(value, list | tuple) or len(value) != count or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
            for v in value):
        raise document.error(f"expected {count} finite numbers", where)
    return tuple(float(v) for v in value)


def _matrix_transform(document: GltfDocument, matrix: np.ndarray, where: str) -> Transform:
    """The matrix's decomposition (translation, rotation as a quaternion, scale)."""
    linear = matrix[:3, :3]
    scale = np.linalg.norm(linear, axis=0)
    if np.any(scale < 1e-12) or abs(matrix[3, 3] - 1.0) > 1e-6 or \
            np.any(np.abs(matrix[3, :3]) > 1e-6):
        raise document.error("is not an affine placement with a scale (a zero axis or a "
                             "projective row)", where)
    if np.linalg.det(linear) < 0.0:
        scale[0] = -scale[0]
    return Transform.model_construct(position=tuple(float(v) for v in matrix[:3, 3]),
                                     rotation=(0.0, 0.0, 0.0), rotation_order="XYZ",
                                     quaternion=matrix_quaternion(linear / scale),
                                     scale=safe_scale(scale))


def matrix_quaternion(rotation: np.ndarray) -> tuple[float, float, float, float]:
    """The unit quaternion [x, y, z, w] of a 3x3 rotation matrix (Shepperd's method)."""
    m = rotation
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4)
    else:
        i = int(np.argmax([m[0, 0], m[1, 1], m[2, 2]]))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(max(1.0 + m[i, i] - m[j, j] - m[k, k], 1e-12))
        q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
        q[i] = s / 4
        q[j] = (m[j, i] + m[i, j]) / s
        q[k] = (m[k, i] + m[i, k]) / s
    q = np.asarray(q, np.float64)
    return tuple(float(v) for v in q / np.linalg.norm(q))


def _forest(document: GltfDocument, nodes: list[GltfNode]) -> dict[int, int]:
    """Each node's parent; a child index that is not a node, a node with two parents or a
    cycle is an error naming the JSON path."""
    parents: dict[int, int] = {}
    for node in nodes:
        for child in node.children:
            at = f"{node.where}.children"
            if not 0 <= child < len(nodes):
                raise document.error(f"refers to nodes[{child}], but the file has "
                                     f"{len(nodes)} nodes", at)
            if child in parents:
                raise document.error(f"nodes[{child}] is a child of nodes[{parents[child]}] "
                                     "too: a node has one parent", at)
            parents[child] = node.index
    rooted: set[int] = set()
    for node in nodes:
        chain, current = [node.index], parents.get(node.index)
        while current is not None and current not in rooted:
            if current == node.index:
                shown = " -> ".join(f"nodes[{i}]" for i in [*reversed(chain[-4:]), node.index])
                raise document.error(f"the node graph has a cycle ({len(chain)} nodes: "
                                     f"{shown}): a node cannot be its own ancestor",
                                     f"nodes[{node.index}].children")
            chain.append(current)
            if len(chain) > len(nodes):
                break  # a cycle above: said for its own members
            current = parents.get(current)
        else:
            rooted.update(chain)
    return parents


def _roots(document: GltfDocument, nodes: list[GltfNode], parents: dict[int, int]) -> list[int]:
    """The default scene's root nodes (every node without a parent where the file has no
    scenes)."""
    scenes = document.raw.get("scenes") or []
    if not scenes:
        return [node.index for node in nodes if node.index not in parents]
    chosen = document.raw.get("scene", 0)
    scene = document.entry("scenes", chosen, "scene")
    where = f"scenes[{chosen}].nodes"
    roots = list(scene.nodes or [])
    for root in roots:
        if not isinstance(root, int) or not 0 <= root < len(nodes):
            raise document.error(f"refers to nodes[{root!r:.20}], but the file has "
                                 f"{len(nodes)} nodes", where)
        if root in parents:
            raise document.error(f"nodes[{root}] is a child of nodes[{parents[root]}]: a "
                                 "scene lists root nodes", where)
    return list(dict.fromkeys(roots))


def _camera(document: GltfDocument, index: int, raw: Any) -> GltfCamera:
    where = f"cameras[{index}]"
    kind = raw.get("type") if isinstance(raw, dict) else None
    if kind not in ("perspective", "orthographic"):
        raise document.error(f"unknown type {kind!r:.40} (perspective or orthographic)",
                             f"{where}.type")
    values = raw.get(kind)
    if not isinstance(values, dict):
        raise document.error(f"has no {kind} object", f"{where}.{kind}")
    name = raw.get("name") if isinstance(raw.get("name"), str) else f"camera{index}"
    near = _positive(document, values.get("znear"), f"{where}.{kind}.znear")
    far = values.get("zfar")
    if far is not None:
        far = _positive(document, far, f"{where}.{kind}.zfar")
        if far <= near:
            raise document.error("zfar must be more than znear", f"{where}.{kind}.zfar")
    if kind == "orthographic":
        document.warn(f"{where} is orthographic: drawn as a perspective camera of 30 degrees")
        return GltfCamera(name, kind, 30.0, None, near, far)
    fov = math.degrees(_positive(document, values.get("yfov"), f"{where}.{kind}.yfov"))
    if not 1.0 < fov < 179.0:
        raise document.error(f"yfov is {fov:.3g} degrees; it must be in (1, 179)",
                             f"{where}.{kind}.yfov")
    aspect = values.get("aspectRatio")
    if aspect is not None:
        aspect = _positive(document, aspect, f"{where}.{kind}.aspectRatio")
    return GltfCamera(name, kind, fov, aspect, near, far)


def _positive(document: GltfDocument, value: Any, where: str) -> float:
    if not isinstance(value, int | float) or isinstance(value, bool) or \
            not (math.isfinite(value) and value > 0.0):
        raise document.error(f"expected a finite number > 0, got {value!r:.40}", where)
    return float(value)


def _lights(document: GltfDocument) -> list[GltfLight]:
    extension = (document.raw.get("extensions") or {}).get("KHR_lights_punctual") or {}
    made = []
    for index, raw in enumerate(extension.get("lights") or []):
        where = f"extensions.KHR_lights_punctual.lights[{index}]"
        kind = raw.get("type") if isinstance(raw, dict) else None
        if kind not in ("directional", "point", "spot"):
            raise document.error(f"unknown type {kind!r:.40} (directional, point or spot)",
                                 f"{where}.type")
        color = _numbers(document, raw.get("color", (1, 1, 1)), 3, f"{where}.color")
        if min(color) < 0.0:
            raise document.error("a colour is >= 0", f"{where}.color")
        intensity = raw.get("intensity", 1.0)
        if not isinstance(intensity, int | float) or not math.isfinite(intensity) or \
                intensity < 0.0:
            raise document.error(f"expected a number >= 0, got {intensity!r:.40}",
                                 f"{where}.intensity")
        reach = raw.get("range")
        if reach is not None:
            reach = _positive(document, reach, f"{where}.range")
        light = GltfLight(raw.get("name") or f"light{index}", kind, color, float(intensity),
                          reach)
        if kind == "spot":
            spot = raw.get("spot") or {}
            light.inner = math.degrees(float(spot.get("innerConeAngle", 0.0)))
            light.outer = math.degrees(float(spot.get("outerConeAngle", math.pi / 4)))
            if not 0.0 <= light.inner < light.outer <= 90.0:
                raise document.error("the cone angles must be 0 <= inner < outer <= pi/2",
                                     f"{where}.spot")
        made.append(light)
    return made


def _skin(document: GltfDocument, index: int, raw: Any) -> GltfSkin:
    where = f"skins[{index}]"
    joints = raw.get("joints") if isinstance(raw, dict) else None
    if not isinstance(joints, list) or not joints:
        raise document.error("expected a list of joint node indices", f"{where}.joints")
    for k, joint in enumerate(joints):
        document.entry("nodes", joint, f"{where}.joints[{k}]")
    if raw.get("inverseBindMatrices") is None:
        binds = np.tile(np.identity(4), (len(joints), 1, 1))
    else:
        values = read_accessor(document, raw["inverseBindMatrices"],
                               f"{where}.inverseBindMatrices", ("MAT4",))
        if len(values) < len(joints):
            raise document.error(f"{len(values)} matrices for {len(joints)} joints",
                                 f"{where}.inverseBindMatrices")
        binds = values[:len(joints)].astype(np.float64).reshape(-1, 4, 4).transpose(0, 2, 1)
    name = raw.get("name") if isinstance(raw.get("name"), str) else f"skin{index}"
    return GltfSkin(name, list(joints), binds)


def _check_references(asset: GltfAsset, node: GltfNode) -> None:
    document = asset.document
    if node.camera is not None:
        document.entry("cameras", node.camera, f"{node.where}.camera")
    if node.light is not None and (not isinstance(node.light, int) or
                                   not 0 <= node.light < len(asset.lights)):
        raise document.error(f"refers to light {node.light!r:.20}, but the file has "
                             f"{len(asset.lights)}",
                             f"{node.where}.extensions.KHR_lights_punctual.light")
    if node.skin is None:
        return
    skin = document.entry("skins", node.skin, f"{node.where}.skin")
    del skin
    joints = len(asset.skins[node.skin].joints)
    for primitive in asset.meshes.get(node.mesh, []):
        if primitive.mesh.joints is not None and int(primitive.mesh.joints.max()) >= joints:
            raise document.error(f"a vertex follows joint {int(primitive.mesh.joints.max())}; "
                                 f"skins[{node.skin}] has {joints}",
                                 f"{primitive.where}.attributes.JOINTS_0")
