"""The per-frame context passes run against, and the resources that live across frames."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import moderngl
import numpy as np

from .camera import gl_bytes
from .context import GLContext
from .mesh import GpuMesh, MeshData
from .shaderlib import ShaderLibrary
from .targets import FrameTargets

if TYPE_CHECKING:
    from .lightbuffer import LightBuffer
    from .scene import Scene, SceneObject

# Blend modes by name: passes say what they want, not GL enums.
BLEND_MODES = {
    "add": (moderngl.ONE, moderngl.ONE),
    # alpha stays coverage: a over background (0) gives a, over a surface (1) stays 1
    "alpha": (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA, moderngl.ONE,
              moderngl.ONE_MINUS_SRC_ALPHA),
    "premultiplied": (moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA),
}
DEPTH_FUNCS = {"less": "<", "lequal": "<=", "gequal": ">=", "greater": ">", "equal": "==",
               "always": "1"}


class Resources:
    """GPU objects that outlive one frame: meshes, textures loaded from files, helper geometry."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._meshes: dict[int, GpuMesh] = {}
        self._mesh_refs: list[MeshData] = []  # keep ids stable while cached
        self._textures: dict[Any, moderngl.Texture] = {}
        self._fullscreen_vaos: dict[int, moderngl.VertexArray] = {}

    def gpu_mesh(self, mesh: MeshData) -> GpuMesh:
        gpu = self._meshes.get(id(mesh))
        if gpu is None:
            gpu = GpuMesh(self.ctx, mesh)
            self._meshes[id(mesh)] = gpu
            self._mesh_refs.append(mesh)
        return gpu

    def texture(self, key: Any, create) -> moderngl.Texture:
        """A cached texture; ``create()`` makes it the first time ``key`` is asked for."""
        texture = self._textures.get(key)
        if texture is None:
            texture = create(self.ctx)
            self._textures[key] = texture
        return texture

    def image_texture(self, path: Path, srgb: bool = True) -> moderngl.Texture:
        from .imageio import read_image

        def create(ctx: moderngl.Context) -> moderngl.Texture:
            pixels = read_image(path, srgb_to_linear=srgb)
            height, width, _ = pixels.shape
            texture = ctx.texture((width, height), 4, np.ascontiguousarray(
                pixels[::-1]).astype(np.float16).tobytes(), dtype="f2")
            texture.build_mipmaps()
            texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            return texture

        return self.texture(("image", str(path), srgb), create)

    def fullscreen_vertex_array(self, program: moderngl.Program) -> moderngl.VertexArray:
        # Full-screen triangles are generated from gl_VertexID; a VAO with no buffers draws them.
        vao = self._fullscreen_vaos.get(program.glo)
        if vao is None:
            vao = self.ctx.vertex_array(program, [])
            self._fullscreen_vaos[program.glo] = vao
        return vao

    def release(self) -> None:
        for gpu in self._meshes.values():
            gpu.release()
        self._meshes.clear()
        self._mesh_refs.clear()
        for texture in self._textures.values():
            texture.release()
        self._textures.clear()
        for vao in self._fullscreen_vaos.values():
            vao.release()
        self._fullscreen_vaos.clear()


@dataclass
class FrameStats:
    draw_calls: int = 0
    draws_by_pass: dict[str, int] = field(default_factory=dict)


class Frame:
    """What a pass sees while it runs: GL, shaders, targets, scene, camera and lights."""

    def __init__(self, gl: GLContext, shaders: ShaderLibrary, targets: FrameTargets,
                 resources: Resources, scene: Scene, light_buffer: LightBuffer):
        self.gl = gl
        self.ctx = gl.ctx
        self.shaders = shaders
        self.targets = targets
        self.resources = resources
        self.scene = scene
        self.light_buffer = light_buffer
        self.width = targets.width
        self.height = targets.height
        self.view = scene.camera.view()
        self.projection = scene.camera.projection(self.width / self.height)
        self.inverse_projection = np.linalg.inv(self.projection)
        self.stats = FrameStats()
        self.current_pass: str = ""

    # -- uniforms ------------------------------------------------------------------------------
    def camera_uniforms(self) -> dict[str, Any]:
        return {
            "u_projection": self.projection,
            "u_inverse_projection": self.inverse_projection,
            "u_view": self.view,
            "u_resolution": (float(self.width), float(self.height)),
            "u_near_far": (self.scene.camera.near, self.scene.camera.far),
        }

    def object_uniforms(self, obj: SceneObject) -> dict[str, Any]:
        model_view = self.view @ obj.model
        normal_matrix = np.linalg.inv(model_view[:3, :3]).T
        return {
            "u_model": obj.model,
            "u_model_view": model_view,
            "u_normal_matrix": normal_matrix,
            "u_material_id": float(obj.material.type_id),
            **self.camera_uniforms(),
        }

    def bind(self, program: moderngl.Program, uniforms: dict[str, Any] | None = None,
             textures: dict[str, moderngl.Texture] | None = None) -> None:
        """Set the uniforms ``program`` declares (others are ignored) and bind textures."""
        for name, value in (uniforms or {}).items():
            if name not in program:
                continue
            member = program[name]
            if isinstance(value, np.ndarray) and value.ndim == 2:
                member.write(gl_bytes(value))
            elif isinstance(value, np.ndarray):
                member.value = tuple(float(v) for v in value)
            else:
                member.value = value
        unit = 0
        for name, texture in (textures or {}).items():
            if name not in program:
                continue
            texture.use(location=unit)
            program[name].value = unit
            unit += 1
        self.light_buffer.bind(program, unit)

    def target_samplers(self, names) -> dict[str, moderngl.Texture]:
        """Targets by the sampler names shaders use for them: ``u_<target name>``."""
        return {f"u_{name}": self.targets[name] for name in names}

    # -- drawing -------------------------------------------------------------------------------
    def _count(self) -> None:
        self.stats.draw_calls += 1
        self.stats.draws_by_pass[self.current_pass] = \
            self.stats.draws_by_pass.get(self.current_pass, 0) + 1

    def draw_mesh(self, mesh: MeshData, program: moderngl.Program, instances: int = 1) -> None:
        self.resources.gpu_mesh(mesh).render(program, instances=instances)
        self._count()

    def draw_fullscreen(self, program: moderngl.Program, instances: int = 1) -> None:
        vao = self.resources.fullscreen_vertex_array(program)
        vao.render(moderngl.TRIANGLES, vertices=3, instances=instances)
        self._count()

    def use_framebuffer(self, colors: tuple[str, ...] | list[str], depth: str | None = None,
                        depth_write: bool = True) -> moderngl.Framebuffer:
        fbo = self.targets.framebuffer(colors, depth)
        fbo.use()
        fbo.depth_mask = depth_write
        self.ctx.viewport = (0, 0, self.width, self.height)
        return fbo

    def set_state(self, depth_test: bool = False, depth_func: str = "less",
                  cull: str | None = None, blend: str | None = None) -> None:
        """Set the fixed-function state a pass needs; every pass states all of it."""
        flags = moderngl.NOTHING
        if depth_test:
            flags |= moderngl.DEPTH_TEST
            self.ctx.depth_func = DEPTH_FUNCS[depth_func]
        if cull:
            flags |= moderngl.CULL_FACE
            self.ctx.cull_face = cull
        if blend:
            flags |= moderngl.BLEND
            self.ctx.blend_func = BLEND_MODES[blend]
            self.ctx.blend_equation = moderngl.FUNC_ADD
        self.ctx.enable_only(flags)
