"""Tube meshes around cartoon hair strands (Costigan 4.3.1-4.3.2), vectorised over all strands.

Each strand is smoothed by its Catmull-Rom spline sampled at ``samples`` points (4.3.1); a
``sides``-sided polygon approximating a circle is swept along it, oriented by the spline's
tangent, and scaled by the quadratic taper ``radius (a x^2 + b x + c)`` at the parameter ``x``
from 0 (root) to 1 (tip) (4.3.2 and section 3.6's H curve, values below 0 taken as 0). The
polygon is carried along by rotation-minimising frames (Wang et al.'s double reflection), so
the tube does not twist about the strand however the strand bends. The open ends are closed by
a vertex at each end joined to its ring (4.3.2). Each vertex exists once and triangles index it
(Fig. 4.5, 4.6); its normal is the average of its triangles' normals, weighted by their area
(4.3.2, 3.3), which on this regular grid is a sum of shifted face-normal arrays, no scatter.

Per strand the vertices are the rings, root first (``samples x sides``, ring ``i`` vertex ``j``
at ``i * sides + j``), then the root cap's centre, then the tip cap's: ``samples x sides + 2``.

:func:`build_tubes` is numpy; :class:`GpuTubes` makes the same positions and averaged normals
with two compute shaders straight into the vertex buffer the tubes are drawn from (what the
material uses where the context has GL 4.3; numpy is its GL 3.3 path and the tests' reference).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

import numpy as np

from .hair_strands import catmull_rom_weights, quadratic, rotation_minimising_frames

DEFAULT_TAPER = (0.0, -1.0, 1.0)  # full radius at the root, a point at the tip
TubeNormals = Literal["averaged", "swept"]


@dataclass(frozen=True)
class TubeMesh:
    """Tube meshes of a strand set, ready for a vertex buffer.

    ``positions`` and ``normals`` ``(V, 3)`` float32 (unit normals; 0 where every triangle of a
    vertex has no area), ``indices`` ``(T, 3)`` uint32 counter-clockwise seen from outside,
    ``strand_ids`` ``(V,)`` uint32 (the strand each vertex belongs to), ``along`` ``(V,)``
    float32 (the parameter along the strand, 0 root to 1 tip; caps 0 and 1) and ``around``
    ``(V,)`` float32 (``j / sides`` round the ring; caps 0).
    """

    positions: np.ndarray
    normals: np.ndarray
    indices: np.ndarray
    strand_ids: np.ndarray
    along: np.ndarray
    around: np.ndarray


def tube_vertex_count(strands: int, samples: int, sides: int) -> int:
    """Vertices of ``strands`` tubes: rings plus two cap centres each."""
    return strands * (samples * sides + 2)


def tube_triangle_count(strands: int, samples: int, sides: int) -> int:
    """Triangles of ``strands`` tubes: two per quad between rings plus a fan per cap."""
    return strands * (2 * (samples - 1) * sides + 2 * sides)


@lru_cache(maxsize=8)
def _strand_pattern(samples: int, sides: int) -> np.ndarray:
    """One strand's triangles ``(T, 3)`` over its own vertex numbers."""
    i, j = np.meshgrid(np.arange(samples - 1), np.arange(sides), indexing="ij")
    j1 = (j + 1) % sides
    a, b = i * sides + j, i * sides + j1
    c, d = (i + 1) * sides + j, (i + 1) * sides + j1
    root_centre, tip_centre = samples * sides, samples * sides + 1
    ring = np.arange(sides)
    last = (samples - 1) * sides
    return np.concatenate([
        np.stack([a, b, c], -1).reshape(-1, 3),  # A: around x along points outward
        np.stack([b, d, c], -1).reshape(-1, 3),  # B
        np.stack([np.full(sides, root_centre), (ring + 1) % sides, ring], -1),
        np.stack([np.full(sides, tip_centre), last + ring, last + (ring + 1) % sides], -1),
    ]).astype(np.int64)


@lru_cache(maxsize=4)
def tube_indices(strands: int, samples: int, sides: int) -> np.ndarray:
    """Triangles ``(T, 3)`` uint32 of ``strands`` tubes: the same for every frame of a strand
    set (upload once; only positions and normals change)."""
    pattern = _strand_pattern(samples, sides)
    per_strand = samples * sides + 2
    offsets = (np.arange(strands, dtype=np.int64) * per_strand)[:, None, None]
    indices = (pattern[None] + offsets).reshape(-1, 3).astype(np.uint32)
    indices.setflags(write=False)
    return indices


