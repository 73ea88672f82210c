"""Meshes: loading through trimesh, built-in shapes, tangent frames and fur comb directions.

Every mesh the framework draws has the same vertex format (``VERTEX_ATTRIBUTES``): position,
normal, UV, tangent, binormal and the RGBA *comb* colour of Revie section 2.4.1 (RGB: comb
direction in tangent space packed from [-1, 1] to [0, 1]; A: fur length scale). Files load through
trimesh; missing normals are computed (area-weighted face normals), missing UVs come from an
xatlas unwrap, tangent frames are built from the UVs.

Every mesh is checked before any of that (:func:`check_geometry`): no triangles, non-finite or
absurd coordinates, face indices outside the vertex list, only zero-area faces, or more than
``MAX_TRIANGLES`` / ``MAX_VERTICES`` are an ``InputError`` naming the mesh. The coordinate limits
come from float32, which the GPU and xatlas compute in: a coordinate beyond ``MAX_COORDINATE``
(1e6) is a stray vertex or the wrong units (squares of large coordinates overflow float32:
xatlas never finishes on a sphere scaled by 1e20), and a mesh spanning more than
``MAX_SPAN_TO_EDGE`` (1e6) times its median edge length has edges of a few float32 steps of its
size, and xatlas slows down with the ratio (measured: 0.6 s for a 320-triangle sphere with one
vertex moved to 1e6, 1.7 s for two triangles with one corner at 1e8). The
unwrap itself runs in a child process with a time limit (``UNWRAP_TIMEOUT_S``, environment
variable ``DEFERRED_UNWRAP_TIMEOUT``), so a mesh that still defeats it is an error after that
time and Ctrl-C stops it (inside xatlas, the interpreter never sees the signal).
"""

from __future__ import annotations

import inspect
import math
import multiprocessing
import os
import signal
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from deferred.errors import InputError
from deferred.gl.meshes import MeshData
from deferred.validation import require_regular_file

BUILTIN_PREFIX = "builtin:"
BUILTIN_MESHES = ("sphere", "torus", "plane", "cube")
MESH_SUFFIXES = (".obj", ".ply", ".stl", ".off", ".glb", ".gltf")

# Input limits (module doc; checked before trimesh parses a file or xatlas unwraps a mesh).
MAX_MESH_FILE_BYTES = 1 << 30  # a 5M-triangle OBJ with normals and UVs is about 0.5 GB
MAX_TRIANGLES = 5_000_000
MAX_VERTICES = 10_000_000
MAX_COORDINATE = 1e6
MAX_SPAN_TO_EDGE = 1e6
UNWRAP_TIMEOUT_S = 60.0
UNWRAP_TIMEOUT_ENV = "DEFERRED_UNWRAP_TIMEOUT"

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
    check_geometry(name, positions, indices)
    if normals is None or len(normals) != len(positions) or not np.isfinite(normals).all():
        normals = _vertex_normals(positions, indices)
    normals = _normalize(np.asarray(normals, dtype=np.float64))
    generated = False
    if uvs is not None and len(uvs) == len(positions) and not np.isfinite(uvs).all():
        raise InputError("mesh has non-finite UVs (NaN or infinity)", name)
    if uvs is None or len(uvs) != len(positions):
        positions, normals, colors, indices, uvs = _unwrap(positions, normals, colors, indices,
                                                           name)
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


