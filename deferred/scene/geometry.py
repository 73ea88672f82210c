"""A mesh's geometry made into the framework's vertex format (:class:`deferred.gl.meshes.MeshData`):
checked first (:func:`check_geometry`: no triangles, non-finite or absurd coordinates, face
indices outside the vertex list, only zero-area faces, or more than ``MAX_TRIANGLES`` /
``MAX_VERTICES`` are an ``InputError`` naming the mesh), then missing normals computed
(area-weighted face normals), missing UVs unwrapped (:mod:`deferred.scene.unwrap`), tangent
frames built from the UVs and fur comb directions taken to tangent space (Revie Listing 2.7).

The coordinate limits come from float32, which the GPU and xatlas compute in: a coordinate beyond
``MAX_COORDINATE`` (1e6) is a stray vertex or the wrong units (squares of large coordinates
overflow float32: xatlas never finishes on a sphere scaled by 1e20), and a mesh spanning more
than ``MAX_SPAN_TO_EDGE`` (1e6) times its median edge length has edges of a few float32 steps
of its size, and xatlas slows down with the ratio (a small mesh with one stray vertex takes
it seconds).
"""
from __future__ import annotations

import numpy as np

from deferred.errors import InputError
from deferred.gl.meshes import MeshData
from deferred.scene.unwrap import unwrap_vertices

# Input limits (checked before xatlas unwraps a mesh).
MAX_TRIANGLES = 5_000_000
MAX_VERTICES = 10_000_000
MAX_COORDINATE = 1e6
MAX_SPAN_TO_EDGE = 1e6

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
    if colors is not None and not np.isfinite(np.asarray(colors, dtype=np.float64)).all():
        # they carry the fur's comb (Revie 2.4.1): a NaN direction is no direction
        raise InputError("mesh has non-finite vertex colours (NaN or infinity)", name)
    if uvs is None or len(uvs) != len(positions):
        positions, normals, colors, indices, uvs = unwrap_vertices(positions, normals, colors,
                                                                   indices, name)
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
