"""A glTF 2.0 file opened and checked: the GLB container or the JSON, the document as pygltflib's
typed objects, its buffers, and the extensions it uses.

pygltflib reads the document (its JSON into typed objects); what it does not check is checked
here before it runs and as its objects are read: the GLB container's lengths (a truncated file),
the number of entries of each list (a file of 10^6 nodes is refused before pygltflib spends
minutes on it), the buffers' URIs (in the file's folder, a regular file, a well-formed data URI)
and lengths, and ``extensionsRequired`` (one the framework lacks is an error naming it). Every
error is one :class:`~deferred.errors.InputError` naming the file and the JSON path
(``model.glb: accessors[3].count``).
"""

from __future__ import annotations

import base64
import binascii
import json
import re
import struct
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import unquote

from deferred.errors import InputError
from deferred.validation import require_regular_file

GLB_MAGIC = b"glTF"
GLB_HEADER = struct.Struct("<4sII")
CHUNK_HEADER = struct.Struct("<II")
CHUNK_JSON = 0x4E4F534A
CHUNK_BIN = 0x004E4942
MAX_FILE_BYTES = 1 << 30  # the mesh files' limit (deferred.scene.meshes)
MAX_JSON_BYTES = 256 << 20
MAX_DATA_URI_BYTES = 256 << 20
# Entries of a list the framework reads: more is a mistake or an attack (a node is an object
# of the scene graph, drawn or walked every frame)
MAX_ENTRIES = {"nodes": 50_000, "meshes": 50_000, "accessors": 500_000,
               "bufferViews": 500_000, "buffers": 10_000, "materials": 50_000,
               "textures": 50_000, "images": 50_000, "samplers": 50_000, "cameras": 10_000,
               "animations": 10_000, "skins": 10_000, "scenes": 10_000}
MAX_LIST_ENTRIES = 1_000_000  # any other list (a node's children, a skin's joints, ...)

# The extensions the framework reads; any other in extensionsRequired is an error, and in
# extensionsUsed a warning (once, by name)
SUPPORTED_EXTENSIONS = ("KHR_lights_punctual", "KHR_texture_transform",
                        "KHR_materials_emissive_strength", "KHR_draco_mesh_compression")


class GltfWarning(UserWarning):
    """Something of a glTF file the framework leaves out (an extension, a feature)."""


@dataclass
class GltfDocument:
    """An opened glTF file: ``gltf`` pygltflib's document, ``raw`` its JSON, ``buffers`` each
    buffer's bytes, ``folder`` where its relative URIs are, ``name`` what errors call it."""

    path: Path
    gltf: Any  # pygltflib.GLTF2
    raw: dict[str, Any]
    buffers: list[bytes]
    unsupported: tuple[str, ...] = ()  # extensions used that the framework does not read
    sources: list[Path] = field(default_factory=list)  # files read (buffers; images add theirs)

    @property
    def folder(self) -> Path:
        return self.path.parent

    @property
    def name(self) -> str:
        return self.path.name

    def error(self, message: str, json_path: str) -> InputError:
        """The one-line error of ``message`` at ``json_path`` (``accessors[3].count``)."""
        return InputError(message, f"{self.name}: {json_path}" if json_path else self.name)

    def entry(self, key: str, index: Any, where: str) -> Any:
        """``gltf.<key>[index]``, the index checked (``InputError`` at ``where``)."""
        items = getattr(self.gltf, key) or []
        if not isinstance(index, int) or isinstance(index, bool) or \
                not 0 <= index < len(items):
            raise self.error(f"refers to {key}[{index!r:.40}], but the file has "
                             f"{len(items)} {key}", where)
        return items[index]

    def warn(self, message: str) -> None:
        warnings.warn(f"{self.name}: {message}", GltfWarning, stacklevel=3)


def open_gltf(path: Path, where: str | None = None) -> GltfDocument:
    """Open ``path`` (.glb or .gltf): the container, the JSON, the counts, the buffers and the
    required extensions checked (``InputError`` naming the file and the JSON path; ``where``,
    a scene key, is said before the file where given)."""
    require_regular_file(path, "glTF file", where)
    try:
        return _open(path)
    except InputError as exc:
        if where is None:
            raise
        raise InputError(str(exc), where) from None


