"""Meshes by name: a file loaded through trimesh (OBJ, PLY, STL, OFF, GLB/glTF; its vertex
colours carry the fur comb) or a built-in shape (:mod:`deferred.scene.builtin_meshes`), made into
the framework's vertex format by :mod:`deferred.scene.geometry`. A file is refused before
trimesh parses it when it is larger than ``MAX_MESH_FILE_BYTES``.
"""
from __future__ import annotations

import json
import mmap
import os
from pathlib import Path
from urllib.parse import unquote

import numpy as np

from deferred.errors import InputError
from deferred.gl.meshes import MeshData
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
    # trimesh reads these too, and swallows every exception there (Ctrl-C included): a pipe or
    # a device among them would block the load for good, so they are refused first
    references = [ref for ref in mesh_references(path) if os.path.lexists(ref)]
    for ref in references:
        require_regular_file(ref, f"{ref.name}, named by mesh file {path.name},", where)
    import trimesh

    try:
        loaded = trimesh.load(str(path), force="mesh", process=False)
    except ImportError:
        raise  # a broken installation (exit 1), not a bad file
    except Exception as exc:  # noqa: BLE001 - trimesh raises many exception types
        reason = str(exc) or type(exc).__name__
        raise InputError(f"cannot read mesh {path.name}: {reason}", where) from None
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
    colors = _vertex_colours(loaded)
    try:
        mesh = build_mesh(path.name, positions, indices, normals, uvs, colors)
    except InputError as exc:
        # ``where`` is a scene key (``scene.toml: object[0].mesh``): say which file too
        message = exc.message if where == spec else f"{path.name}: {exc.message}"
        raise InputError(message, where) from None
    mesh.sources = (path, *references)
    return mesh


def mesh_references(path: Path) -> list[Path]:
    """The files trimesh reads for mesh file ``path`` besides it, found as trimesh finds them:
    an OBJ's material library (the rest of the line of its first ``mtllib``) and that
    library's ``map_Kd`` textures, and a glTF's (or GLB's) buffers and images given by a
    relative URI; all relative to the mesh file's folder. Files that do not exist are listed
    too (trimesh goes without them)."""
    suffix = path.suffix.lower()
    names: list[str] = []
    if suffix == ".obj":
        library = _obj_library(path)
        if library:
            names.append(library)
            names += _mtl_textures(path.parent / library)
    elif suffix in (".gltf", ".glb"):
        names += _gltf_uris(path)
    return [path.parent / name for name in dict.fromkeys(names)]


def _obj_library(path: Path) -> str | None:
    if path.stat().st_size == 0:
        return None
    with open(path, "rb") as file, \
            mmap.mmap(file.fileno(), 0, access=mmap.ACCESS_READ) as data:
        start = data.find(b"mtllib")  # anywhere, as trimesh looks for it
        if start < 0:
            return None
        end = data.find(b"\n", start)
        line = data[start + 6:end if end >= 0 else len(data)]
    return line.decode("utf-8", errors="replace").strip() or None


def _mtl_textures(library: Path) -> list[str]:
    try:  # a library that is not a regular file is refused by the caller, not read here
        if not library.is_file() or library.stat().st_size > MAX_MESH_FILE_BYTES:
            return []
        text = library.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return []
    names = []
    for line in text.splitlines():
        split = line.split()
        if split and split[0].lower() == "map_kd":
            name = line[line.lower().index("map_kd") + 6:].strip()
            if name:
                names.append(name)
    return names


def _gltf_uris(path: Path) -> list[str]:
    try:
        if path.suffix.lower() == ".glb":
            with open(path, "rb") as file:
                header = file.read(20)
                if len(header) < 20 or header[:4] != b"glTF" or header[16:20] != b"JSON":
                    return []
                document = json.loads(file.read(int.from_bytes(header[12:16], "little")))
        else:
            document = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []  # trimesh says what is wrong with the file
    if not isinstance(document, dict):
        return []
    uris = []
    for key in ("buffers", "images"):
        entries = document.get(key)
        for entry in entries if isinstance(entries, list) else ():
            uri = entry.get("uri") if isinstance(entry, dict) else None
            if isinstance(uri, str) and uri and not uri.startswith("data:") and \
                    "://" not in uri:
                uris.append(unquote(uri))
    return uris


def _vertex_colours(loaded) -> np.ndarray | None:
    """Per-vertex RGBA in [0, 1], wherever trimesh put them (None when the file has none).

    With UVs, trimesh keeps a texture visual and moves vertex colours (OBJ ``v x y z r g b``,
    glTF ``COLOR_0``) into vertex attributes; without UVs they form a vertex-colour visual.
    """
    visual = loaded.visual
    if getattr(visual, "kind", None) == "vertex":
        return np.asarray(visual.vertex_colors, dtype=np.float64) / 255.0
    for attributes in (getattr(loaded, "vertex_attributes", {}),
                       getattr(visual, "vertex_attributes", {})):
        colours = attributes.get("color") if attributes is not None else None
        if colours is not None and len(colours) == len(loaded.vertices):
            colours = np.asarray(colours)
            scale = 255.0 if colours.dtype == np.uint8 or colours.max() > 1.0 else 1.0
            return colours.astype(np.float64) / scale
    return None