def check_geometry(name: str, positions: np.ndarray, indices: np.ndarray) -> None:
    """``InputError`` (naming ``name``) for a mesh the framework cannot draw or unwrap: too
    large, no triangles, non-finite or absurd coordinates, indices outside the vertex list, or
    only zero-area faces (limits and why: module doc). Cheap next to the unwrap it guards."""
    if len(indices) > MAX_TRIANGLES:
        raise InputError(f"mesh has {len(indices):,} triangles, more than the "
                         f"{MAX_TRIANGLES:,} the framework draws; simplify it", name)
    if len(positions) > MAX_VERTICES:
        raise InputError(f"mesh has {len(positions):,} vertices, more than the "
                         f"{MAX_VERTICES:,} the framework draws; simplify it", name)
    if len(positions) == 0 or len(indices) == 0:
        raise InputError("mesh has no triangles", name)
    finite = np.isfinite(positions).all(axis=1)
    if not finite.all():
        raise InputError(f"mesh has non-finite vertex positions (NaN or infinity; first: vertex "
                         f"{int(np.argmin(finite))}, counting from 0)", name)
    if indices.min() < 0 or indices.max() >= len(positions):
        raise InputError(f"mesh has face indices outside its vertex list (0..{len(positions) - 1}"
                         f"; found {int(indices.min())}..{int(indices.max())})", name)
    largest = float(np.abs(positions).max())
    if largest > MAX_COORDINATE:
        vertex = int(np.argmax(np.abs(positions).max(axis=1)))
        raise InputError(f"mesh has a coordinate of {largest:.3g} (vertex {vertex}, counting "
                         f"from 0), beyond +-{MAX_COORDINATE:.0e}: a stray vertex or the wrong "
                         f"units? (scale the object in the scene instead)", name)
    used = positions[np.unique(indices)]
    span = float((used.max(axis=0) - used.min(axis=0)).max())
    # Doubled face areas; "zero" relative to the mesh's size, as float32 would see it.
    areas = np.linalg.norm(np.cross(positions[indices[:, 1]] - positions[indices[:, 0]],
                                    positions[indices[:, 2]] - positions[indices[:, 0]]), axis=1)
    if span == 0.0 or not (areas > 1e-14 * span * span).any():
        raise InputError(f"mesh is degenerate: none of its {len(indices):,} triangles has an "
                         f"area (corners coincide or lie on a line)", name)
    # The median edge, from a sample of the faces on large meshes (a median does not need all).
    sample = indices[::max(1, len(indices) // 1_000_000)]
    edges = np.concatenate([np.linalg.norm(positions[sample[:, (i + 1) % 3]]
                                           - positions[sample[:, i]], axis=1) for i in range(3)])
    edges = edges[edges > 0.0]
    median = float(np.median(edges))
    if span > MAX_SPAN_TO_EDGE * median:
        raise InputError(f"mesh spans {span:.3g} units but its median edge is {median:.3g} "
                         f"({span / median:.2g} times smaller, limit {MAX_SPAN_TO_EDGE:.0e}): a "
                         f"stray vertex far from the rest?", name)


def _unwrap(positions: np.ndarray, normals: np.ndarray, colors: np.ndarray | None,
            indices: np.ndarray, name: str = "mesh"):
    """Generate UVs with an xatlas unwrap (vertices on seams are split)."""
    vmapping, new_indices, uvs = unwrap_uvs(positions, indices, name)
    # xatlas leaves the corners of triangles too thin for it (relative to float32) without a
    # chart: NaN. Such a triangle covers no texel; they take (0, 0). None charted: degenerate.
    charted = np.isfinite(uvs).all(axis=1)
    if not charted.any():
        raise InputError(f"mesh is degenerate: the UV unwrap found no triangle with an area "
                         f"among its {len(indices):,} (give the mesh UVs)", name)
    uvs = np.where(charted[:, None], uvs, 0.0)
    vmapping = vmapping.astype(np.int64)
    colors = None if colors is None else np.asarray(colors)[vmapping]
    return (positions[vmapping], normals[vmapping], colors,
            new_indices.astype(np.int64), uvs.astype(np.float64))


def unwrap_timeout() -> float:
    """Seconds an unwrap may take: ``DEFERRED_UNWRAP_TIMEOUT`` or ``UNWRAP_TIMEOUT_S``."""
    text = os.environ.get(UNWRAP_TIMEOUT_ENV)
    if text is None or not text.strip():
        return UNWRAP_TIMEOUT_S
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    if not (math.isfinite(seconds) and seconds > 0.0):
        raise InputError(f"environment variable {UNWRAP_TIMEOUT_ENV} must be a number of "
                         f"seconds greater than 0, got '{text}'")
    return seconds


def _xatlas_parametrize(positions: np.ndarray, indices: np.ndarray):
    import xatlas

    return xatlas.parametrize(positions, indices)


def _die_with_parent(parent: int) -> None:
    """Linux: the kernel kills this process when its parent dies, even by SIGKILL (the OOM
    killer), which leaves no ``finally`` to end a hung unwrap."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:  # the parent died before prctl: nobody waits for the result
        os._exit(1)


def _unwrap_child(connection, positions: np.ndarray, indices: np.ndarray,
                  parent: int) -> None:
    """The unwrap process: xatlas, then the arrays (or the error) back through the pipe."""
    # Ctrl-C is the parent's to handle (it ends this process), and so is SIGTERM: a handler
    # forked from the parent (deferred.io.safety's) would turn the parent's terminate()
    # into an exception here. xatlas' ASSERT lines and a traceback from here would break the
    # command line's one-line errors.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _die_with_parent(parent)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)
    sys.stdout = sys.stderr = open(os.devnull, "w")  # noqa: SIM115 - the process's whole life
    try:
        result = ("ok", _xatlas_parametrize(positions, indices))
    except Exception as exc:  # noqa: BLE001 - reported by the parent, naming the mesh
        result = ("error", f"{type(exc).__name__}: {exc}")
    connection.send(result)
    connection.close()


def _process_context():
    # fork: the child starts in about 10 ms with the arrays already in its memory (spawn: about
    # 300 ms to import numpy and xatlas again); spawn where fork is missing or unsafe (macOS).
    if sys.platform != "darwin" and "fork" in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("fork")
    return multiprocessing.get_context("spawn")


def unwrap_uvs(positions: np.ndarray, indices: np.ndarray,
               name: str = "mesh") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """xatlas' ``(vmapping, indices, uvs)`` for a mesh, computed in a child process.

    xatlas can run for ever on a bad mesh and, inside C++, ignores Ctrl-C: the child is ended
    after :func:`unwrap_timeout` seconds (an ``InputError`` naming ``name``) or when the wait
    here is interrupted. A crash of the child is an ``InputError`` too.
    """
    limit = unwrap_timeout()
    context = _process_context()
    receiver, sender = context.Pipe(duplex=False)
    child = context.Process(target=_unwrap_child, daemon=True, name=f"unwrap {name}",
                            args=(sender, np.ascontiguousarray(positions, dtype=np.float32),
                                  np.ascontiguousarray(indices, dtype=np.uint32), os.getpid()))
    try:
        with warnings.catch_warnings():
            # Python 3.12+ warns that forking a threaded process (GL drivers, BLAS) may
            # deadlock the child; ours runs numpy and xatlas only, and the time limit bounds it.
            warnings.filterwarnings("ignore", message=".*fork.*", category=DeprecationWarning)
            child.start()
        sender.close()  # the child holds the only writing end: its exit ends the wait below
        deadline = time.monotonic() + limit
        # short polls: a pending Ctrl-C is raised here at the latest a quarter second later
        while not receiver.poll(min(0.25, max(0.0, deadline - time.monotonic()))):
            if time.monotonic() >= deadline:
                raise InputError(f"UV unwrap did not finish in {limit:g} s; give the mesh UVs "
                                 f"or simplify it", name)
        try:
            status, payload = receiver.recv()
        except EOFError:
            child.join(5.0)
            code = child.exitcode
            how = f"signal {-code}" if code is not None and code < 0 else f"exit code {code}"
            raise InputError(f"UV unwrap failed: the unwrapping process died ({how}; out of "
                             f"memory?); give the mesh UVs or simplify it", name) from None
        child.join(2.0)  # it only has to exit now
        if status != "ok":
            raise InputError(f"UV unwrap failed: {payload}; give the mesh UVs", name)
        return payload
    finally:
        receiver.close()
        if child.is_alive():  # out of time, interrupted, or the wait itself failed
            child.terminate()
            child.join(1.0)
            if child.is_alive():
                child.kill()
        child.join()


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
BUILTIN_SIZE_MAX = 1e4
# Triangles each shape makes from its arguments (with defaults): checked before it is built.
_BUILTIN_TRIANGLES = {
    "sphere": lambda a: 2 * a["segments"] * a["rings"],
    "torus": lambda a: 2 * a["segments"] * a["sides"],
    "plane": lambda a: 2 * a["divisions"] ** 2,
}


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
    if shape in _BUILTIN_TRIANGLES:
        counted = {name: p.default for name, p in parameters.items()} | arguments
        triangles = _BUILTIN_TRIANGLES[shape](counted)
        if triangles > MAX_TRIANGLES:
            raise InputError(f"builtin:{shape} with these arguments has {triangles:,} "
                             f"triangles, more than the {MAX_TRIANGLES:,} a mesh may have",
                             where)
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
    if not math.isfinite(number) or not 0.0 < number <= BUILTIN_SIZE_MAX:
        raise InputError(f"builtin:{shape} parameter '{key}' must be greater than 0 and at "
                         f"most {BUILTIN_SIZE_MAX:g}, got {text}", where)
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
    require_regular_file(path, "mesh file", where)
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise InputError(f"unsupported mesh format '{path.suffix}' "
                         f"(use {', '.join(MESH_SUFFIXES)})", where)
    size = path.stat().st_size
    if size > MAX_MESH_FILE_BYTES:  # before trimesh spends minutes and gigabytes parsing it
        raise InputError(f"mesh file {path.name} is {size:,} bytes, more than the "
                         f"{MAX_MESH_FILE_BYTES:,} the framework reads; simplify it", where)
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
        return build_mesh(path.name, positions, indices, normals, uvs, colors)
    except InputError as exc:
        # ``where`` is a scene key (``scene.toml: object[0].mesh``): say which file too
        message = exc.message if where == spec else f"{path.name}: {exc.message}"
        raise InputError(message, where) from None


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