def _open(path: Path) -> GltfDocument:
    name = path.name
    size = path.stat().st_size
    if size > MAX_FILE_BYTES:
        raise InputError(f"{size:,} bytes, more than the {MAX_FILE_BYTES:,} the framework "
                         "reads", name)
    data = path.read_bytes()
    binary = None
    if data[:4] == GLB_MAGIC:
        json_bytes, binary = _glb_chunks(data, name)
    elif path.suffix.lower() == ".glb":
        raise InputError("not a GLB file (it does not begin with 'glTF')", name)
    else:
        json_bytes = data
    if len(json_bytes) > MAX_JSON_BYTES:
        raise InputError(f"its JSON is {len(json_bytes):,} bytes, more than the "
                         f"{MAX_JSON_BYTES:,} the framework reads", name)
    try:
        raw = json.loads(json_bytes.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"malformed glTF JSON: {exc}", name) from None
    except RecursionError:
        raise InputError("malformed glTF JSON: nested too deep", name) from None
    if not isinstance(raw, dict):
        raise InputError("malformed glTF JSON: the document is not an object", name)
    _check_raw(raw, name)
    gltf = _typed(raw, name, binary)
    document = GltfDocument(path, gltf, raw, [])
    document.buffers = [_buffer(document, index, binary)
                        for index in range(len(gltf.buffers or []))]
    document.unsupported = _extensions(document)
    return document


def _glb_chunks(data: bytes, name: str) -> tuple[bytes, bytes | None]:
    """The JSON chunk and the BIN chunk (or None) of a GLB file, every length checked."""
    if len(data) < GLB_HEADER.size:
        raise InputError(f"truncated GLB: {len(data)} bytes, less than its 12-byte header",
                         name)
    _, version, length = GLB_HEADER.unpack_from(data)
    if version != 2:
        raise InputError(f"GLB version {version}; the framework reads glTF 2.0", name)
    if length != len(data):
        said = "truncated GLB" if length > len(data) else "GLB with bytes after its end"
        raise InputError(f"{said}: its header says {length:,} bytes, the file has "
                         f"{len(data):,}", name)
    chunks: list[tuple[int, bytes]] = []
    offset = GLB_HEADER.size
    while offset < length:
        if offset + CHUNK_HEADER.size > length:
            raise InputError(f"truncated GLB: chunk {len(chunks)}'s header runs past the "
                             "end of the file", name)
        chunk_length, chunk_type = CHUNK_HEADER.unpack_from(data, offset)
        start = offset + CHUNK_HEADER.size
        if start + chunk_length > length:
            raise InputError(f"truncated GLB: chunk {len(chunks)} says {chunk_length:,} bytes, "
                             f"{length - start:,} are left", name)
        chunks.append((chunk_type, data[start:start + chunk_length]))
        offset = start + chunk_length
    if not chunks or chunks[0][0] != CHUNK_JSON:
        raise InputError("malformed GLB: its first chunk is not JSON", name)
    binary = chunks[1][1] if len(chunks) > 1 and chunks[1][0] == CHUNK_BIN else None
    return chunks[0][1], binary


def _check_raw(raw: dict[str, Any], name: str) -> None:
    """The version and the size of every list, before pygltflib reads them."""
    asset = raw.get("asset")
    version = asset.get("version") if isinstance(asset, dict) else None
    if not isinstance(version, str):
        raise InputError("has no asset.version: not a glTF 2.0 file", f"{name}: asset.version")
    if not version.startswith("2."):
        raise InputError(f"glTF {version[:20]}; the framework reads glTF 2.0",
                         f"{name}: asset.version")
    for key, value in raw.items():
        if key in ("extensions", "extras", "asset"):
            continue
        limit = MAX_ENTRIES.get(key, MAX_LIST_ENTRIES)
        if isinstance(value, list) and len(value) > limit:
            raise InputError(f"{len(value):,} {key}, more than the {limit:,} the framework "
                             "reads", f"{name}: {key}")
    for index, node in enumerate(raw.get("nodes") or []):
        children = node.get("children") if isinstance(node, dict) else None
        if isinstance(children, list) and len(children) > MAX_ENTRIES["nodes"]:
            raise InputError(f"{len(children):,} children", f"{name}: nodes[{index}].children")


def _typed(raw: dict[str, Any], name: str, binary: bytes | None) -> Any:
    """pygltflib's document of ``raw`` (its JSON's typed objects)."""
    import pygltflib

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # pygltflib's notes on fields it fills in
            gltf = pygltflib.GLTF2.from_dict(raw, infer_missing=True)
    except Exception as exc:  # noqa: BLE001 - dataclasses_json raises whatever a field's type does
        raise InputError(f"malformed glTF JSON: {type(exc).__name__}: {exc}"[:300], name) \
            from None
    if binary is not None:
        gltf.set_binary_blob(binary)
    return gltf


