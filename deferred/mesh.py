"""Meshes: loading through trimesh, built-in shapes, tangent frames and fur comb directions.

Every mesh the framework draws has the same vertex format (``VERTEX_ATTRIBUTES``): position,
normal, UV, tangent, binormal and the RGBA *comb* colour of Revie section 2.4.1 (RGB: comb
direction in tangent space packed from [-1, 1] to [0, 1]; A: fur length scale). Files load through
trimesh; missing normals are computed (area-weighted face normals), missing UVs come from an
xatlas unwrap, tangent frames are built from the UVs.
"""

from __future__ import annotations

import inspect
import math
from dataclasses import dataclass, field
from pathlib import Path

import moderngl
import numpy as np

from .errors import InputError

BUILTIN_PREFIX = "builtin:"
BUILTIN_MESHES = ("sphere", "torus", "plane", "cube")
MESH_SUFFIXES = (".obj", ".ply", ".stl", ".off", ".glb", ".gltf")

# (name, components) in buffer order; the GLSL attribute is ``in_<name>``.
VERTEX_ATTRIBUTES = (("position", 3), ("normal", 3), ("uv", 2), ("tangent", 3),
                     ("binormal", 3), ("comb", 4))
VERTEX_FLOATS = sum(n for _, n in VERTEX_ATTRIBUTES)


@dataclass
class MeshData:
    """CPU-side mesh in the framework's vertex format (float32 arrays, uint32 triangles)."""

    name: str
    positions: np.ndarray
    normals: np.ndarray
    uvs: np.ndarray
    tangents: np.ndarray
    binormals: np.ndarray
    comb: np.ndarray  # (N, 4) in [0, 1]: tangent-space comb direction packed, length scale
    indices: np.ndarray  # (M, 3)
    has_comb: bool = False  # True when the comb came from the file's vertex colours
    generated_uvs: bool = False

    @property
    def vertex_count(self) -> int:
        return len(self.positions)

    def interleaved(self) -> np.ndarray:
        parts = [self.positions, self.normals, self.uvs, self.tangents, self.binormals, self.comb]
        return np.ascontiguousarray(np.hstack(parts).astype(np.float32))

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return self.positions.min(axis=0), self.positions.max(axis=0)


# -- tangent frames and comb directions ------------------------------------------------------

def _normalize(v: np.ndarray, eps: float = 1e-12) -> np.ndarray:
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(length, eps)


