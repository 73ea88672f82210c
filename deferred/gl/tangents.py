"""Tangents with their handedness for normal maps, where a mesh file gives none.

glTF asks for MikkTSpace tangents (Mikkelsen 2008) when a file has no ``TANGENT``: a normal
map baked against them is reproduced only with the same frame. No maintained package on PyPI
computes them (``pymikktspace``, the one binding, is unmaintained and does not build with
Cython 3), so :func:`mikktspace_tangents` follows MikkTSpace's weighting per vertex: each
corner's face tangent (the triangle's direction of +U) projected into the tangent plane of
the corner's vertex normal and normalised, weighted by the corner's angle, summed over the
faces at the vertex and normalised; the handedness is the sign of the bitangent summed the
same way against ``cross(n, t)``. It equals MikkTSpace's result where MikkTSpace would not
split a vertex (the faces around it agree on their handedness and roughly on their tangent
direction, as they do inside a UV chart of a file whose vertices are split at UV seams); at a
vertex MikkTSpace would split, it gives one averaged frame.
"""

from __future__ import annotations

import numpy as np


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-20)


def mikktspace_tangents(positions: np.ndarray, normals: np.ndarray, uvs: np.ndarray,
                        indices: np.ndarray) -> np.ndarray:
    """``(N, 4)`` float32: per vertex the unit tangent along +U, orthogonal to the normal, and
    in ``w`` the handedness (+1 or -1) such that ``cross(n, t) * w`` runs along +V."""
    positions = np.asarray(positions, dtype=np.float64)
    normals = _unit(np.asarray(normals, dtype=np.float64))
    uvs = np.asarray(uvs, dtype=np.float64)
    faces = np.asarray(indices, dtype=np.int64).reshape(-1, 3)
    p = positions[faces]  # (F, 3 corners, 3)
    w = uvs[faces]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = w[:, 1] - w[:, 0], w[:, 2] - w[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    valid = np.abs(det) > 1e-20
    sign = np.where(det < 0.0, -1.0, 1.0)[:, None]
    # the face's +U and +V directions (their lengths dropped, as MikkTSpace drops them)
    face_t = np.where(valid[:, None], (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * sign, 0.0)
    face_b = np.where(valid[:, None], (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * sign, 0.0)
    tangent_sum = np.zeros_like(positions)
    bitangent_sum = np.zeros_like(positions)
    for corner in range(3):
        vertex = faces[:, corner]
        to_next = _unit(p[:, (corner + 1) % 3] - p[:, corner])
        to_prev = _unit(p[:, (corner + 2) % 3] - p[:, corner])
        angle = np.arccos(np.clip(np.sum(to_next * to_prev, axis=1), -1.0, 1.0))[:, None]
        n = normals[vertex]
        t = _unit(face_t - np.sum(face_t * n, axis=1, keepdims=True) * n)
        b = _unit(face_b - np.sum(face_b * n, axis=1, keepdims=True) * n)
        np.add.at(tangent_sum, vertex, t * angle)
        np.add.at(bitangent_sum, vertex, b * angle)
    t = tangent_sum - np.sum(tangent_sum * normals, axis=1, keepdims=True) * normals
    flat = np.linalg.norm(t, axis=1) < 1e-12
    if flat.any():  # no UV gradient reaches the vertex: any direction in its tangent plane
        axis = np.where(np.abs(normals[flat, 0:1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        t[flat] = np.cross(normals[flat], axis)
    t = _unit(t)
    handedness = np.where(np.sum(np.cross(normals, t) * bitangent_sum, axis=1) < 0.0, -1.0, 1.0)
    return np.hstack([t, handedness[:, None]]).astype(np.float32)