DATA_URI = re.compile(r"data:([\w.+-]+/[\w.+-]+)?(;[\w=.+-]+)*?;base64,", re.ASCII)


def decode_data_uri(uri: str, where: str, name: str) -> tuple[str | None, bytes]:
    """(its MIME type, its bytes) of a base64 data URI; ``InputError`` for any other form, a
    malformed payload or one over ``MAX_DATA_URI_BYTES``."""
    match = DATA_URI.match(uri)
    if match is None:
        raise InputError(f"a data URI the framework does not read ({uri[:40]!r}...: only "
                         "base64 ones)", f"{name}: {where}")
    payload = uri[match.end():]
    if len(payload) * 3 // 4 > MAX_DATA_URI_BYTES:
        raise InputError(f"its data URI holds about {len(payload) * 3 // 4:,} bytes, more than "
                         f"{MAX_DATA_URI_BYTES:,}", f"{name}: {where}")
    try:
        return match.group(1), base64.b64decode(payload, validate=True)
    except (binascii.Error, ValueError) as exc:
        raise InputError(f"malformed base64 in its data URI ({exc})", f"{name}: {where}") \
            from None


def resolve_uri(document: GltfDocument, uri: Any, what: str, where: str) -> Path:
    """The file a relative URI names, in the glTF file's folder or below it (``InputError``
    for an absolute one, one leaving the folder, a missing or irregular file)."""
    if not isinstance(uri, str) or not uri:
        raise document.error("expected a URI (text)", where)
    decoded = unquote(uri)
    if "://" in decoded or decoded.startswith("/") or Path(decoded).is_absolute():
        raise document.error(f"the {what} {uri[:80]!r} is not a path relative to the glTF "
                             "file: the framework reads files beside it only", where)
    folder = document.folder.resolve()
    path = (folder / decoded).resolve()
    if not path.is_relative_to(folder):
        raise document.error(f"the {what} {uri[:80]!r} is outside the glTF file's folder",
                             where)
    require_regular_file(path, what, f"{document.name}: {where}")
    return path


def _buffer(document: GltfDocument, index: int, binary: bytes | None) -> bytes:
    """Buffer ``index``'s bytes: the GLB's BIN chunk, a data URI or a file beside the glTF
    file, at least ``byteLength`` long."""
    buffer = document.gltf.buffers[index]
    where = f"buffers[{index}]"
    length = buffer.byteLength
    if not isinstance(length, int) or isinstance(length, bool) or length < 1:
        raise document.error(f"byteLength must be a whole number >= 1, got {length!r:.40}",
                             f"{where}.byteLength")
    if buffer.uri is None:
        if binary is None or index != 0:
            raise document.error("has no uri and is not the GLB's binary chunk", where)
        data = binary
    elif buffer.uri.startswith("data:"):
        data = decode_data_uri(buffer.uri, f"{where}.uri", document.name)[1]
    else:
        path = resolve_uri(document, buffer.uri, "buffer file", f"{where}.uri")
        if path.stat().st_size > MAX_FILE_BYTES:
            raise document.error(f"{path.name} is more than {MAX_FILE_BYTES:,} bytes",
                                 f"{where}.uri")
        data = path.read_bytes()
        document.sources.append(path)
    if len(data) < length:
        raise document.error(f"holds {len(data):,} bytes, less than its byteLength "
                             f"{length:,} (truncated?)", where)
    return data


def _extensions(document: GltfDocument) -> tuple[str, ...]:
    """The extensions used that the framework does not read (each warned once, by name); an
    error for the first required one it lacks."""
    gltf = document.gltf
    for index, name in enumerate(gltf.extensionsRequired or []):
        if name not in SUPPORTED_EXTENSIONS:
            raise document.error(f"requires the extension {name!r:.80}, which the framework "
                                 f"does not implement (it reads "
                                 f"{', '.join(SUPPORTED_EXTENSIONS)})",
                                 f"extensionsRequired[{index}]")
    unsupported = tuple(dict.fromkeys(str(name) for name in gltf.extensionsUsed or []
                                      if name not in SUPPORTED_EXTENSIONS))
    for name in unsupported:
        document.warn(f"uses the extension {name[:80]}, which the framework does not "
                      "implement (left out)")
    return unsupported