def any_perpendicular(n: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to each row of ``n`` (used where UVs give no tangent)."""
    helper = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    return _normalize(np.cross(n, helper))


def tangent_frames(positions: np.ndarray, normals: np.ndarray, uvs: np.ndarray,
                   indices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-vertex tangent (along +U) and binormal (along +V), orthonormal to the normal.

    Triangle tangents are accumulated per vertex from the UV gradients, then Gram-Schmidt
    orthogonalised against the normal; the binormal is ``cross(n, t)`` flipped to follow +V.
    """
    p0, p1, p2 = (positions[indices[:, i]] for i in range(3))
    w0, w1, w2 = (uvs[indices[:, i]] for i in range(3))
    e1, e2 = p1 - p0, p2 - p0
    d1, d2 = w1 - w0, w2 - w0
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    safe = np.where(np.abs(det) < 1e-20, 1.0, det)[:, None]
    valid = (np.abs(det) >= 1e-20)[:, None]
    tri_t = np.where(valid, (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) / safe, 0.0)
    tri_b = np.where(valid, (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) / safe, 0.0)
    t = np.zeros_like(positions, dtype=np.float64)
    b = np.zeros_like(positions, dtype=np.float64)
    for i in range(3):
        np.add.at(t, indices[:, i], tri_t)
        np.add.at(b, indices[:, i], tri_b)
    n = _normalize(normals.astype(np.float64))
    t = t - np.sum(t * n, axis=1, keepdims=True) * n
    degenerate = np.linalg.norm(t, axis=1) < 1e-10
    t = _normalize(t)
    if degenerate.any():
        t[degenerate] = any_perpendicular(n[degenerate])
    binormal = np.cross(n, t)
    handedness = np.where(np.sum(binormal * b, axis=1) < 0.0, -1.0, 1.0)[:, None]
    return t.astype(np.float32), (binormal * handedness).astype(np.float32)


def comb_to_tangent_space(colors: np.ndarray, normals: np.ndarray, tangents: np.ndarray,
                          binormals: np.ndarray) -> np.ndarray:
    """Revie Listing 2.7: object-space comb colours to tangent-space comb colours.

    ``colors`` is (N, 4) in [0, 1]: RGB an object-space direction packed from [-1, 1], A the fur
    length scale (kept). The direction is Gram-Schmidt projected onto the tangent plane,
    normalised, expressed in the (tangent, binormal, normal) basis and packed back to [0, 1].
    """
    colors = np.asarray(colors, dtype=np.float64)
    n = np.asarray(normals, dtype=np.float64)
    direction = colors[:, :3] * 2.0 - 1.0
    direction = direction - np.sum(direction * n, axis=1, keepdims=True) * n
    # A comb pointing straight along the normal has no tangential part: fall back to the tangent.
    flat = np.linalg.norm(direction, axis=1) < 1e-6
    direction[flat] = tangents[flat]
    direction = _normalize(direction)
    tangent_space = np.stack([np.sum(direction * tangents, axis=1),
                              np.sum(direction * binormals, axis=1),
                              np.sum(direction * n, axis=1)], axis=1)
    out = np.empty_like(colors)
    out[:, :3] = (tangent_space + 1.0) * 0.5
    out[:, 3] = colors[:, 3]
    return out.astype(np.float32)


def default_comb(count: int) -> np.ndarray:
    """Comb colour for meshes without vertex colours: along +tangent, full length."""
    comb = np.tile(np.array([[1.0, 0.5, 0.5, 1.0]], dtype=np.float32), (count, 1))
    return comb


def build_mesh(name: str, positions: np.ndarray, indices: np.ndarray,
               normals: np.ndarray | None = None, uvs: np.ndarray | None = None,
               colors: np.ndarray | None = None) -> MeshData:
    """Complete a mesh to the framework's vertex format (normals, UVs, tangents, comb)."""
    positions = np.asarray(positions, dtype=np.float64)
    indices = np.asarray(indices, dtype=np.int64).reshape(-1, 3)
    if len(positions) == 0 or len(indices) == 0:
        raise InputError("mesh has no triangles", name)
    if not np.isfinite(positions).all():
        raise InputError("mesh has non-finite vertex positions", name)
    if indices.min() < 0 or indices.max() >= len(positions):
        raise InputError("mesh has face indices outside its vertex list", name)
    if normals is None or len(normals) != len(positions) or not np.isfinite(normals).all():
        normals = _vertex_normals(positions, indices)
    normals = _normalize(np.asarray(normals, dtype=np.float64))
    generated = False
    if uvs is None or len(uvs) != len(positions):
        positions, normals, colors, indices, uvs = _unwrap(positions, normals, colors, indices)
        generated = True
    uvs = np.asarray(uvs, dtype=np.float64)
    tangents, binormals = tangent_frames(positions, normals, uvs, indices)
    if colors is not None:
        colors = np.asarray(colors, dtype=np.float64)
        if colors.shape[1] == 3:
            colors = np.hstack([colors, np.ones((len(colors), 1))])
        comb = comb_to_tangent_space(colors, normals, tangents.astype(np.float64),
                                     binormals.astype(np.float64))
    else:
        comb = default_comb(len(positions))
    return MeshData(name=name, positions=positions.astype(np.float32),
                    normals=normals.astype(np.float32), uvs=uvs.astype(np.float32),
                    tangents=tangents, binormals=binormals, comb=comb,
                    indices=indices.astype(np.uint32), has_comb=colors is not None,
                    generated_uvs=generated)


def _vertex_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    p0, p1, p2 = (positions[indices[:, i]] for i in range(3))
    face = np.cross(p1 - p0, p2 - p0)  # area weighted
    normals = np.zeros_like(positions)
    for i in range(3):
        np.add.at(normals, indices[:, i], face)
    bad = np.linalg.norm(normals, axis=1) < 1e-20
    normals[bad] = [0.0, 1.0, 0.0]
    return _normalize(normals)


def _unwrap(positions, normals, colors, indices):
    """Generate UVs with an xatlas unwrap (vertices on seams are split)."""
    import xatlas

    vmapping, new_indices, uvs = xatlas.parametrize(positions.astype(np.float32),
                                                   indices.astype(np.uint32))
    vmapping = vmapping.astype(np.int64)
    colors = None if colors is None else np.asarray(colors)[vmapping]
    return (positions[vmapping], normals[vmapping], colors,
            new_indices.astype(np.int64), uvs.astype(np.float64))


# -- built-in shapes ---------------------------------------------------------------------------

def _grid_indices(rows: int, cols: int) -> np.ndarray:
    """Two triangles per cell of a (rows+1) x (cols+1) vertex grid, counter-clockwise."""
    r, c = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    a = (r * (cols + 1) + c).ravel()
    b = a + 1
    d = a + cols + 1
    e = d + 1
    return np.concatenate([np.stack([a, d, b], 1), np.stack([b, d, e], 1)])


def builtin_sphere(segments: int = 64, rings: int = 32, radius: float = 1.0) -> MeshData:
    u = np.linspace(0.0, 1.0, segments + 1)
    v = np.linspace(0.0, 1.0, rings + 1)
    vv, uu = np.meshgrid(v, u, indexing="ij")
    theta = vv * math.pi  # from +Y down
    phi = uu * 2.0 * math.pi
    normals = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta),
                        np.sin(theta) * np.cos(phi)], -1).reshape(-1, 3)
    uvs = np.stack([uu, 1.0 - vv], -1).reshape(-1, 2)
    indices = _grid_indices(rings, segments)
    return build_mesh("builtin:sphere", normals * radius, indices, normals, uvs)