def tube_radii(samples: int, radius: float,
               taper: tuple[float, float, float] = DEFAULT_TAPER) -> np.ndarray:
    """The ring radii ``radius * max(a x^2 + b x + c, 0)`` at ``x = i / (samples - 1)``."""
    x = np.linspace(0.0, 1.0, samples)
    return radius * np.maximum(quadratic(taper, x), 0.0)


def build_tubes(strands: np.ndarray, samples: int = 8, sides: int = 8, radius: float = 0.005,
                taper: tuple[float, float, float] = DEFAULT_TAPER,
                reference: np.ndarray | None = None,
                normals: TubeNormals = "averaged") -> TubeMesh:
    """Tube meshes around ``strands`` ``(S, P, 3)`` (Costigan 4.3.1-4.3.2).

    ``samples`` (>= 2) spline samples per strand, ``sides`` (>= 3) vertices per ring, ring
    radius ``radius * max(a x^2 + b x + c, 0)`` with ``taper = (a, b, c)``; ``reference``
    ``(S, 3)`` turns each strand's first ring (a direction that moves with the strand's root,
    so the rings do not jump round when the strand swings; see
    :func:`rotation_minimising_frames`). ``normals``: ``averaged``, each vertex's triangles'
    normals averaged (Costigan 3.3, 4.3.2), or ``swept``, the normal of the smooth tapered tube
    the mesh samples (the ring's radial direction tilted by the taper's slope along the spline;
    the caps' centres along the tangent): a few operations a vertex where averaging takes
    dozens, and the same to within the facets' angle away from the caps. See :class:`TubeMesh`
    for what comes back.
    """
    if samples < 2 or sides < 3:
        raise ValueError("a tube needs at least 2 samples and 3 sides")
    if normals not in ("averaged", "swept"):
        raise ValueError(f"normals must be 'averaged' or 'swept', got {normals!r}")
    strands = np.asarray(strands, dtype=np.float32)
    count, points = strands.shape[:2]
    # the spline and its slope at every sample: one matrix product each over all strands
    flat = strands.transpose(1, 0, 2).reshape(points, -1)
    spline, slope = (
        np.ascontiguousarray((catmull_rom_weights(points, samples, derivative).astype(np.float32)
                              @ flat).reshape(samples, count, 3).transpose(1, 0, 2))
        for derivative in (False, True))
    speed = np.maximum(np.linalg.norm(slope, axis=-1, keepdims=True), 1e-20)
    tangents = slope / speed
    ref = None if reference is None else np.asarray(reference, dtype=np.float32)
    normal = rotation_minimising_frames(spline, tangents, ref)
    binormal = np.cross(tangents, normal)
    angle = np.arange(sides) * (2.0 * np.pi / sides)
    cos, sin = np.cos(angle).astype(np.float32), np.sin(angle).astype(np.float32)
    radii = tube_radii(samples, radius, taper).astype(np.float32)[None, :, None]
    # component-major rings (3, S, samples, sides + 1), the first vertex repeated at the end so
    # the neighbour round the ring is a slice; ring j at angle 2 pi j / sides, counter-clockwise
    # about the tangent
    centre = np.ascontiguousarray(np.moveaxis(spline, -1, 0))
    radial = np.empty((3, count, samples, sides + 1), dtype=np.float32)
    for c in range(3):
        radial[c, :, :, :sides] = cos * normal[:, :, c, None] + sin * binormal[:, :, c, None]
    radial[..., sides] = radial[..., 0]
    rings = centre[..., None] + radii * radial
    if normals == "averaged":
        ring_normals, cap_normals = _vertex_normals(rings, centre)
    else:
        # d(radius)/d(arc length): the taper's slope over the spline's speed
        x = np.linspace(0.0, 1.0, samples)
        a, b, _ = (float(v) for v in taper)
        growth = np.where(tube_radii(samples, 1.0, taper) > 0.0, radius * (2.0 * a * x + b), 0.0)
        tilt = (growth[None, :] / speed[..., 0]).astype(np.float32)  # (S, samples)
        scale = 1.0 / np.sqrt(1.0 + tilt * tilt)
        ring_normals = (radial[..., :sides] - (tilt[..., None] * np.moveaxis(tangents, -1, 0)
                                               [..., None])) * scale[..., None]
        cap_normals = np.stack([-tangents[:, 0], tangents[:, -1]], axis=-1).transpose(1, 0, 2)
    per_strand = samples * sides + 2
    positions = np.empty((count, per_strand, 3), dtype=np.float32)
    vertex_normals = np.empty_like(positions)
    for c in range(3):
        positions[:, :-2, c] = rings[c, :, :, :sides].reshape(count, -1)
        vertex_normals[:, :-2, c] = ring_normals[c].reshape(count, -1)
    positions[:, -2], positions[:, -1] = spline[:, 0], spline[:, -1]
    vertex_normals[:, -2:] = np.moveaxis(cap_normals, 0, -1)
    along = np.empty(per_strand, dtype=np.float32)
    along[:-2] = np.repeat(np.linspace(0.0, 1.0, samples), sides)
    along[-2:] = 0.0, 1.0
    around = np.zeros(per_strand, dtype=np.float32)
    around[:-2] = np.tile(np.arange(sides) / sides, samples)
    return TubeMesh(positions=positions.reshape(-1, 3), normals=vertex_normals.reshape(-1, 3),
                    indices=tube_indices(count, samples, sides),
                    strand_ids=np.repeat(np.arange(count, dtype=np.uint32), per_strand),
                    along=np.tile(along, count), around=np.tile(around, count))


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross products of component-major vectors ``(3, ...)``."""
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def _unit(v: np.ndarray) -> np.ndarray:
    """Component-major vectors ``(3, ...)`` made unit length (zero ones left zero)."""
    length = np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return v / np.where(length > 0.0, length, 1.0)


def _vertex_normals(rings: np.ndarray, centre: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each ring vertex's normal ``(3, S, samples, sides)``: the area-weighted sum of the six
    triangles round it (two quads of the rings before and after it and, on the end rings, two
    cap triangles), normalised; and the cap centres' ``(3, S, 2)``, the sums of their fans.
    ``rings`` is component-major with the first vertex repeated last, ``centre`` the spline
    ``(3, S, samples)``."""
    here, right = rings[:, :, :-1, :-1], rings[:, :, :-1, 1:]
    ahead, right_ahead = rings[:, :, 1:, :-1], rings[:, :, 1:, 1:]
    a = _cross(right - here, ahead - here)  # triangle (i j, i j+1, i+1 j)
    # a quad's two triangles together: its vector area, the cross of its diagonals
    quads = _cross(right_ahead - here, ahead - right)
    b = quads - a  # triangle (i j+1, i+1 j+1, i+1 j)
    total = np.empty(rings[:, :, :, :-1].shape, dtype=rings.dtype)
    total[:, :, :-1] = a  # quad (i, j)
    total[:, :, -1] = 0.0
    total[:, :, :-1, 1:] += quads[..., :-1]  # quad (i, j-1)
    total[:, :, :-1, 0] += quads[..., -1]
    total[:, :, 1:] += quads  # quad (i-1, j)
    total[:, :, 1:, 1:] += b[..., :-1]  # quad (i-1, j-1)
    total[:, :, 1:, 0] += b[..., -1]
    first, last = rings[:, :, 0], rings[:, :, -1]
    root_cap = _cross(first[..., 1:] - centre[:, :, 0, None],
                      first[..., :-1] - centre[:, :, 0, None])  # (centre, j+1, j)
    tip_cap = _cross(last[..., :-1] - centre[:, :, -1, None],
                     last[..., 1:] - centre[:, :, -1, None])  # (centre, j, j+1)
    total[:, :, 0] += root_cap + np.roll(root_cap, 1, axis=-1)
    total[:, :, -1] += tip_cap + np.roll(tip_cap, 1, axis=-1)
    caps = np.stack([root_cap.sum(axis=-1), tip_cap.sum(axis=-1)], axis=-1)
    return _unit(total), _unit(caps)


