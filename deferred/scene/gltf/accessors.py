"""A glTF accessor read into a numpy array, checked: its component type and shape, its byte
range within its buffer view and the view's within its buffer, its sparse substitution, and its
values (NaN or infinity in a float accessor is an error). pygltflib leaves reading accessors to
its user; these are the glTF 2.0 specification's rules (section 3.6), each broken one an
``InputError`` naming the JSON path."""

from __future__ import annotations

import numpy as np

from deferred.scene.gltf.document import GltfDocument

COMPONENT_TYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16,
                   5125: np.uint32, 5126: np.float32}
TYPE_SIZES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
MAX_COUNT = 50_000_000


def _whole(value, default: int | None = None) -> int | None:
    if value is None:
        return default
    if isinstance(value, bool) or not isinstance(value, int):
        return -1
    return value


def buffer_view_bytes(document: GltfDocument, index: int, where: str) -> tuple[memoryview, int]:
    """(the bytes of buffer view ``index``, its byteStride or 0), its range checked."""
    view = document.entry("bufferViews", index, where)
    at = f"bufferViews[{index}]"
    buffer_index = view.buffer
    document.entry("buffers", buffer_index, f"{at}.buffer")
    data = document.buffers[buffer_index]
    offset, length = _whole(view.byteOffset, 0), _whole(view.byteLength)
    if offset is None or offset < 0:
        raise document.error(f"must be a whole number >= 0, got {view.byteOffset!r:.40}",
                             f"{at}.byteOffset")
    if length is None or length < 1:
        raise document.error(f"must be a whole number >= 1, got {view.byteLength!r:.40}",
                             f"{at}.byteLength")
    declared = document.gltf.buffers[buffer_index].byteLength
    if offset + length > declared:
        raise document.error(f"bytes {offset:,}..{offset + length:,} run past the end of "
                             f"buffers[{buffer_index}] ({declared:,} bytes)", at)
    stride = _whole(view.byteStride, 0)
    if stride != 0 and not (4 <= stride <= 252 and stride % 4 == 0):
        raise document.error(f"must be a multiple of 4 in 4..252, got {view.byteStride!r:.40}",
                             f"{at}.byteStride")
    return memoryview(data)[offset:offset + length], stride


def read_accessor(document: GltfDocument, index: int, where: str,
                  types: tuple[str, ...] | None = None, finite: bool = True) -> np.ndarray:
    """Accessor ``index`` as an array of shape (count, components) (normalised integers as
    floats in [0, 1] or [-1, 1]); ``types`` the accessor types the caller takes; ``where``
    the JSON path that refers to it (for an index that is not there)."""
    accessor = document.entry("accessors", index, where)
    at = f"accessors[{index}]"
    dtype = COMPONENT_TYPES.get(accessor.componentType)
    if dtype is None:
        raise document.error(f"unknown componentType {accessor.componentType!r:.40}",
                             f"{at}.componentType")
    components = TYPE_SIZES.get(accessor.type)
    if components is None:
        raise document.error(f"unknown type {accessor.type!r:.40}", f"{at}.type")
    if types is not None and accessor.type not in types:
        raise document.error(f"is {accessor.type}; {where} takes {' or '.join(types)}", at)
    count = _whole(accessor.count)
    if count is None or not 1 <= count <= MAX_COUNT:
        raise document.error(f"must be a whole number in 1..{MAX_COUNT:,}, got "
                             f"{accessor.count!r:.40}", f"{at}.count")
    size = np.dtype(dtype).itemsize
    if accessor.type in ("MAT2", "MAT3") and size < 4:
        raise document.error(f"a {accessor.type} of {size}-byte components (padded columns) "
                             "is not read by the framework", at)
    element = size * components
    if accessor.bufferView is None:
        values = np.zeros((count, components), dtype)
    else:
        data, stride = buffer_view_bytes(document, accessor.bufferView, f"{at}.bufferView")
        stride = stride or element
        offset = _whole(accessor.byteOffset, 0)
        if offset is None or offset < 0 or offset % size:
            raise document.error(f"must be a whole number >= 0 and a multiple of {size}, got "
                                 f"{accessor.byteOffset!r:.40}", f"{at}.byteOffset")
        end = offset + stride * (count - 1) + element
        if end > len(data):
            raise document.error(f"{count:,} elements of {element} bytes (stride {stride}) "
                                 f"from byte {offset:,} end at byte {end:,}, past the end of "
                                 f"bufferViews[{accessor.bufferView}] ({len(data):,} bytes)", at)
        values = np.ndarray((count, components), dtype, buffer=data, offset=offset,
                            strides=(stride, size)).copy()
    if accessor.sparse is not None:
        values = _sparse(document, accessor.sparse, values, f"{at}.sparse")
    if accessor.normalized:
        if dtype == np.float32 or dtype == np.uint32:
            raise document.error("normalized applies to 8- and 16-bit integers only",
                                 f"{at}.normalized")
        limit = float(np.iinfo(dtype).max)
        values = np.maximum(values.astype(np.float64) / limit, -1.0)
    elif dtype == np.float32 and finite:
        bad = ~np.isfinite(values)
        if bad.any():
            first = int(np.argmax(bad.any(axis=1)))
            raise document.error(f"holds {int(bad.sum()):,} NaN or infinite values (the first "
                                 f"in element {first})", at)
    return values


def _sparse(document: GltfDocument, sparse, values: np.ndarray, at: str) -> np.ndarray:
    """``values`` with the sparse substitution of an accessor applied (a copy)."""
    count = _whole(sparse.count)
    if count is None or not 1 <= count <= len(values):
        raise document.error(f"must be a whole number in 1..{len(values):,}, got "
                             f"{sparse.count!r:.40}", f"{at}.count")
    indices_info, values_info = sparse.indices, sparse.values
    index_type = COMPONENT_TYPES.get(indices_info.componentType)
    if index_type not in (np.uint8, np.uint16, np.uint32):
        raise document.error("must be an unsigned integer type",
                             f"{at}.indices.componentType")
    indices = _packed(document, indices_info, index_type, 1, count, f"{at}.indices")[:, 0]
    if np.any(np.diff(indices.astype(np.int64)) <= 0) or int(indices.max()) >= len(values):
        raise document.error(f"its indices must rise strictly and stay below the accessor's "
                             f"count {len(values):,}", f"{at}.indices")
    replaced = _packed(document, values_info, values.dtype.type, values.shape[1], count,
                       f"{at}.values")
    values = values.copy()
    values[indices.astype(np.int64)] = replaced
    return values


def _packed(document: GltfDocument, info, dtype, components: int, count: int,
            at: str) -> np.ndarray:
    """``count`` tightly packed elements at a sparse part's buffer view and offset."""
    data, _ = buffer_view_bytes(document, info.bufferView, f"{at}.bufferView")
    offset = _whole(info.byteOffset, 0)
    element = np.dtype(dtype).itemsize * components
    if offset is None or offset < 0 or offset + element * count > len(data):
        raise document.error(f"{count} elements from byte {info.byteOffset!r:.20} run past "
                             f"the end of bufferViews[{info.bufferView}]", at)
    return np.frombuffer(data, dtype, count * components, offset).reshape(count, components)
