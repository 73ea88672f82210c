"""One-particle mass-spring strands (Silva et al. section 3.2.1, Eq. 2 and 3).

Each triangle carries one virtual strand: its root ``p_root`` at the triangle's centroid, its rest
tip ``p_0 = p_root + n L_0`` along the face normal, and a particle of mass ``m`` at the tip,
pulled back toward ``p_0`` by a spring of constant ``k``. External forces (gravity, wind) move
it by Newton's law (Eq. 2), integrated at a fixed time step, the spring and a linear damping
force ``-c v`` (not in the paper, whose spring alone would ring forever) taken implicitly:

    v' = (v + dt (f_ext / m - (k / m)(p - p_0))) / (1 + dt c / m + dt^2 k / m),  p' = p + dt v'

which is stable for any stiffness, damping and step (explicit damping diverges once
dt c / m > 2) and rests exactly where ``k (p - p_0) = f_ext``. After every step the tip is
projected back into the region of Eq. 3: no farther than ``L_0`` from the root and never below
the surface, ``(p - p_root) . n >= 0``; its velocity is what the projected step moved it.

The layers of the fur follow a quadratic Bezier from ``p_root`` to ``p`` (the vertex shader,
``shaders/materials/shell_fur/strand.glsl``). The shader receives each vertex's tip deflection
``p - p_0``: the area-weighted mean of its triangles', in object space.

All positions are world space, vectorised over triangles (numpy).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from deferred.api import MeshData

from .topology import weld


@dataclass(frozen=True)
class StrandForces:
    """What acts on the strands during one step (world units, SI-like)."""

    stiffness: float  # k, force per unit of stretch
    mass: float  # m
    damping: float  # c, force per unit of velocity
    gravity: np.ndarray  # (3,) acceleration
    wind: np.ndarray  # (3,) force, or (T, 3) per strand (gusts vary over the surface)


class StrandSimulation:
    """The strands of one object (see the module documentation)."""

    def __init__(self, roots: np.ndarray, normals: np.ndarray, lengths: np.ndarray):
        self.roots = np.asarray(roots, np.float64)
        self.normals = np.asarray(normals, np.float64)
        self.lengths = np.asarray(lengths, np.float64)
        self.rest = self.roots + self.normals * self.lengths[:, None]  # p_0
        self.reset()

    def move(self, roots: np.ndarray, normals: np.ndarray, lengths: np.ndarray) -> None:
        """Put the roots where the object has moved them (its transform at this step); the
        tips stay where they are in the world, so the strands trail a moving object."""
        self.roots = np.asarray(roots, np.float64)
        self.normals = np.asarray(normals, np.float64)
        self.lengths = np.asarray(lengths, np.float64)
        self.rest = self.roots + self.normals * self.lengths[:, None]
        self.tips = self.constrain(self.tips)

    def reset(self) -> None:
        self.tips = self.rest.copy()  # p
        self.velocities = np.zeros_like(self.tips)

    def step(self, dt: float, forces: StrandForces) -> None:
        """Advance by ``dt`` (Eq. 2, see the module documentation), then constrain (Eq. 3)."""
        m = forces.mass
        external = forces.mass * forces.gravity + forces.wind
        spring = forces.stiffness * (self.tips - self.rest)
        velocities = (self.velocities + dt * (external - spring) / m) / \
            (1.0 + dt * forces.damping / m + dt * dt * forces.stiffness / m)
        moved = self.tips + dt * velocities
        constrained = self.constrain(moved)
        self.velocities = (constrained - self.tips) / dt
        self.tips = constrained

    def constrain(self, tips: np.ndarray) -> np.ndarray:
        """``tips`` projected into the region of Eq. 3 (hemisphere of radius L_0 above the
        surface)."""
        offset = tips - self.roots
        height = np.einsum("ij,ij->i", offset, self.normals)
        offset = offset - np.minimum(height, 0.0)[:, None] * self.normals
        length = np.linalg.norm(offset, axis=-1)
        scale = np.where(length > self.lengths, self.lengths / np.maximum(length, 1e-300), 1.0)
        return self.roots + offset * scale[:, None]

    def deflections(self) -> np.ndarray:
        """(T, 3) ``p - p_0`` per strand."""
        return self.tips - self.rest


def triangle_strands(mesh: MeshData, model: np.ndarray,
                     fur_length: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World roots (centroids), unit face normals and world strand lengths of each triangle:
    ``fur_length`` object units along the normal, times the mean length scale of the
    triangle's vertices (the vertex colour alpha, Revie 2.4.1), measured in world units.
    Triangles without area get a zero length (their strand never moves)."""
    faces = np.asarray(mesh.indices, dtype=np.int64).reshape(-1, 3)
    positions = np.asarray(mesh.positions, np.float64)
    linear = model[:3, :3]
    world = positions @ linear.T + model[:3, 3]
    p = world[faces]
    cross = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    norm = np.linalg.norm(cross, axis=-1)
    normals = np.where(norm[:, None] > 1e-20, cross / np.maximum(norm, 1e-300)[:, None], 0.0)
    # keep the mesh's outward side: the face normal agrees with the vertex normals
    vertex_normals = np.asarray(mesh.normals, np.float64)[faces].sum(axis=1) @ \
        np.linalg.inv(linear)  # normals transform by the inverse transpose
    flip = np.einsum("ij,ij->i", normals, vertex_normals) < 0.0
    normals[flip] *= -1.0
    # the length of the object-space normal segment in world units
    object_normals = np.cross(positions[faces][:, 1] - positions[faces][:, 0],
                              positions[faces][:, 2] - positions[faces][:, 0])
    object_norm = np.linalg.norm(object_normals, axis=-1)
    unit = object_normals / np.maximum(object_norm, 1e-300)[:, None]
    world_per_object = np.linalg.norm(unit @ linear.T, axis=-1)
    scale = np.asarray(mesh.comb, np.float64)[faces][..., 3].mean(axis=1)
    lengths = np.where(norm > 1e-20, fur_length * scale * world_per_object, 0.0)
    return p.mean(axis=1), normals, lengths


