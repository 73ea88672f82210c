"""Meshes as the GPU draws them: the framework's one vertex format, a mesh's arrays in it
(:class:`MeshData`, made by :mod:`deferred.scene.meshes`) and their buffers (:class:`GpuMesh`).

Every mesh has the same vertex format (``VERTEX_ATTRIBUTES``): position, normal, UV, tangent,
binormal and the RGBA *comb* colour of Revie section 2.4.1 (RGB: comb direction in tangent space
packed from [-1, 1] to [0, 1]; A: fur length scale).

A mesh may carry more (``EXTRA_ATTRIBUTES``, glTF's): a second UV set, a vertex colour and
tangents with their handedness for normal maps. They go into a second vertex buffer that a mesh
makes only for a program reading one of them (``in_uv1``, ``in_color``, ``in_tangent4``): every
other program reads the buffer it always has. Where a mesh lacks one, its stand-in is used: the
first UV set, white, and MikkTSpace's frame (:mod:`deferred.gl.tangents`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import moderngl
import numpy as np

from deferred.gl.tangents import mikktspace_tangents
from deferred.memo import kept_while

# (name, components) in buffer order; the GLSL attribute is ``in_<name>``.
VERTEX_ATTRIBUTES = (("position", 3), ("normal", 3), ("uv", 2), ("tangent", 3),
                     ("binormal", 3), ("comb", 4))
# the second buffer's, made only for programs reading one of them (see the module documentation)
EXTRA_ATTRIBUTES = (("uv1", 2), ("color", 4), ("tangent4", 4))


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
    # the files it was read from: the mesh file and those it names (a material library, its
    # textures, glTF buffers): inputs an output must not replace
    sources: tuple[Path, ...] = ()
    # glTF's further attributes (the first three are EXTRA_ATTRIBUTES'), None where the file has
    # none: TEXCOORD_1 (N, 2) in the framework's convention as ``uvs`` (v up: 1 - glTF's v),
    # COLOR_0 (N, 4) linear RGBA, TANGENT (N, 4): xyz along +U, w the handedness
    # (cross(normal, xyz) * w runs along +V), and a skin's four joints and weights a vertex
    # (JOINTS_0 (N, 4) uint16, WEIGHTS_0 (N, 4) float32 summing to 1:
    # deferred.render.skinning)
    uv1: np.ndarray | None = None
    colors: np.ndarray | None = None
    file_tangents: np.ndarray | None = None
    joints: np.ndarray | None = None
    weights: np.ndarray | None = None

    @property
    def vertex_count(self) -> int:
        return len(self.positions)

    def interleaved(self) -> np.ndarray:
        parts = [self.positions, self.normals, self.uvs, self.tangents, self.binormals, self.comb]
        return np.ascontiguousarray(np.hstack(parts).astype(np.float32))

    @kept_while("uvs", "uv1", "colors", "file_tangents", "normals", "indices")
    def extra_attributes(self) -> np.ndarray:
        """``EXTRA_ATTRIBUTES`` interleaved, ``(N, 10)`` float32: each the mesh's own or its
        stand-in (the first UV set, opaque white, MikkTSpace tangents)."""
        count = self.vertex_count
        uv1 = self.uvs if self.uv1 is None else self.uv1
        colors = np.ones((count, 4), np.float32) if self.colors is None else self.colors
        tangents = self.file_tangents if self.file_tangents is not None else \
            mikktspace_tangents(self.positions, self.normals, self.uvs, self.indices)
        return np.ascontiguousarray(np.hstack([uv1, colors, tangents]).astype(np.float32))

    @kept_while("positions")
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(least, greatest) position per axis; made once per positions array (the GPU copy
        assumes the arrays do not change either), as the fur's level of detail asks for it
        every frame."""
        return self.positions.min(axis=0), self.positions.max(axis=0)


SKINNED_SURFACE = (("position", 3), ("normal", 3), ("tangent", 3), ("binormal", 3))
# a skinned mesh's previous surface, as the motion vectors read it (the rest skipped)
PREVIOUS_SURFACE = (("previous_position", 3), ("previous_frame", 9))
# a moving mesh's previous surface (keeps_previous), as the motion vectors read it
PREVIOUS_MOVING_SURFACE = (("previous_position", 3), ("previous_normal", 3))


