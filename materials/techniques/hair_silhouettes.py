"""Object-space silhouette strokes on hair tubes (Costigan 4.3.7, second half, after Lake et al.
and Northrup et al.).

- **Edge table** (4.3.7): each triangle's three neighbours, found once per topology from the
  indices alone (:func:`triangle_adjacency`; the thesis' hash table of edges keyed by their
  vertex indices, here a sort of the edges' keys). The tubes of every strand share one pattern,
  so :func:`tube_adjacency` finds one strand's neighbours and offsets them. The result is an
  index buffer for ``GL_TRIANGLES_ADJACENCY`` (6 indices a triangle) over the tubes' own
  vertex buffer.
- **Silhouettes** (Fig. 4.14): ``materials/cartoon_hair/silhouette.geom`` takes a triangle and
  its neighbours; an edge between a front- and a back-facing triangle is a silhouette edge,
  emitted once, by its front-facing triangle. Faces without area (the tip ring of a tube
  tapered to a point) face as the sum of their vertices' normals.
- **Strokes** (Figs. 4.16-4.17): each silhouette edge becomes a quad ``stroke_width`` pixels
  wide (or ``stroke_world_width`` object units at its depth: it thins with distance), at most
  the tube's radius on screen (so a thin tube, far or tapering to its tip, keeps at least half
  its width in its colour), extruded in screen space. Edges are not chained into strips (the
  thesis' insertion sort): each end of a quad is pushed either side along its vertex's normal
  as it projects on screen (the edge's own normal where that looks along the edge), so the
  quads of two edges meeting at a vertex share their corners there: joints neither overlap
  (no doubled ink) nor gap at bends, the role of the thesis' extrusion along the sum of
  neighbouring edges (Fig. 4.16); the stroke keeps its width across a straight strand and
  thins a little where the normal leans along the edge. The stroke image runs along the whole
  strand (its ``u`` is the parameter along the strand, 0 root to 1 tip) and across
  the quad, so strokes are coherent from frame to frame without chaining; it is the hatching
  generator's soft-ended stroke (:func:`.tam.default_stroke`).
- **Fade** (Fig. 4.19): the stroke's alpha times ``clamp(a x^2 + b x + c, 0, 1)`` of the
  parameter ``x`` along the strand, so self-overlaps near the roots (Fig. 4.18) fade out.
- **Visibility** (4.3.7, Northrup's ID buffer): deferred, depth test off, a fragment is drawn
  where the G-buffer's ``strand_id`` is the stroke's own strand (the half of the stroke over
  its strand, whatever hides it: the thesis' rule), or where the stroke is no more than
  ``tolerance`` behind the G-buffer's depth (the outer half, over the background, the head or
  strands behind it). Forward has no ID buffer: the quads are pulled ``tolerance`` toward the
  eye and depth tested against the depth buffer, so a strand's own front surface never hides
  its stroke, but a strand crossing in front of another within the tolerance does not hide
  that one's stroke either, and a strand overlapping itself by more than the tolerance hides
  its own stroke (the thesis' Fig. 4.18 artefact does not occur).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import moderngl
import numpy as np

from deferred.api import (
    COMPOSITE,
    DEPTH,
    LINEAR_DEPTH,
    GpuMesh,
    MeshPrimitives,
    ObjectPass,
    Order,
)

from .hair_tubes import tube_indices
from .tam import default_stroke

SILHOUETTE_VERTEX = "materials/cartoon_hair/silhouette.vert"
SILHOUETTE_GEOMETRY = "materials/cartoon_hair/silhouette.geom"
SILHOUETTE_FRAGMENT = "materials/cartoon_hair/silhouette.frag"
STRAND_ID = "strand_id"  # the cartoon_hair material's G-buffer datum: 1 + a strand's index
STROKE_SHAPE = (32, 256)  # texels across and along the stroke image


def triangle_adjacency(indices: np.ndarray) -> np.ndarray:
    """``(T, 6)`` uint32 in ``GL_TRIANGLES_ADJACENCY`` order: for triangle ``(a, b, c)``,
    ``[a, p, b, q, c, r]`` where ``p``, ``q``, ``r`` are the vertices opposite the edges
    ``ab``, ``bc``, ``ca`` in the triangle across each edge. An edge keeps no neighbour unless
    exactly two triangles share it (a boundary, or a non-manifold edge): its slot holds the
    triangle's own third vertex, a neighbour facing the other way, so the edge is always drawn
    as a silhouette. Edges are told apart by their vertex indices only (positions never)."""
    faces = np.asarray(indices, dtype=np.int64).reshape(-1, 3)
    count = len(faces)
    if count == 0:
        return np.zeros((0, 6), np.uint32)
    # directed edge k of face f: (faces[f, k], faces[f, k + 1]), opposite vertex faces[f, k + 2]
    start = faces.reshape(-1)
    end = faces[:, [1, 2, 0]].reshape(-1)
    opposite = faces[:, [2, 0, 1]].reshape(-1)
    low, high = np.minimum(start, end), np.maximum(start, end)
    key = low * (int(faces.max()) + 1) + high  # one key an undirected edge: a perfect hash
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    starts = np.flatnonzero(np.r_[True, sorted_key[1:] != sorted_key[:-1]])
    sizes = np.diff(np.r_[starts, len(sorted_key)])
    neighbour = opposite.copy()  # no neighbour: the face's own opposite vertex
    pairs = starts[sizes == 2]
    first, second = order[pairs], order[pairs + 1]
    neighbour[first] = opposite[second]
    neighbour[second] = opposite[first]
    adjacency = np.empty((count, 6), np.int64)
    adjacency[:, 0::2] = faces
    adjacency[:, 1::2] = neighbour.reshape(count, 3)
    return adjacency.astype(np.uint32)


@lru_cache(maxsize=4)
def tube_adjacency(strands: int, samples: int, sides: int) -> np.ndarray:
    """:func:`triangle_adjacency` of :func:`.hair_tubes.tube_indices` ``(strands, samples,
    sides)``, ``(T, 6)`` uint32: one strand's, offset to each strand's vertices (the tubes are
    closed, so every edge has its two triangles)."""
    pattern = triangle_adjacency(tube_indices(1, samples, sides)).astype(np.int64)
    per_strand = samples * sides + 2
    offsets = (np.arange(strands, dtype=np.int64) * per_strand)[:, None, None]
    adjacency = (pattern[None] + offsets).reshape(-1, 6).astype(np.uint32)
    adjacency.setflags(write=False)
    return adjacency


def stroke_texture(ctx: moderngl.Context) -> moderngl.Texture:
    """The stroke image (ink in [0, 1], ``u`` along, ``v`` across) as a mipmapped R8 texture."""
    ink = default_stroke(STROKE_SHAPE)  # (across, along)
    pixels = np.round(np.clip(ink, 0.0, 1.0) * 255.0).astype(np.uint8)
    texture = ctx.texture((pixels.shape[1], pixels.shape[0]), 1, pixels.tobytes())
    texture.build_mipmaps()
    texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    texture.repeat_x = texture.repeat_y = False
    return texture


def silhouette_geometry(ctx: moderngl.Context, gpu_mesh: GpuMesh,
                        adjacency: np.ndarray) -> MeshPrimitives:
    """A tube mesh's triangles with their neighbours (:func:`tube_adjacency`), over the mesh's
    own vertex buffer."""
    return MeshPrimitives(ctx, gpu_mesh, adjacency, moderngl.TRIANGLES_ADJACENCY)


class SilhouettePass(ObjectPass):
    """Silhouette strokes of an object's hair tubes over the composition buffer.

    A subclass gives the tubes (:meth:`silhouette_geometry`, made by the owner of the tubes'
    buffers and released with them) and the stroke
    parameters (:meth:`stroke_settings`). ``id_buffer=True`` (deferred) tests visibility
    against the G-buffer's ``strand_id`` and ``linear_depth``; ``False`` (forward) against the
    depth buffer."""

    vertex = SILHOUETTE_VERTEX
    geometry = SILHOUETTE_GEOMETRY
    fragment = SILHOUETTE_FRAGMENT
    colors = (COMPOSITE,)
    depth = DEPTH
    depth_test = True
    depth_func = "lequal"
    depth_write = False
    cull = None
    blend = "alpha"
    order = Order.TRANSPARENT
    id_buffer = False

    def __init__(self, name, phase, obj, **options: Any):
        if options.get("id_buffer"):
            options.setdefault("depth", None)
            options.setdefault("depth_test", False)
            options.setdefault("extra_reads", (STRAND_ID, LINEAR_DEPTH))
        super().__init__(name, phase, obj, **options)

    def silhouette_geometry(self, frame) -> MeshPrimitives:
        """The tubes with their neighbours this frame."""
        raise NotImplementedError

    def stroke_settings(self, frame) -> dict[str, Any]:
        """``width`` (pixels), ``world_width`` (object units, or None: ``width`` pixels),
        ``color`` (linear RGB), ``fade`` (a, b, c), ``tolerance`` (object units), the tubes'
        ``radius`` (object units) and ``taper`` (a, b, c) of the object as ``frame`` has it."""
        raise NotImplementedError

    def defines(self, frame) -> dict[str, str]:
        defines = super().defines(frame)
        return {**defines, "STROKE_ID_BUFFER": "1"} if self.id_buffer else defines

    def uniforms(self, frame) -> dict[str, Any]:
        settings = self.stroke_settings(frame)
        # the tolerance in view units: the object's largest scale
        scale = float(np.max(np.linalg.norm(np.asarray(self.object(frame).model)[:3, :3],
                                            axis=0)))
        world_width = settings.get("world_width")
        return {"u_stroke_width": float(settings["width"]),
                "u_stroke_world_width": 0.0 if world_width is None else world_width * scale,
                "u_tube_radius": float(settings["radius"]) * scale,
                "u_tube_taper": tuple(float(c) for c in settings["taper"]),
                "u_stroke_color": tuple(float(c) for c in settings["color"]),
                "u_stroke_fade": tuple(float(c) for c in settings["fade"]),
                "u_stroke_tolerance": float(settings["tolerance"]) * scale}

    def textures(self, frame) -> dict[str, moderngl.Texture]:
        return {**super().textures(frame),
                "u_stroke": frame.resources.texture("hair_silhouette_stroke", stroke_texture)}

    def draw(self, frame, program: moderngl.Program) -> None:
        geometry = self.silhouette_geometry(frame)
        frame.gl_call(lambda: geometry.render(program))
        frame.count_draw()