def curl_frames(mesh: MeshData, welded: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(V, 3) u and v per vertex spanning the tangent plane (Eq. 4's u, v): orthonormal, and the
    same for every copy of a vertex split at a UV seam (the mean of the copies' tangents and
    normals), so a curled layer does not crack along the seams of an unwrap."""
    groups = int(welded.max()) + 1
    normals = np.asarray(mesh.normals, np.float64)
    tangents = np.asarray(mesh.tangents, np.float64)
    mean_normal = np.stack([np.bincount(welded, normals[:, c], minlength=groups)
                            for c in range(3)], -1)
    mean_tangent = np.stack([np.bincount(welded, tangents[:, c], minlength=groups)
                             for c in range(3)], -1)
    n = mean_normal / np.maximum(np.linalg.norm(mean_normal, axis=1, keepdims=True), 1e-300)
    t = mean_tangent - np.einsum("ij,ij->i", mean_tangent, n)[:, None] * n
    length = np.linalg.norm(t, axis=1)
    # no usable tangent (copies cancel, a pole): any direction in the plane
    fallback = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    fallback = fallback - np.einsum("ij,ij->i", fallback, n)[:, None] * n
    t = np.where(length[:, None] > 1e-8, t, fallback)
    u = t / np.linalg.norm(t, axis=1, keepdims=True)
    v = np.cross(n, u)
    return u[welded], v[welded]


class VertexAverage:
    """Per-triangle values to per-vertex values: the area-weighted mean over the triangles
    around each vertex, welded by position so a seam does not tear the layers apart."""

    def __init__(self, mesh: MeshData):
        faces = np.asarray(mesh.indices, dtype=np.int64).reshape(-1, 3)
        positions = np.asarray(mesh.positions, np.float64)
        self.welded = weld(positions)
        self.groups = int(self.welded.max()) + 1
        p = positions[faces]
        area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=-1)
        self.corner_groups = self.welded[faces].reshape(-1)
        self.corner_weights = np.repeat(area, 3)
        total = np.bincount(self.corner_groups, self.corner_weights, minlength=self.groups)
        self.group_weight = np.where(total > 0.0, total, 1.0)

    def __call__(self, values: np.ndarray) -> np.ndarray:
        """(T, C) per triangle -> (V, C) per vertex."""
        values = np.asarray(values, np.float64)
        corners = np.repeat(values, 3, axis=0) * self.corner_weights[:, None]
        out = np.stack([np.bincount(self.corner_groups, corners[:, c], minlength=self.groups)
                        for c in range(values.shape[1])], axis=-1)
        return (out / self.group_weight[:, None])[self.welded]
