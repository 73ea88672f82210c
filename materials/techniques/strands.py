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
``materials/shell_fur/strand.glsl``). The shader receives each vertex's tip deflection
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

    def vary(self, variation: float, seed: int) -> None:
        """Give each strand its own stiffness, mass and response to the wind: factors drawn
        uniformly in [1 - variation, 1 + variation] (seeded), so strands settle and overshoot
        each at its own pace instead of in lockstep. 0: every strand the same (the paper)."""
        rng = np.random.default_rng([seed, 0x5712A4D])
        count = len(self.roots)
        self.stiffness_scale, self.mass_scale, self.wind_scale = (
            1.0 + variation * rng.uniform(-1.0, 1.0, (count, 1)) for _ in range(3))

    stiffness_scale: np.ndarray | float = 1.0  # per strand (T, 1): vary
    mass_scale: np.ndarray | float = 1.0
    wind_scale: np.ndarray | float = 1.0

    def step(self, dt: float, forces: StrandForces) -> None:
        """Advance by ``dt`` (Eq. 2, see the module documentation), then constrain (Eq. 3)."""
        m = forces.mass * self.mass_scale
        k = forces.stiffness * self.stiffness_scale
        external = m * forces.gravity + forces.wind * self.wind_scale
        spring = k * (self.tips - self.rest)
        velocities = (self.velocities + dt * (external - spring) / m) / \
            (1.0 + dt * forces.damping / m + dt * dt * k / m)
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


def gust_wind(wind: np.ndarray, roots: np.ndarray, normals: np.ndarray, gust: float,
              frequency: float, time: float, wavelength: float) -> np.ndarray:
    """(T, 3) the wind on each strand at ``time``: ``wind`` varied by gusts that differ over the
    surface and never repeat, and sheltered in the object's lee. Silva et al.'s wind is one
    force for all strands (and a single travelling gust wave repeats exactly at its period).

    - Along the wind, three travelling waves of incommensurate frequencies (``frequency`` times
      1, the golden ratio and 1 + sqrt 2) and wavelengths, crossing at angles, scale it by
      1 +- about ``gust``.
    - Turbulence: three more waves push along, across and up by up to half ``gust`` of the
      wind's strength.
    - Shelter: a strand facing downwind (its normal along the wind: the lee) gets less of the
      steady wind, which only presses it along its length there, and more of the turbulence:
      eddies push it back and forth, so the leeward outline moves too."""
    strength = float(np.linalg.norm(wind))
    if gust <= 0.0 or strength <= 0.0:
        return np.broadcast_to(wind, roots.shape)
    along = wind / strength
    helper = np.array([0.0, 1.0, 0.0]) if abs(along[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    side = np.cross(along, helper)
    side /= np.linalg.norm(side)
    up = np.cross(side, along)
    x, y, z = (roots @ axis / wavelength for axis in (along, side, up))
    phase = 2.0 * np.pi * frequency * time
    golden, silver = (1.0 + 5.0 ** 0.5) / 2.0, 1.0 + 2.0 ** 0.5
    scale = (np.sin(phase - 2.0 * np.pi * x)
             + 0.6 * np.sin(golden * phase - 2.0 * np.pi * (1.7 * x - 0.9 * y) + 1.3)
             + 0.4 * np.sin(silver * phase - 2.0 * np.pi * (2.3 * x + 1.1 * z) + 2.1)) / 2.0
    turbulence = 0.5 * (
        np.sin(1.31 * phase - 2.0 * np.pi * (1.4 * x - 2.0 * z) + 0.7)[:, None] * side
        + np.sin(1.73 * phase - 2.0 * np.pi * (0.8 * x + 1.9 * y) + 2.9)[:, None] * up
        + np.sin(2.11 * phase - 2.0 * np.pi * (1.2 * y + 1.6 * z) + 4.4)[:, None] * along)
    shelter = np.clip(np.asarray(normals, np.float64) @ along, 0.0, 1.0)[:, None]
    return wind[None, :] * (1.0 + gust * scale)[:, None] * (1.0 - shelter) + \
        strength * gust * (1.0 + shelter) * turbulence


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


# The curl's layer displacement may change by at most this fraction of the distance between two
# points of the surface through the phases' variation, so that no layer folds over itself
# (curl_phases).
CURL_PHASE_STRAIN = 0.4
CURL_PHASE_WAVES = 6  # plane waves summed into the phase field


def curl_phases(mesh: MeshData, variation: float, seed: int, curl_radius: float) -> np.ndarray:
    """(V,) an angle per vertex to turn its curl's (u, v) by: each strand's helix starts at its
    own phase, so neighbouring curls do not wind in lockstep (Eq. 4 gives every strand the same
    phase). A smooth field over the object: ``CURL_PHASE_WAVES`` plane waves of random
    directions and phases in object space, averaged and scaled to +- ``variation`` / 2 of a turn
    (seeded; the copies of a vertex split at a seam share their position, so their phase).

    Its wavenumber keeps the layers whole: all strands of a triangle share the layer's
    displacement (the curl ``K h (cos(w h) u + sin(w h) v)``, turned by the phase), so where
    the phase changes by ``d phi`` between two vertices a distance ``d`` apart their layer
    points move apart by up to ``K d phi``, and once that passes ``d`` the triangle between
    them turns over (a crumpled, cracked layer: phases drawn per vertex did that on most of a
    curled ball). The field's gradient is at most ``pi variation k``, so ``k`` is chosen for
    ``K pi variation k = CURL_PHASE_STRAIN``, and no finer than six median edges a wave."""
    positions = np.asarray(mesh.positions, np.float64)
    if variation <= 0.0:
        return np.zeros(len(positions))
    faces = np.asarray(mesh.indices, np.int64).reshape(-1, 3)
    edges = positions[faces] - positions[faces[:, [1, 2, 0]]]
    edge = float(np.median(np.linalg.norm(edges, axis=-1)))
    finest = 2.0 * np.pi / max(6.0 * edge, 1e-12)
    k = finest if curl_radius <= 0.0 else \
        min(CURL_PHASE_STRAIN / (np.pi * variation * curl_radius), finest)
    rng = np.random.default_rng([seed, 0xC011])
    directions = rng.normal(size=(CURL_PHASE_WAVES, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    offsets = rng.uniform(0.0, 2.0 * np.pi, CURL_PHASE_WAVES)
    field = np.sin(positions @ (k * directions).T + offsets).mean(axis=1)  # |grad| <= k
    return np.pi * variation * field


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
