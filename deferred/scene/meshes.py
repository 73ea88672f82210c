"""Meshes by name: a file loaded through trimesh (OBJ, PLY, STL, OFF; its vertex colours carry
the fur comb), a glTF file's default scene as one mesh (:mod:`deferred.scene.gltf`) or a
built-in shape (:mod:`deferred.scene.builtin_meshes`), made into the framework's vertex format
by :mod:`deferred.scene.geometry`. A file is refused before
trimesh parses it when it is larger than ``MAX_MESH_FILE_BYTES``.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from deferred.errors import InputError
from deferred.gl.meshes import MeshData
from deferred.io.images import first_line
from deferred.io.safety import raise_if_stop_requested
from deferred.scene.builtin_meshes import BUILTIN_PREFIX, BUILTIN_SHAPES, builtin_arguments
from deferred.scene.geometry import build_mesh
from deferred.validation import require_regular_file

MESH_SUFFIXES = (".obj", ".ply", ".stl", ".off", ".glb", ".gltf")
MAX_MESH_FILE_BYTES = 1 << 30  # a 5M-triangle OBJ with normals and UVs is about 0.5 GB


def load_mesh(spec: str, base_dir: Path | None = None, where: str | None = None) -> MeshData:
    """Load ``builtin:<name>`` or a mesh file (relative paths resolve against ``base_dir``).

    Built-in shapes take their function's keyword arguments as a query:
    ``builtin:torus?segments=78&sides=60`` (see :func:`builtin_arguments`); the mesh is still
    named ``builtin:torus``.
    """
    where = where or spec
    if spec.startswith(BUILTIN_PREFIX):
        shape, arguments = builtin_arguments(spec, where)
        return BUILTIN_SHAPES[shape](**arguments)
    path = Path(spec)
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    require_regular_file(path, "mesh file", where)
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise InputError(f"unsupported mesh format '{path.suffix}' "
                         f"(use {', '.join(MESH_SUFFIXES)})", where)
    size = path.stat().st_size
    if size > MAX_MESH_FILE_BYTES:  # before trimesh spends minutes and gigabytes parsing it
        raise InputError(f"mesh file {path.name} is {size:,} bytes, more than the "
                         f"{MAX_MESH_FILE_BYTES:,} the framework reads; simplify it", where)
    _check_magic(path, where)
    if path.suffix.lower() in (".gltf", ".glb"):  # read by deferred.scene.gltf, not trimesh
        from deferred.scene.gltf.building import flat_mesh

        return flat_mesh(path, where)
    import trimesh

    resolver = _regular_file_resolver(trimesh, path)
    try:
        loaded = trimesh.load(str(path), force="mesh", process=False, resolver=resolver)
    except ImportError:
        raise  # a broken installation (exit 1), not a bad file
    except Exception as exc:  # noqa: BLE001 - trimesh raises many exception types
        for refused in resolver.refused:  # a file it named and could not have: the cause
            require_regular_file(refused, f"file {refused.name} named by {path.name}", where)
        reason = first_line(str(exc), default="it is malformed (trimesh stopped with a bare "
                                               f"{type(exc).__name__})")
        raise InputError(f"cannot read mesh {path.name}: {reason}", where) from None
    # trimesh catches BaseException in places: a Ctrl-C or SIGTERM it swallowed stops here,
    # not after the rest of the command
    raise_if_stop_requested()
    for refused in resolver.refused:  # named by the mesh, not opened: say so
        require_regular_file(refused, f"file {refused.name} named by {path.name}", where)
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise InputError(f"mesh {path.name} has no triangles", where)
    positions = np.asarray(loaded.vertices, dtype=np.float64)
    indices = np.asarray(loaded.faces, dtype=np.int64)
    normals = None
    if "vertex_normals" in loaded._cache.cache:  # normals stored in the file
        normals = np.asarray(loaded.vertex_normals, dtype=np.float64)
    uvs = None
    visual = loaded.visual
    if getattr(visual, "kind", None) == "texture" and getattr(visual, "uv", None) is not None:
        uvs = np.asarray(visual.uv, dtype=np.float64)
    colors = _vertex_colours(loaded, path.name, where)
    try:
        mesh = build_mesh(path.name, positions, indices, normals, uvs, colors)
    except InputError as exc:
        # ``where`` is a scene key (``scene.toml: object[0].mesh``): say which file too
        message = exc.message if where == spec else f"{path.name}: {exc.message}"
        raise InputError(message, where) from None
    mesh.sources = (path, *dict.fromkeys(resolver.read))
    return mesh


# The first bytes of formats that have them: a file without them is refused before trimesh
# reads it (a 1 GiB file of NUL bytes named .ply took 8 GB to be called "not a ply file")
MAGIC = {".ply": b"ply", ".glb": b"glTF"}


def _check_magic(path: Path, where: str) -> None:
    magic = MAGIC.get(path.suffix.lower())
    if magic is None:
        return
    with open(path, "rb") as file:
        start = file.read(len(magic))
    if start != magic:
        raise InputError(f"{path.name} is not a {path.suffix.lower()[1:].upper()} file (it does "
                         f"not begin with {magic.decode()!r})", where)


def _regular_file_resolver(trimesh, path: Path):
    """A trimesh resolver for the files ``path`` names (an OBJ's material library and its
    textures, a glTF's buffers and images), found as trimesh's own finds them, that opens
    regular files only and keeps which it read (``read``) and which it would not (``refused``).
    trimesh swallows every exception while it reads them, Ctrl-C included: a pipe or a device
    opened there would block the load for good."""

    class RegularFileResolver(trimesh.resolvers.FilePathResolver):
        def __init__(self, source: str, read: list[Path], refused: list[Path]):
            super().__init__(source)
            self.read, self.refused = read, refused

        def get(self, name: str) -> bytes:
            for candidate in (name.strip(), name.strip().lstrip("/"), os.path.split(name)[-1]):
                try:
                    found = self.absolute(candidate)
                except ValueError:
                    continue
                if found.exists():
                    if not found.is_file():
                        self.refused.append(found)
                        raise FileNotFoundError(name)
                    self.read.append(found)
                    return found.read_bytes()
            self.absolute(name)  # a name escaping the mesh's folder: trimesh's own error
            raise FileNotFoundError(name)

        def namespaced(self, namespace: str):
            return RegularFileResolver(os.path.join(self.parent, namespace), self.read,
                                       self.refused)

    return RegularFileResolver(str(path), [], [])


def _vertex_colours(loaded, name: str, where: str) -> np.ndarray | None:
    """Per-vertex RGBA in [0, 1], wherever trimesh put them (None when the file has none);
    ``InputError`` naming the file for a colour that is not a finite number (trimesh would
    turn a NaN into 0).

    With UVs, trimesh keeps a texture visual and moves vertex colours (OBJ ``v x y z r g b``,
    glTF ``COLOR_0``) into vertex attributes; without UVs they form a vertex-colour visual.
    """
    _check_ply_colours(loaded, name, where)
    visual = loaded.visual
    if getattr(visual, "kind", None) == "vertex":
        return np.asarray(visual.vertex_colors, dtype=np.float64) / 255.0
    for attributes in (getattr(loaded, "vertex_attributes", {}),
                       getattr(visual, "vertex_attributes", {})):
        colours = attributes.get("color") if attributes is not None else None
        if colours is not None and len(colours) == len(loaded.vertices):
            colours = np.asarray(colours)
            _check_finite_colours(colours, name, where)
            scale = 255.0 if colours.dtype == np.uint8 or colours.max() > 1.0 else 1.0
            return colours.astype(np.float64) / scale
    return None


PLY_COLOUR_CHANNELS = ("red", "green", "blue", "alpha")


def _check_ply_colours(loaded, name: str, where: str) -> None:
    """A PLY's float colour properties as stored (trimesh keeps them raw beside the mesh)."""
    raw = getattr(loaded, "metadata", {}).get("_ply_raw")
    data = raw.get("vertex", {}).get("data") if isinstance(raw, dict) else None
    if not isinstance(data, dict):
        return
    channels = [np.asarray(data[c], dtype=np.float64).reshape(-1) for c in PLY_COLOUR_CHANNELS
                if c in data and np.asarray(data[c]).dtype.kind == "f"]
    if channels:
        _check_finite_colours(np.stack(channels, axis=-1), name, where)


def _check_finite_colours(colours: np.ndarray, name: str, where: str) -> None:
    if colours.dtype.kind != "f" or np.isfinite(colours).all():
        return
    bad = ~np.isfinite(colours)
    vertex = int(np.argwhere(bad)[0][0])
    count = int(bad.any(axis=-1).sum())
    said = "a vertex colour that is not a finite number" if count == 1 else \
        f"{count:,} vertex colours that are not finite numbers"
    raise InputError(f"mesh {name} has {said} (the first at vertex {vertex}: "
                     f"{np.array2string(colours[vertex], precision=3)}); colours are numbers "
                     "in [0, 1]", where)