@dataclass
class GpuMesh:
    """A mesh's vertex and index buffers, with one vertex array per program using it.

    ``moving=True`` keeps positions and normals in a buffer of their own,
    :attr:`surface_vbo` (6 floats a vertex, rewritten as the mesh moves: by
    :meth:`write_surface` or by a compute shader), and the constant attributes in :attr:`vbo`:
    a frame's rewrite touches a third of the bytes of the whole vertex format.

    ``skinned=True`` (a mesh with joints and weights) is a moving mesh whose surface holds
    the tangent frame too, rewritten each frame by the skinning step
    (``deferred.render.skinning``) from :attr:`rest_vbo` (the rest surface, joints and
    weights); :attr:`previous_vbo` keeps the surface of the frame before (motion vectors).

    ``keeps_previous=True`` gives a moving mesh a :attr:`previous_vbo` too, the surface of the
    frame before as its owner keeps it (:meth:`keep_previous` before each rewrite), for the
    motion vectors of a surface that moves on its own (simulated hair)."""

    ctx: moderngl.Context
    data: MeshData
    moving: bool = False
    skinned: bool = False
    keeps_previous: bool = False
    vbo: moderngl.Buffer = field(init=False)
    ibo: moderngl.Buffer = field(init=False)
    surface_vbo: moderngl.Buffer | None = field(init=False, default=None)
    rest_vbo: moderngl.Buffer | None = field(init=False, default=None)
    previous_vbo: moderngl.Buffer | None = field(init=False, default=None)
    extra_vbo: moderngl.Buffer | None = field(init=False, default=None)  # made when first read
    _arrays: dict[int, moderngl.VertexArray] = field(init=False, default_factory=dict)

    def __post_init__(self) -> None:
        if self.skinned:
            self.moving = True
            surface = self._surface(SKINNED_SURFACE)
            self.surface_vbo = self.ctx.buffer(surface.tobytes())
            self.previous_vbo = self.ctx.buffer(surface.tobytes())
            rest = np.hstack([surface, self.data.joints.astype(np.float32),
                              self.data.weights.astype(np.float32)])
            self.rest_vbo = self.ctx.buffer(np.ascontiguousarray(rest, np.float32).tobytes())
            parts = [self.data.uvs, self.data.comb]
            self.vbo = self.ctx.buffer(np.hstack(parts).astype(np.float32).tobytes())
        elif self.moving:
            self.surface_vbo = self.ctx.buffer(self._surface().tobytes())
            if self.keeps_previous:
                self.previous_vbo = self.ctx.buffer(self._surface().tobytes())
            parts = [self.data.uvs, self.data.tangents, self.data.binormals, self.data.comb]
            self.vbo = self.ctx.buffer(np.hstack(parts).astype(np.float32).tobytes())
        else:
            self.vbo = self.ctx.buffer(self.data.interleaved().tobytes())
        self.ibo = self.ctx.buffer(self.data.indices.astype(np.uint32).tobytes())

    def _surface(self, attributes=VERTEX_ATTRIBUTES[:2]) -> np.ndarray:
        return np.ascontiguousarray(np.hstack([getattr(self.data, f"{name}s")
                                               for name, _ in attributes]), dtype=np.float32)

    def write_surface(self) -> None:
        """Upload the mesh data's positions and normals again (``moving`` meshes)."""
        if self.surface_vbo is None:
            raise ValueError(f"{self.data.name}: only a moving mesh rewrites its surface")
        self.surface_vbo.write(self._surface().tobytes())

    def keep_previous(self) -> None:
        """The surface as it is becomes the frame before's (``keeps_previous`` meshes): called
        before the surface is rewritten for a new frame, or on a frame that does not move it
        (no motion)."""
        if self.previous_vbo is None or self.skinned:
            raise ValueError(f"{self.data.name}: only a moving mesh made with keeps_previous "
                             "keeps its previous surface")
        self.ctx.copy_buffer(self.previous_vbo, self.surface_vbo)

    def vertex_buffer(self, program: moderngl.Program) -> tuple:
        """The vertex buffer with the format of the attributes ``program`` reads (moderngl's
        ``(buffer, format, *names)``), for vertex arrays over other index buffers too (a
        moving mesh's: :meth:`vertex_buffers`)."""
        if self.moving:
            raise ValueError(f"{self.data.name}: a moving mesh has two vertex buffers")
        return self._buffer_format(self.vbo, VERTEX_ATTRIBUTES, program)

    def vertex_buffers(self, program: moderngl.Program) -> list[tuple]:
        """:meth:`vertex_buffer`, or a moving mesh's two buffers (those ``program`` reads),
        and the extra attributes' buffer where ``program`` reads one of them."""
        if not self.moving:
            buffers = [self.vertex_buffer(program)]
        else:
            if self.skinned:
                buffers = [self._buffer_format(self.surface_vbo, SKINNED_SURFACE, program),
                           self._buffer_format(self.vbo, (VERTEX_ATTRIBUTES[2],
                                                          VERTEX_ATTRIBUTES[5]), program),
                           self._buffer_format(self.previous_vbo, PREVIOUS_SURFACE, program)]
            else:
                buffers = [self._buffer_format(self.surface_vbo, VERTEX_ATTRIBUTES[:2], program),
                           self._buffer_format(self.vbo, VERTEX_ATTRIBUTES[2:], program)]
                if self.previous_vbo is not None:
                    buffers.append(self._buffer_format(self.previous_vbo,
                                                       PREVIOUS_MOVING_SURFACE, program))
            buffers = [buffer for buffer in buffers if len(buffer) > 2]
        if any(f"in_{name}" in program for name, _ in EXTRA_ATTRIBUTES):
            if self.extra_vbo is None:
                self.extra_vbo = self.ctx.buffer(self.data.extra_attributes().tobytes())
            buffers.append(self._buffer_format(self.extra_vbo, EXTRA_ATTRIBUTES, program))
        return buffers

    @staticmethod
    def _buffer_format(buffer: moderngl.Buffer, attributes, program: moderngl.Program) -> tuple:
        fmt, names = [], []
        for name, count in attributes:
            attribute = f"in_{name}"
            if attribute in program:
                fmt.append(f"{count}f")
                names.append(attribute)
            else:
                fmt.append(f"{count * 4}x")
        return (buffer, " ".join(fmt), *names)

    def vertex_array(self, program: moderngl.Program) -> moderngl.VertexArray:
        vao = self._arrays.get(program.glo)
        if vao is None:
            vao = self.ctx.vertex_array(program, self.vertex_buffers(program),
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
        for buffer in (self.surface_vbo, self.rest_vbo, self.previous_vbo, self.extra_vbo):
            if buffer is not None:
                buffer.release()


class MeshPrimitives:
    """A mesh's vertex buffer drawn through another index buffer as other primitives (lines or
    triangles with adjacency for a geometry shader: fins, silhouette strokes); one vertex array
    per program, released with it. The mesh's buffers stay the mesh's. No indices (a mesh
    with no interior edge has no fins) draw nothing: GL has no empty buffer."""

    def __init__(self, ctx: moderngl.Context, gpu_mesh: GpuMesh, indices: np.ndarray,
                 mode: int):
        self.ctx = ctx
        self.gpu_mesh = gpu_mesh  # holds its MeshData: a cache key's id() stays unique
        self.mode = mode
        self.count = int(indices.size)
        self.ibo = ctx.buffer(np.ascontiguousarray(indices, dtype=np.uint32).tobytes()) \
            if self.count else None
        self._arrays: dict[int, moderngl.VertexArray] = {}

    def render(self, program: moderngl.Program) -> None:
        if self.ibo is None:
            return
        vao = self._arrays.get(program.glo)
        if vao is None:
            vao = self.ctx.vertex_array(program, self.gpu_mesh.vertex_buffers(program),
                                        index_buffer=self.ibo, index_element_size=4)
            self._arrays[program.glo] = vao
        vao.render(self.mode, vertices=self.count)

    def release(self) -> None:
        for vao in self._arrays.values():
            vao.release()
        self._arrays.clear()
        if self.ibo is not None:
            self.ibo.release()