def builtin_torus(segments: int = 64, sides: int = 32, major: float = 0.7,
                  minor: float = 0.3) -> MeshData:
    u = np.linspace(0.0, 1.0, segments + 1)
    v = np.linspace(0.0, 1.0, sides + 1)
    vv, uu = np.meshgrid(v, u, indexing="ij")
    phi = uu * 2.0 * math.pi  # around the major circle (Y axis)
    theta = vv * 2.0 * math.pi  # around the tube
    centre = np.stack([np.sin(phi) * major, np.zeros_like(phi), np.cos(phi) * major], -1)
    normal = np.stack([np.sin(phi) * np.cos(theta), np.sin(theta), np.cos(phi) * np.cos(theta)], -1)
    positions = (centre + normal * minor).reshape(-1, 3)
    uvs = np.stack([uu, vv], -1).reshape(-1, 2)
    indices = _grid_indices(sides, segments)[:, [0, 2, 1]]  # counter-clockwise seen from outside
    return build_mesh("builtin:torus", positions, indices, normal.reshape(-1, 3), uvs)


def builtin_plane(divisions: int = 32, size: float = 2.0) -> MeshData:
    """A square in the XZ plane facing +Y, ``size`` wide, centred on the origin."""
    t = np.linspace(-0.5, 0.5, divisions + 1) * size
    zz, xx = np.meshgrid(t, t, indexing="ij")
    positions = np.stack([xx, np.zeros_like(xx), zz], -1).reshape(-1, 3)
    normals = np.tile([0.0, 1.0, 0.0], (len(positions), 1))
    uvs = np.stack([xx / size + 0.5, 0.5 - zz / size], -1).reshape(-1, 2)
    indices = _grid_indices(divisions, divisions)
    return build_mesh("builtin:plane", positions, indices, normals, uvs)


def builtin_cube(size: float = 1.5) -> MeshData:
    positions, normals, uvs, indices = [], [], [], []
    h = size / 2.0
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = np.zeros(3)
            n[axis] = sign
            u_axis = np.zeros(3)
            u_axis[(axis + 1) % 3] = 1.0
            v_axis = np.cross(n, u_axis)
            base = len(positions)
            for cu, cv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                positions.append(n * h + (cu * 2 - 1) * h * u_axis + (cv * 2 - 1) * h * v_axis)
                normals.append(n)
                uvs.append((cu, cv))
            indices += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    return build_mesh("builtin:cube", np.array(positions), np.array(indices),
                      np.array(normals), np.array(uvs, dtype=np.float64))


_BUILTINS = {"sphere": builtin_sphere, "torus": builtin_torus, "plane": builtin_plane,
             "cube": builtin_cube}


# -- loading -----------------------------------------------------------------------------------

# Bounds of the built-in shapes' integer arguments (subdivision counts); float arguments
# (sizes, radii) must be finite and positive.
BUILTIN_COUNT_RANGE = (3, 4096)


def builtin_arguments(spec: str, where: str | None = None) -> tuple[str, dict[str, int | float]]:
    """``builtin:torus?segments=78&sides=60`` -> ``("torus", {"segments": 78, "sides": 60})``.

    The arguments are keyword arguments of the shape's function (``builtin_torus``...), each
    parsed as its annotation says (int or float); an unknown shape or key, a bad number or a
    value out of range is an ``InputError`` naming ``where`` (default: the spec).
    """
    where = where or spec
    shape, _, query = spec.removeprefix(BUILTIN_PREFIX).partition("?")
    if shape not in _BUILTINS:
        raise InputError(f"unknown built-in mesh '{BUILTIN_PREFIX}{shape}' (choose from "
                         f"{', '.join(BUILTIN_PREFIX + n for n in BUILTIN_MESHES)})", where)
    parameters = inspect.signature(_BUILTINS[shape], eval_str=True).parameters
    kinds = {name: parameter.annotation for name, parameter in parameters.items()}
    arguments: dict[str, int | float] = {}
    for item in filter(None, query.split("&")):
        key, equals, text = (part.strip() for part in item.partition("="))
        if key not in kinds:
            raise InputError(f"builtin:{shape} has no parameter '{key}' (parameters: "
                             f"{', '.join(kinds)})", where)
        if not equals or not text:
            raise InputError(f"builtin:{shape} parameter '{key}' has no value "
                             f"(write {key}=NUMBER)", where)
        if key in arguments:
            raise InputError(f"builtin:{shape} parameter '{key}' is given twice", where)
        arguments[key] = _builtin_argument(shape, key, text, kinds[key], where)
    return shape, arguments


