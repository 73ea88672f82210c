"""A glTF mesh primitive made into the framework's vertex format
(:class:`~deferred.gl.meshes.MeshData`): its attributes read and checked
(:mod:`deferred.scene.gltf.accessors`), strips and fans made triangles, flat normals where the
file gives none (as the specification asks), tangents from the file where it gives them, and
the second UV set, vertex colours, joints and weights kept beside the vertex format."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from deferred.errors import InputError
from deferred.gl.meshes import MeshData
from deferred.scene.geometry import build_mesh
from deferred.scene.gltf.accessors import read_accessor
from deferred.scene.gltf.document import GltfDocument

TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN = 4, 5, 6
MODE_NAMES = {0: "points", 1: "lines", 2: "line loop", 3: "line strip"}
MAX_INFLUENCES = 4  # joints a vertex follows (JOINTS_0 / WEIGHTS_0)


@dataclass
class GltfPrimitive:
    """One primitive of a glTF mesh: its mesh data, its material's index (None: glTF's default
    material), where it is in the file (``meshes[0].primitives[1]``), and its morph targets'
    count (read but not drawn)."""

    mesh: MeshData
    material: int | None
    where: str
    targets: int = 0


def read_primitives(document: GltfDocument, mesh_index: int) -> list[GltfPrimitive]:
    """The triangle primitives of mesh ``mesh_index`` (points and lines are left out with a
    warning)."""
    raw_mesh = document.raw["meshes"][mesh_index]
    name = document.gltf.meshes[mesh_index].name or f"mesh{mesh_index}"
    made = []
    for index, raw in enumerate(raw_mesh.get("primitives") or []):
        where = f"meshes[{mesh_index}].primitives[{index}]"
        if not isinstance(raw, dict):
            raise document.error("expected an object", where)
        mode = raw.get("mode", TRIANGLES)
        if mode in MODE_NAMES:
            document.warn(f"{where} draws {MODE_NAMES[mode]}, which the framework does not "
                          "draw (left out)")
            continue
        if mode not in (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN):
            raise document.error(f"unknown mode {mode!r:.40}", f"{where}.mode")
        mesh = _primitive_mesh(document, raw, f"{name}[{index}]", where)
        material = raw.get("material")
        if material is not None:
            document.entry("materials", material, f"{where}.material")
        targets = raw.get("targets") or []
        made.append(GltfPrimitive(mesh, material, where, len(targets)))
    morphed = sum(1 for primitive in made if primitive.targets)
    if morphed:
        document.warn(f"meshes[{mesh_index}] ({name}) has morph targets in {morphed} "
                      "primitive(s): drawn in the base shape (morph targets are not drawn)")
    return made


def _attribute(document: GltfDocument, attributes: dict, key: str, where: str,
               types: tuple[str, ...]) -> np.ndarray | None:
    if key not in attributes:
        return None
    return read_accessor(document, attributes[key], f"{where}.attributes.{key}", types)


ATTRIBUTE_TYPES = (("POSITION", ("VEC3",)), ("NORMAL", ("VEC3",)), ("TANGENT", ("VEC4",)),
                   ("TEXCOORD_0", ("VEC2",)), ("TEXCOORD_1", ("VEC2",)),
                   ("COLOR_0", ("VEC3", "VEC4")), ("JOINTS_0", ("VEC4",)),
                   ("WEIGHTS_0", ("VEC4",)))
DRACO = "KHR_draco_mesh_compression"


def _primitive_mesh(document: GltfDocument, raw: dict, name: str, where: str) -> MeshData:
    attributes = raw.get("attributes")
    if not isinstance(attributes, dict) or "POSITION" not in attributes:
        raise document.error("has no POSITION attribute", f"{where}.attributes")
    draco = (raw.get("extensions") or {}).get(DRACO)
    if draco is not None:
        read, indices = _draco_attributes(document, draco, f"{where}.extensions.{DRACO}")
    else:
        read = {key: _attribute(document, attributes, key, where, types)
                for key, types in ATTRIBUTE_TYPES}
        indices = None
    positions = read.pop("POSITION")
    count = len(positions)
    for key, values in read.items():
        if values is not None and len(values) != count:
            raise document.error(f"has {len(values):,} elements; POSITION has {count:,}",
                                 f"{where}.attributes.{key}")
    _refuse_more_influences(document, attributes, where)
    if indices is None:
        indices = _indices(document, raw, count, where)
    triangles = _triangles(indices, raw.get("mode", TRIANGLES))
    if len(triangles) == 0:
        raise document.error("has no triangles", where)
    if read["NORMAL"] is None:  # flat normals: each triangle's corners apart (build_mesh's
        # area-weighted normals of lone triangles are their faces')
        corners = triangles.reshape(-1)
        read = {key: None if values is None else values[corners] for key, values in
                read.items()}
        positions = positions[corners]
        triangles = np.arange(len(corners), dtype=np.int64).reshape(-1, 3)
    uvs = read["TEXCOORD_0"]
    if uvs is None:  # no texture reads them: zeros, not an unwrap (which reorders vertices)
        uvs = np.zeros((len(positions), 2))
    uvs = gl_uvs(uvs)
    try:
        mesh = build_mesh(name, positions.astype(np.float64), triangles,
                          None if read["NORMAL"] is None else read["NORMAL"].astype(np.float64),
                          uvs.astype(np.float64))
    except InputError as exc:
        raise document.error(exc.message, where) from None
    _extra_attributes(document, mesh, read, where)
    mesh.sources = tuple(document.sources) or (document.path,)
    return mesh


def gl_uvs(uvs: np.ndarray) -> np.ndarray:
    """glTF texture coordinates (v = 0 at the image's top) as GL's (v = 0 at its bottom, as
    the framework's textures are uploaded): ``(u, 1 - v)``."""
    flipped = np.asarray(uvs, np.float64).copy()
    flipped[:, 1] = 1.0 - flipped[:, 1]
    return flipped


def _extra_attributes(document: GltfDocument, mesh: MeshData, read: dict, where: str) -> None:
    """The file's tangents, second UV set, colours, joints and weights on ``mesh``."""
    if read["TANGENT"] is not None:
        _file_tangents(mesh, read["TANGENT"])
    if read["TEXCOORD_1"] is not None:
        mesh.uv1 = gl_uvs(read["TEXCOORD_1"]).astype(np.float32)
    if read["COLOR_0"] is not None:
        colors = read["COLOR_0"].astype(np.float32)
        if colors.shape[1] == 3:
            colors = np.hstack([colors, np.ones((len(colors), 1), np.float32)])
        mesh.colors = np.clip(colors, 0.0, None)
    _skin_attributes(document, mesh, read["JOINTS_0"], read["WEIGHTS_0"], where)


def _draco_attributes(document: GltfDocument, draco: dict, where: str
                      ) -> tuple[dict[str, np.ndarray | None], np.ndarray]:
    """The attributes and indices of a Draco-compressed primitive (DracoPy decodes it)."""
    try:
        import DracoPy
    except ImportError:  # a declared dependency: missing only from a broken install
        raise document.error("a Draco-compressed mesh needs the Draco decoder, DracoPy, which "
                             "is not installed: pip install DracoPy", where) from None

    from deferred.scene.gltf.accessors import buffer_view_bytes

    if not isinstance(draco, dict) or not isinstance(draco.get("attributes"), dict):
        raise document.error("expected a bufferView and attributes", where)
    data, _ = buffer_view_bytes(document, draco.get("bufferView"), f"{where}.bufferView")
    try:
        decoded = DracoPy.decode(bytes(data))
    except Exception as exc:  # noqa: BLE001 - the decoder's own errors
        raise document.error(f"cannot decode the Draco mesh: {exc}"[:200], where) from None
    read: dict[str, np.ndarray | None] = {key: None for key, _ in ATTRIBUTE_TYPES}
    for key, unique_id in draco["attributes"].items():
        if key not in read:
            continue
        attribute = decoded.get_attribute_by_unique_id(unique_id)
        if attribute is None:
            raise document.error(f"the Draco mesh has no attribute {unique_id!r:.20}",
                                 f"{where}.attributes.{key}")
        values = np.asarray(attribute["data"])
        if values.dtype.kind == "f" and not np.all(np.isfinite(values)):
            raise document.error("holds NaN or infinite values", f"{where}.attributes.{key}")
        read[key] = values.reshape(len(values), -1)
    if read["POSITION"] is None:
        raise document.error("the Draco mesh has no POSITION", f"{where}.attributes")
    indices = np.asarray(decoded.faces, np.int64).reshape(-1)
    if len(indices) and (indices.min() < 0 or indices.max() >= len(read["POSITION"])):
        raise document.error("a Draco face refers to a vertex it does not have", where)
    return read, indices


def _refuse_more_influences(document: GltfDocument, attributes: dict, where: str) -> None:
    """A vertex following more than four joints (JOINTS_1 with weight) is an error."""
    for key in attributes:
        if key.startswith("WEIGHTS_") and key != "WEIGHTS_0":
            weights = read_accessor(document, attributes[key], f"{where}.attributes.{key}",
                                    ("VEC4",))
            if np.any(weights > 0.0):
                raise document.error(f"vertices follow more than {MAX_INFLUENCES} joints "
                                     f"({key} has weights); the framework skins with "
                                     f"{MAX_INFLUENCES} (JOINTS_0, WEIGHTS_0): reduce the "
                                     "influences when exporting", f"{where}.attributes.{key}")


def _indices(document: GltfDocument, raw: dict, count: int, where: str) -> np.ndarray:
    if raw.get("indices") is None:
        return np.arange(count, dtype=np.int64)
    index = raw["indices"]
    accessor = document.entry("accessors", index, f"{where}.indices")
    if accessor.componentType not in (5121, 5123, 5125):
        raise document.error("indices must be unsigned bytes, shorts or ints",
                             f"accessors[{index}].componentType")
    indices = read_accessor(document, index, f"{where}.indices", ("SCALAR",))[:, 0]
    indices = indices.astype(np.int64)
    if len(indices) and int(indices.max()) >= count:
        raise document.error(f"an index is {int(indices.max()):,}, past the {count:,} "
                             "vertices of its primitive", f"{where}.indices")
    return indices


def _triangles(indices: np.ndarray, mode: int) -> np.ndarray:
    """(T, 3) corners of the triangles of a list, strip or fan."""
    if mode == TRIANGLES:
        return indices[:len(indices) // 3 * 3].reshape(-1, 3)
    if len(indices) < 3:
        return np.zeros((0, 3), np.int64)
    k = np.arange(len(indices) - 2)
    if mode == TRIANGLE_STRIP:  # every other triangle turned back to keep the winding
        even = k % 2 == 0
        return np.stack([indices[k], np.where(even, indices[k + 1], indices[k + 2]),
                         np.where(even, indices[k + 2], indices[k + 1])], axis=1)
    return np.stack([np.full_like(k, indices[0]), indices[k + 1], indices[k + 2]], axis=1)


def _file_tangents(mesh: MeshData, tangents: np.ndarray) -> None:
    """The file's tangents (xyz, and w the bitangent's sign: ``cross(n, t) * w``)."""
    normals = mesh.normals.astype(np.float64)
    t = tangents[:, :3].astype(np.float64)
    t -= np.sum(t * normals, axis=1, keepdims=True) * normals
    length = np.linalg.norm(t, axis=1, keepdims=True)
    usable = length[:, 0] > 1e-8
    t = np.where(usable[:, None], t / np.maximum(length, 1e-30), mesh.tangents)
    sign = np.where(tangents[:, 3:4] < 0.0, -1.0, 1.0)
    binormals = np.where(usable[:, None], np.cross(normals, t) * sign, mesh.binormals)
    mesh.tangents = t.astype(np.float32)
    mesh.binormals = binormals.astype(np.float32)
    mesh.file_tangents = np.hstack([t, np.where(usable[:, None], sign, 1.0)]).astype(np.float32)


def _skin_attributes(document: GltfDocument, mesh: MeshData, joints: np.ndarray | None,
                     weights: np.ndarray | None, where: str) -> None:
    if joints is None and weights is None:
        return
    if joints is None or weights is None:
        missing = "JOINTS_0" if joints is None else "WEIGHTS_0"
        raise document.error(f"a skinned primitive needs both JOINTS_0 and WEIGHTS_0 ("
                             f"{missing} is missing)", f"{where}.attributes")
    if np.any(joints < 0):
        raise document.error("joints are unsigned", f"{where}.attributes.JOINTS_0")
    weights = np.clip(weights.astype(np.float64), 0.0, None)
    total = weights.sum(axis=1, keepdims=True)
    # a vertex of no weight follows the first joint (the specification asks for sums of 1)
    weights = np.where(total > 1e-8, weights / np.maximum(total, 1e-30), [1.0, 0.0, 0.0, 0.0])
    mesh.joints = joints.astype(np.uint16)
    mesh.weights = weights.astype(np.float32)
