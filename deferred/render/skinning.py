"""Skinned meshes deformed on the GPU before a frame's passes draw them.

Each skinned object of the frame state (``ObjectState.skin_matrices``) has its mesh's surface
buffer rewritten by transform feedback (``shaders/skinning/skin.vert``): the rest surface moved
by the weighted sum of each vertex's four joint matrices, read from a float texture of a row a
joint. Every pass (G-buffer, forward, shadows, fur) then draws the deformed mesh as it draws any
mesh. The surface of the frame before is kept (``GpuMesh.previous_vbo``) for the motion vectors
of temporal anti-aliasing; on an object's first frame it is the frame's own.
"""

from __future__ import annotations

from typing import Any

import moderngl
import numpy as np

from deferred.gl.meshes import GpuMesh
from deferred.gl.resources import Resources
from deferred.gl.shaderlib import ShaderLibrary
from deferred.scene.state import FrameState

SKIN_SHADER = "skinning/skin.vert"
VARYINGS = ("out_position", "out_normal", "out_tangent", "out_binormal")
REST_FORMAT = ("3f 3f 3f 3f 4f 4f", "in_position", "in_normal", "in_tangent", "in_binormal",
               "in_joints", "in_weights")


class Skinning:
    """Deforms a renderer's skinned meshes each frame (see the module documentation)."""

    def __init__(self, ctx: moderngl.Context, shaders: ShaderLibrary, resources: Resources):
        self.ctx = ctx
        self.shaders = shaders
        self.resources = resources
        self._program: moderngl.Program | None = None
        self._arrays: dict[int, moderngl.VertexArray] = {}
        self._textures: dict[int, moderngl.Texture] = {}
        self._skinned: dict[int, np.ndarray] = {}  # by GPU mesh: the matrices it holds

    def program(self) -> moderngl.Program:
        if self._program is None:
            source = self.shaders.assemble(SKIN_SHADER)
            self._program = self.ctx.program(vertex_shader=source.text,
                                             varyings=list(VARYINGS),
                                             varyings_capture_mode="interleaved")
        return self._program

    def run(self, state: FrameState) -> int:
        """Deform every skinned object of ``state`` whose joint matrices changed since its
        mesh was last deformed; the number deformed."""
        count = 0
        for obj in state.objects:
            matrices = obj.skin_matrices
            if matrices is None:
                continue
            gpu = self.resources.gpu_mesh(obj.mesh)
            held = self._skinned.get(id(gpu))
            if held is matrices:
                # the same pose again: the frame before is this one (no motion)
                self.ctx.copy_buffer(gpu.previous_vbo, gpu.surface_vbo)
                continue
            self._deform(gpu, matrices, first=held is None)
            self._skinned[id(gpu)] = matrices
            count += 1
        return count

    def _deform(self, gpu: GpuMesh, matrices: np.ndarray, first: bool) -> None:
        if not first:
            self.ctx.copy_buffer(gpu.previous_vbo, gpu.surface_vbo)
        texture = self._joint_texture(gpu, matrices)
        program = self.program()
        vao = self._arrays.get(id(gpu))
        if vao is None:
            vao = self.ctx.vertex_array(program, [(gpu.rest_vbo, *REST_FORMAT)])
            self._arrays[id(gpu)] = vao
        texture.use(0)
        program["u_joint_matrices"].value = 0
        vao.transform(gpu.surface_vbo, moderngl.POINTS, vertices=gpu.data.vertex_count)
        if first:
            self.ctx.copy_buffer(gpu.previous_vbo, gpu.surface_vbo)

    def _joint_texture(self, gpu: GpuMesh, matrices: np.ndarray) -> moderngl.Texture:
        """The joint matrices as a float texture: a row a joint, its four columns."""
        count = len(matrices)
        texture = self._textures.get(id(gpu))
        if texture is None or texture.height != count:
            if texture is not None:
                texture.release()
            texture = self.ctx.texture((4, count), 4, dtype="f4")
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self._textures[id(gpu)] = texture
        columns = np.ascontiguousarray(np.transpose(matrices, (0, 2, 1)), np.float32)
        texture.write(columns.tobytes())
        return texture

    def release(self) -> None:
        for held in (*self._arrays.values(), *self._textures.values()):
            held.release()
        self._arrays.clear()
        self._textures.clear()
        self._skinned.clear()
        if self._program is not None:
            self._program.release()
            self._program = None


def skinned_objects(state: Any) -> bool:
    """Whether ``state`` has an object to deform."""
    return any(obj.skin_matrices is not None for obj in state.objects)
