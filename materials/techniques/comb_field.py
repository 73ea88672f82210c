"""The comb field: one comb direction per vertex, smooth over the mesh, for the fur's lean and
grain (Revie 2.3.1, 2.3.3, 2.4.1).

A constant object-space ``comb`` projected onto each tangent plane vanishes where the normal is
parallel to it (a sphere's poles) and flips across ridges (a torus's): a per-triangle fallback
there shows as a spot of arbitrary directions or a sharp parting. A tangent field on a sphere
must vanish somewhere (the hairy-ball theorem), so the aim is a singularity that reads as fur's
crown or whorl. Here:

- The comb is projected onto each vertex's tangent plane (vertices welded across UV seams share
  one value, ``topology.weld``); its tangential length says how well it is defined there.
- The unit directions are smoothed over the mesh's edges (trimesh's unique edges): each step a
  vertex takes the normalised sum of its own and its neighbours' directions plus its projected
  comb weighted by that length (the anchor), projected onto its tangent plane. Where the comb is
  well defined the anchor keeps it; near a pole or a ridge the neighbours decide, so the
  direction turns continuously instead of jumping. A vertex whose comb projects to nothing
  takes its direction from its neighbours.
- The lean is the coherence of the neighbourhood (the length of the mean of a vertex's and its
  neighbours' directions, 1 where they agree): it falls to 0 at a singular vertex, so strands
  stand up in the crown instead of leaning every way; spread over a few edges (never above the
  coherence) so they rise gently rather than as a tuft.

Vertex-colour combs (``comb_directions``) are anchored hard: they are kept as painted, and only
the vertices where they project to nothing are filled from their neighbours.
"""

from __future__ import annotations

import math

import moderngl
import numpy as np
import trimesh

from deferred.api import MeshData

from .topology import weld

SMOOTHING_STEPS = 48  # smoothing steps: a singularity spreads over about their root in edges
ANCHOR = 0.1  # pull of the projected comb, per unit of its tangential length and neighbour
LEAN_STEPS = 6  # edges over which the lean falls to 0 at a singular vertex
FIELD_WIDTH = 1024  # texels per row of the per-vertex field texture (fur.vert)
_DEFINED = 1e-3  # a tangential comb shorter than this (of its length) is no direction


def _unit(v: np.ndarray, least: float = 1e-12) -> tuple[np.ndarray, np.ndarray]:
    length = np.linalg.norm(v, axis=-1)
    return np.where(length[:, None] > least, v / np.maximum(length, 1e-300)[:, None], 0.0), \
        length


def _tangential(v: np.ndarray, n: np.ndarray) -> np.ndarray:
    return v - np.einsum("ij,ij->i", v, n)[:, None] * n


def _group_mean(values: np.ndarray, welded: np.ndarray, groups: int) -> np.ndarray:
    return np.stack([np.bincount(welded, values[:, c], minlength=groups)
                     for c in range(values.shape[1])], -1)


class _Neighbours:
    """Sums over each welded vertex's edge neighbours (both directions of every unique edge)."""

    def __init__(self, positions: np.ndarray, faces: np.ndarray, welded: np.ndarray,
                 groups: int):
        welded_faces = welded[faces]
        keep = (welded_faces[:, 0] != welded_faces[:, 1]) & \
            (welded_faces[:, 1] != welded_faces[:, 2]) & (welded_faces[:, 2] != welded_faces[:, 0])
        edges = trimesh.Trimesh(vertices=positions, faces=welded_faces[keep],
                                process=False).edges_unique
        self.source = np.concatenate([edges[:, 0], edges[:, 1]])
        self.target = np.concatenate([edges[:, 1], edges[:, 0]])
        self.groups = groups
        self.degree = np.bincount(self.target, minlength=groups).astype(np.float64)

    def sum(self, values: np.ndarray) -> np.ndarray:
        return np.stack([np.bincount(self.target, values[self.source, c],
                                     minlength=self.groups) for c in range(values.shape[1])], -1)