# --------------------------------------------------------------------------- on the GPU

TUBE_FRAMES = "materials/cartoon_hair/tube_frames.comp"
TUBE_VERTICES = "materials/cartoon_hair/tube_vertices.comp"
TUBE_GROUP = 256  # invocations a work group (64 to 1,024 cost the same on llvmpipe)


class GpuTubes:
    """:func:`build_tubes`' positions and averaged normals made by two compute shaders, into a
    vertex buffer the tubes are drawn from (GL 4.3): ``materials/cartoon_hair/tube_frames.comp``
    samples each strand's spline and its rotation-minimising frames (an invocation a strand),
    ``tube_vertices.comp`` each ring's vertices and their averaged normals (an invocation a
    ring). The arithmetic is build_tubes', in float32: the results agree to float rounding.
    Only the strands' points go up each frame (``4 x (points + 1)`` floats a strand, against
    the ``6 x samples x sides`` of its built vertices); the vertex order, indices and the
    vertices' other attributes are build_tubes', written once by whoever made the buffer.

    ``shaders`` in :meth:`build` is the renderer's shader library (``compute(name, defines)``
    and ``uniforms(program).set(values)``).
    """

    def __init__(self, ctx, strands: int, points: int, samples: int, sides: int):
        if samples < 2 or sides < 3 or points < 2:
            raise ValueError("a tube needs at least 2 points, 2 samples and 3 sides")
        self.ctx = ctx
        self.strands, self.points, self.samples, self.sides = strands, points, samples, sides
        self._upload = np.zeros((strands, points + 1, 4), np.float32)
        self._points = ctx.buffer(reserve=self._upload.nbytes)
        self._frames = ctx.buffer(reserve=4 * 4 * 3 * samples * strands)

    @property
    def vertex_count(self) -> int:
        return tube_vertex_count(self.strands, self.samples, self.sides)

    def upload(self, points: np.ndarray, reference: np.ndarray) -> None:
        """The strands' points, component-major ``(3, points, strands)`` (the simulation's
        layout: :attr:`.hair_dynamics.HairSimulation.component_points`), and the first rings'
        reference directions ``(3, strands)``."""
        points, reference = np.asarray(points), np.asarray(reference)
        if points.shape != (3, self.points, self.strands) or \
                reference.shape != (3, self.strands):
            raise ValueError(f"points must be (3, {self.points}, {self.strands}) and reference "
                             f"(3, {self.strands}), got {points.shape} and {reference.shape}")
        upload = self._upload
        upload[:, :-1, :3] = points.transpose(2, 1, 0)
        upload[:, -1, :3] = reference.T
        self._points.write(upload)

    def build(self, shaders, vertices, radius: float,
              taper: tuple[float, float, float] = DEFAULT_TAPER,
              to_object: np.ndarray | None = None, stride: int = 3 * 4 * 2) -> None:
        """Write the uploaded strands' tubes into ``vertices`` (a buffer of
        :attr:`vertex_count` vertices of ``stride`` bytes, position then normal first),
        through the 4x4 ``to_object`` (identity by default; normals by its inverse transpose).
        The writes are visible to draws after it (a memory barrier)."""
        to_object = np.eye(4) if to_object is None else np.asarray(to_object, np.float64)
        defines = {"TUBE_GROUP": str(TUBE_GROUP)}
        frames = shaders.compute(TUBE_FRAMES, defines)
        vertex = shaders.compute(TUBE_VERTICES, defines)
        counts = {"u_strands": self.strands, "u_samples": self.samples}
        shaders.uniforms(frames).set({
            **counts, "u_points": self.points, "u_radius": float(radius),
            "u_taper": tuple(float(v) for v in taper),
            # GL's matrices are column-major: the transpose's rows are the columns
            "u_to_object": tuple(float(v) for v in to_object.T.reshape(-1))})
        turn = 2.0 * np.pi / self.sides
        shaders.uniforms(vertex).set({
            **counts, "u_sides": self.sides, "u_stride": stride // 4,
            "u_turn": (float(np.cos(turn)), float(np.sin(turn))),
            "u_orientation": -1.0 if np.linalg.det(to_object[:3, :3]) < 0.0 else 1.0})
        self._points.bind_to_storage_buffer(0)
        self._frames.bind_to_storage_buffer(2)
        vertices.bind_to_storage_buffer(3)
        frames.run(-(-self.strands // TUBE_GROUP))  # an invocation a strand
        self.ctx.memory_barrier()
        vertex.run(-(-self.strands * self.samples // TUBE_GROUP))  # an invocation a ring
        self.ctx.memory_barrier()

    def release(self) -> None:
        self._points.release()
        self._frames.release()
