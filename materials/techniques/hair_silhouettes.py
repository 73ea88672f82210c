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


EDGES_COMPUTE = "materials/cartoon_hair/silhouette_edges.comp"
STROKES_VERTEX = "materials/cartoon_hair/silhouette_strokes.vert"
EDGE_GROUP = 64  # invocations (strands) a work group
MAX_SIDES = 16  # silhouette_edges.comp's ring arrays (cartoon_hair's sides go to 16)
STROKES_A_RING = 4  # the stroke buffer's room: a tube seen side on has about 2.6 a ring
FIND_TEXTURE_UNIT = 12  # the edge pass's first texture unit (GL 4.3 gives a stage 16)
STROKE_CORNER_BYTES = 32  # NDC x, y, z, view depth, along, across, strand and one unused


def edges_on_gpu(gl) -> bool:
    """Whether the silhouette strokes are made by a compute shader and drawn from a storage
    buffer (GL 4.3, and storage buffers in vertex shaders: GL 4.3 requires none there)."""
    if not gl.features.compute_shaders:
        return False
    return int(gl.ctx.info.get("GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS", 0) or 0) >= 2


class SilhouetteEdges:
    """The silhouette strokes of a set of tubes made on the GPU (Costigan 4.3.7, Figs.
    4.14-4.17): ``materials/cartoon_hair/silhouette_edges.comp``, an invocation a strand,
    walks the tube's rings, classifies the edges of its fixed topology (no adjacency buffer: a
    tube's neighbours follow from its vertex order) against the eye and writes each
    silhouette edge's stroke quad, its 4 corners, into :attr:`strokes`, counting 6 indices a
    quad into :attr:`command`, a ``glDrawElementsIndirect`` command over a fixed index buffer
    of two triangles a quad: every stroke in one draw, and nothing back to the CPU. The quads
    are made once, in the compute pass: drawn as an instance an edge, or with each of 6
    vertices making its quad again, the strokes of 10,000 strands took llvmpipe half a second.
    :attr:`capacity` strokes (``STROKES_A_RING`` a ring) fit; more are dropped."""

    def __init__(self, ctx: moderngl.Context, strands: int, samples: int, sides: int):
        if sides > MAX_SIDES:
            raise ValueError(f"the GPU silhouettes take tubes of at most {MAX_SIDES} sides")
        self.ctx = ctx
        self.strands, self.samples, self.sides = strands, samples, sides
        self.capacity = strands * samples * STROKES_A_RING
        self.strokes = ctx.buffer(reserve=4 * STROKE_CORNER_BYTES * self.capacity)
        quads = np.arange(self.capacity, dtype=np.uint32)[:, None] * 4
        indices = (quads + np.array([0, 1, 2, 2, 1, 3], np.uint32)).astype(np.uint32)
        self.indices = ctx.buffer(indices.tobytes())
        self.command = ctx.buffer(reserve=20)
        self._arrays: dict[int, moderngl.VertexArray] = {}

    @property
    def nbytes(self) -> int:
        """Bytes of GPU memory held."""
        return self.strokes.size + self.indices.size + self.command.size

    def find(self, shaders, vertices: moderngl.Buffer, model_view: np.ndarray,
             stroke: dict[str, Any], defines: dict[str, str] | None = None,
             textures: dict[str, moderngl.Texture] | None = None, stride: int = 6) -> None:
        """Make the strokes of the tubes in ``vertices`` (``stride`` floats a vertex, position
        and normal first, object space) seen through the 4x4 ``model_view``; ``stroke``: the
        values of ``silhouette_stroke.glsl``'s uniforms (and ``u_strand_base``), ``defines`` the
        stroke pass's (with ``STROKE_ID_BUFFER``, strokes the G-buffer's ``textures``,
        ``u_linear_depth`` and ``u_strand_id``, hide are not made)."""
        self.command.write(np.array([0, 1, 0, 0, 0], np.uint32).tobytes())
        shader = shaders.compute(EDGES_COMPUTE, {**(defines or {}),
                                                 "EDGE_GROUP": str(EDGE_GROUP)})
        model_view = np.asarray(model_view, np.float64)
        normal = np.linalg.inv(model_view[:3, :3]).T
        values = {
            "u_strands": self.strands, "u_samples": self.samples, "u_sides": self.sides,
            "u_stride": stride, "u_capacity": self.capacity,
            # GL's matrices are column-major: the transpose's rows are the columns
            "u_model_view": tuple(float(v) for v in model_view.T.reshape(-1)),
            "u_normal_matrix": tuple(float(v) for v in normal.T.reshape(-1)), **stroke}
        shaders.uniforms(shader).set({name: value for name, value in values.items()
                                      if name in shader})
        # texture units above the stroke program's: the pass has bound its samplers already
        for unit, (name, texture) in enumerate((textures or {}).items(), FIND_TEXTURE_UNIT):
            if name in shader:
                texture.use(unit)
                shader[name].value = unit
        vertices.bind_to_storage_buffer(0)
        self.strokes.bind_to_storage_buffer(1)
        self.command.bind_to_storage_buffer(2)
        shader.run(-(-self.strands // EDGE_GROUP))
        self.ctx.memory_barrier()

    def draw(self, program: moderngl.Program) -> None:
        """The strokes :meth:`find` made, in one indexed draw."""
        vertex_array = self._arrays.get(program.glo)
        if vertex_array is None:
            vertex_array = self._arrays[program.glo] = self.ctx.vertex_array(
                program, [], index_buffer=self.indices, index_element_size=4)
        self.strokes.bind_to_storage_buffer(1)
        vertex_array.render_indirect(self.command, moderngl.TRIANGLES, count=1)

    def count(self) -> int:
        """The strokes made last (read back: tests and figures only)."""
        return int(np.frombuffer(self.command.read(), np.uint32)[0]) // 6

    def corners(self) -> np.ndarray:
        """``(count, 4, 7)`` float32: the corners of the strokes made last (read back): NDC x,
        y, z, view depth, along, across, strand."""
        count = self.count()
        raw = np.frombuffer(self.strokes.read(4 * STROKE_CORNER_BYTES * count), np.float32)
        return raw.reshape(count, 4, 8)[..., :7]

    def release(self) -> None:
        for vertex_array in self._arrays.values():
            vertex_array.release()
        for buffer in (self.strokes, self.indices, self.command):
            buffer.release()


class SilhouettePass(ObjectPass):
    """Silhouette strokes of an object's hair tubes over the composition buffer.

    A subclass gives the tubes (:meth:`tube_vertices`; and, made by the owner of the tubes'
    buffers and released with them, :meth:`silhouette_edges` where compute shaders make the
    strokes, else :meth:`silhouette_geometry` for the geometry shader over their adjacency)
    and the stroke parameters (:meth:`stroke_settings`). ``id_buffer=True`` (deferred) tests
    visibility against the G-buffer's ``strand_id`` and ``linear_depth``; ``False`` (forward)
    against the depth buffer."""

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
        """The tubes with their neighbours this frame (the geometry shader's path)."""
        raise NotImplementedError

    def silhouette_edges(self, frame) -> SilhouetteEdges:
        """The tubes' :class:`SilhouetteEdges` (the compute path)."""
        raise NotImplementedError

    def tube_vertices(self, frame) -> moderngl.Buffer:
        """The buffer of the tubes' positions and normals (6 floats a vertex)."""
        raise NotImplementedError

    def stroke_settings(self, frame) -> dict[str, Any]:
        """``width`` (pixels), ``world_width`` (object units, or None: ``width`` pixels),
        ``color`` (linear RGB), ``fade`` (a, b, c), ``tolerance`` (object units), the tubes'
        ``radius`` (object units) and ``taper`` (a, b, c) of the object as ``frame`` has it."""
        raise NotImplementedError

    def defines(self, frame) -> dict[str, str]:
        defines = super().defines(frame)
        return {**defines, "STROKE_ID_BUFFER": "1"} if self.id_buffer else defines

    def program(self, frame, obj=None) -> moderngl.Program:
        if not edges_on_gpu(frame.gl):
            return super().program(frame, obj)
        return frame.shaders.program(STROKES_VERTEX, self.fragment, None,
                                     defines=self.defines(frame))

    def stroke_uniforms(self, frame) -> dict[str, Any]:
        """The values of ``silhouette_stroke.glsl``'s uniforms (where the quads are made)."""
        settings = self.stroke_settings(frame)
        # view units: times the object's largest scale
        scale = float(np.max(np.linalg.norm(np.asarray(self.object(frame).model)[:3, :3],
                                            axis=0)))
        world_width = settings.get("world_width")
        return {"u_stroke_width": float(settings["width"]),
                "u_stroke_world_width": 0.0 if world_width is None else world_width * scale,
                "u_tube_radius": float(settings["radius"]) * scale,
                "u_tube_taper": tuple(float(c) for c in settings["taper"]),
                "u_stroke_tolerance": float(settings["tolerance"]) * scale}

    def uniforms(self, frame) -> dict[str, Any]:
        settings = self.stroke_settings(frame)
        stroke = self.stroke_uniforms(frame)
        uniforms = {"u_stroke_color": tuple(float(c) for c in settings["color"]),
                    "u_stroke_fade": tuple(float(c) for c in settings["fade"])}
        if self.id_buffer:
            uniforms["u_stroke_tolerance"] = stroke["u_stroke_tolerance"]
        if not edges_on_gpu(frame.gl):  # the geometry shader makes the quads
            uniforms.update(stroke)
        return uniforms

    def textures(self, frame) -> dict[str, moderngl.Texture]:
        return {**super().textures(frame),
                "u_stroke": frame.resources.texture("hair_silhouette_stroke", stroke_texture)}

    def draw(self, frame, program: moderngl.Program) -> None:
        if edges_on_gpu(frame.gl):
            edges, vertices = self.silhouette_edges(frame), self.tube_vertices(frame)
            model_view = np.asarray(frame.view) @ np.asarray(self.object(frame).model)
            stroke = {**self.stroke_uniforms(frame), **self.uniforms(frame),
                      "u_projection": frame.projection,
                      "u_resolution": (float(frame.width), float(frame.height))}
            visibility = {"u_linear_depth": frame.target(LINEAR_DEPTH),
                          "u_strand_id": frame.target(STRAND_ID)} if self.id_buffer else {}
            frame.gl_call(lambda: edges.find(frame.shaders, vertices, model_view, stroke,
                                             self.defines(frame), visibility))
            frame.count_draw()
            frame.gl_call(lambda: edges.draw(program))
        else:
            geometry = self.silhouette_geometry(frame)
            frame.gl_call(lambda: geometry.render(program))
        frame.count_draw()