def comb_field(mesh: MeshData, comb: tuple[float, float, float] | None = None,
               steps: int = SMOOTHING_STEPS) -> np.ndarray:
    """(V, 3) object-space comb per vertex: the unit direction times the lean (0 .. 1).

    With ``comb`` the object-space comb projected and smoothed over ``steps`` edges; without it,
    the mesh's vertex-colour comb (``mesh.comb``, tangent space), kept where it is defined and
    filled from the neighbours where it is not (see the module documentation)."""
    positions = np.asarray(mesh.positions, np.float64)
    faces = np.asarray(mesh.indices, np.int64).reshape(-1, 3)
    welded = weld(positions)
    groups = int(welded.max()) + 1
    counts = np.bincount(welded, minlength=groups).astype(np.float64)[:, None]
    normal, _ = _unit(_group_mean(np.asarray(mesh.normals, np.float64), welded, groups))
    first = np.zeros(groups, np.int64)
    first[welded[::-1]] = np.arange(len(welded))[::-1]  # a vertex of each group
    neighbours = _Neighbours(positions[first], faces, welded, groups)
    if comb is not None:
        given = np.asarray(comb, np.float64)
        anchor_weight = ANCHOR
        projected = _tangential(np.broadcast_to(given / np.linalg.norm(given), (groups, 3)),
                                normal)
    else:
        # the painted comb, back to object space (the mesh holds it in tangent space)
        packed = np.asarray(mesh.comb, np.float64)[:, :3] * 2.0 - 1.0
        frame = (np.asarray(mesh.tangents, np.float64), np.asarray(mesh.binormals, np.float64),
                 np.asarray(mesh.normals, np.float64))
        painted = sum(packed[:, k:k + 1] * frame[k] for k in range(3))
        painted, _ = _unit(_tangential(painted, np.asarray(mesh.normals, np.float64)))
        projected = _tangential(_group_mean(painted, welded, groups) / counts, normal)
        anchor_weight = 1e3  # kept as painted
    direction, strength = _unit(projected)
    defined = strength > _DEFINED
    anchor = direction * (anchor_weight * strength * neighbours.degree)[:, None]
    field = direction
    for _ in range(steps if comb is not None else max(steps, 1)):
        total = _tangential(field + neighbours.sum(field) + anchor, normal)
        # directions that cancel (a parting the comb asks for, symmetric) stay cancelled:
        # normalising what rounding leaves would pick a direction at random
        field, _ = _unit(total, 1e-6)
        if comb is None and defined.all():
            break
    if comb is None:
        field = np.where(defined[:, None], direction, field)
    coherence = np.linalg.norm(field + neighbours.sum(field), axis=-1) / (1.0 + neighbours.degree)
    lean = np.clip((coherence - 0.2) / 0.6, 0.0, 1.0)
    lean = lean * lean * (3.0 - 2.0 * lean)  # smoothstep: 0 in the crown, 1 where it agrees
    # spread over a few rings, never above the coherence: strands rise gently into the crown
    spread = lean[:, None]
    for _ in range(LEAN_STEPS):
        spread = (spread + neighbours.sum(spread)) / (1.0 + neighbours.degree[:, None])
    lean = np.minimum(lean, spread[:, 0])
    if comb is None:
        lean = np.where(defined, 1.0, lean)  # a painted comb leans as painted
    return (field * lean[:, None])[welded]


def comb_field_texture(ctx: moderngl.Context, field: np.ndarray) -> moderngl.Texture:
    """The field as ``u_comb_field`` (fur.vert): RGBA32F, vertex i at texel i of rows of
    :data:`FIELD_WIDTH`, fetched by ``gl_VertexID``."""
    rows = max(1, math.ceil(len(field) / FIELD_WIDTH))
    data = np.zeros((rows * FIELD_WIDTH, 4), np.float32)
    data[:len(field), :3] = field
    texture = ctx.texture((FIELD_WIDTH, rows), 4, data.tobytes(), dtype="f4")
    texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
    return texture