def _builtin_argument(shape: str, key: str, text: str, kind: type, where: str) -> int | float:
    if kind is int:
        try:
            value = int(text)
        except ValueError:
            raise InputError(f"builtin:{shape} parameter '{key}' must be an integer, got "
                             f"'{text}'", where) from None
        low, high = BUILTIN_COUNT_RANGE
        if not low <= value <= high:
            raise InputError(f"builtin:{shape} parameter '{key}' must be {low}..{high}, got "
                             f"{value}", where)
        return value
    try:
        number = float(text)
    except ValueError:
        raise InputError(f"builtin:{shape} parameter '{key}' must be a number, got '{text}'",
                         where) from None
    if not math.isfinite(number) or number <= 0.0:
        raise InputError(f"builtin:{shape} parameter '{key}' must be finite and greater than "
                         f"0, got {text}", where)
    return number


def load_mesh(spec: str, base_dir: Path | None = None, where: str | None = None) -> MeshData:
    """Load ``builtin:<name>`` or a mesh file (relative paths resolve against ``base_dir``).

    Built-in shapes take their function's keyword arguments as a query:
    ``builtin:torus?segments=78&sides=60`` (see :func:`builtin_arguments`); the mesh is still
    named ``builtin:torus``.
    """
    where = where or spec
    if spec.startswith(BUILTIN_PREFIX):
        shape, arguments = builtin_arguments(spec, where)
        return _BUILTINS[shape](**arguments)
    path = Path(spec)
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    if not path.is_file():
        raise InputError(f"mesh file not found: {path}", where)
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise InputError(f"unsupported mesh format '{path.suffix}' "
                         f"(use {', '.join(MESH_SUFFIXES)})", where)
    import trimesh

    try:
        loaded = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many exception types
        raise InputError(f"cannot read mesh {path.name}: {exc}", where) from None
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
        return build_mesh(path.name, positions, indices, normals, uvs, colors)
    except InputError as exc:
        raise InputError(exc.message, where) from None


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


# -- GPU side ----------------------------------------------------------------------------------

@dataclass
class GpuMesh:
    """A mesh's vertex and index buffers, with one vertex array per program using it."""

    ctx: moderngl.Context
    data: MeshData
    vbo: moderngl.Buffer = field(init=False)
    ibo: moderngl.Buffer = field(init=False)
    _arrays: dict[int, moderngl.VertexArray] = field(init=False, default_factory=dict)

    def __post_init__(self) -> None:
        self.vbo = self.ctx.buffer(self.data.interleaved().tobytes())
        self.ibo = self.ctx.buffer(self.data.indices.astype(np.uint32).tobytes())

    def vertex_buffer(self, program: moderngl.Program) -> tuple:
        """The vertex buffer with the format of the attributes ``program`` reads (moderngl's
        ``(buffer, format, *names)``), for vertex arrays over other index buffers too."""
        fmt, names = [], []
        for name, count in VERTEX_ATTRIBUTES:
            attribute = f"in_{name}"
            if attribute in program:
                fmt.append(f"{count}f")
                names.append(attribute)
            else:
                fmt.append(f"{count * 4}x")
        return (self.vbo, " ".join(fmt), *names)

    def vertex_array(self, program: moderngl.Program) -> moderngl.VertexArray:
        vao = self._arrays.get(program.glo)
        if vao is None:
            vao = self.ctx.vertex_array(program, [self.vertex_buffer(program)],
                                        index_buffer=self.ibo, index_element_size=4)
            self._arrays[program.glo] = vao
        return vao

    def render(self, program: moderngl.Program, instances: int = 1) -> None:
        self.vertex_array(program).render(moderngl.TRIANGLES, instances=instances)

    def release(self) -> None:
        for vao in self._arrays.values():
            vao.release()
        self._arrays.clear()
        self.vbo.release()
        self.ibo.release()
