"""The deferred pass that draws every light of one type (the ``volumes`` light path: bounding
spheres for point and spot lights, a full-screen triangle for the rest), and the lighting
phase's full-screen passes that run on the scene's surfaces only."""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from deferred.core.passes import FullscreenPass, Order, Phase, RenderPass
from deferred.gbuffer.layout import DEPTH, GBUFFER_COLOR_TARGETS
from deferred.gl.context import GL_DEPTH_CLAMP
from deferred.gl.meshes import MeshData
from deferred.gl.target_spec import TargetSpec
from deferred.gl.targets import DIFFUSE_LIGHT, LIGHT_ACCUMULATION
from deferred.interfaces.light import Light
from deferred.lighting.buffer import LIGHT_BUFFER
from deferred.names import LightVolume
from deferred.scene.geometry import build_mesh

if TYPE_CHECKING:
    from deferred.core.frame import Frame


@lru_cache(maxsize=1)
def light_volume_mesh() -> tuple[MeshData, float]:
    """An icosphere and the scale that makes it enclose the unit sphere (faces sit inside it)."""
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
    faces = np.asarray(sphere.faces)
    vertices = np.asarray(sphere.vertices)
    normals = np.asarray(sphere.face_normals)
    inscribed = np.min(np.abs(np.sum(normals * vertices[faces[:, 0]], axis=1)))
    mesh = build_mesh("light-volume", vertices, faces, vertices,
                      uvs=np.zeros((len(vertices), 2)))
    return mesh, 1.0 / float(inscribed)


def surface_pass(name: str, fragment: str, inputs: dict[str, str],
                 creates: dict[str, TargetSpec], background: tuple[float, float, float],
                 defines: dict[str, str] | None = None) -> FullscreenPass:
    """A full-screen pass of the lighting phase that runs on the scene's surfaces only: it
    creates ``creates`` cleared to ``background`` (alpha 0; its shader's ``u_background``, for
    pixels with depth but no surface), and draws its triangle on the far plane with the depth
    test "greater" against the G-buffer's depth (``common/fullscreen_triangle.glsl``). On
    llvmpipe a block of pixels failing that test is skipped, where an ``if`` in the shader
    skips nothing: the list shading (``deferred.lighting.culling.list_shading_pass``) and the
    volumes path's background pass."""
    cleared = (*background, 0.0)
    return FullscreenPass(name, Phase.LIGHTING, fragment, inputs, tuple(creates),
                          defines={"FULLSCREEN_AT_FAR": "1", **(defines or {})},
                          creates={target: replace(spec, clear=cleared)
                                   for target, spec in creates.items()},
                          uniforms=lambda frame: {"u_background": background},
                          depth=DEPTH, depth_test=True, depth_func="greater",
                          order=Order.FIRST)


class LightTypePass(RenderPass):
    """Deferred lighting of every light of one type, instanced, added into light accumulation.

    It reads the G-buffer, including the scene's declared data (``gbuffer``, the colour targets
    of the scene's layout), so every shading model finds what it reads. With ``split`` (the
    scene splits its light) it adds the diffuse part into the diffuse light too."""

    phase = Phase.LIGHTING

    def __init__(self, light_type: type[Light], occlusion: str | None = None,
                 gbuffer: tuple[str, ...] = GBUFFER_COLOR_TARGETS, split: bool = False):
        self.light_type = light_type
        self.writes = (LIGHT_ACCUMULATION, DIFFUSE_LIGHT) if split else (LIGHT_ACCUMULATION,)
        self.name = f"lighting.{light_type.name}"
        self.occlusion = occlusion  # target holding ambient occlusion (SSAO), if any
        self.gbuffer = gbuffer
        self.samples = (*gbuffer, *((occlusion,) if occlusion else ()))
        self.reads = (*self.samples, DEPTH, *self.writes)

    def execute(self, frame: Frame) -> None:
        offset, count = frame.blackboard[LIGHT_BUFFER].range(self.light_type)
        if count == 0:
            return
        sphere = self.light_type.volume == LightVolume.SPHERE
        vertex = "lighting/volume.vert" if sphere else "lighting/fullscreen.vert"
        defines = {"LIGHT_FUNCTION": self.light_type.glsl_function}
        if self.occlusion:
            defines["HAS_SSAO"] = "1"
        if not sphere:
            defines["FULLSCREEN_AT_FAR"] = "1"
        program = frame.shaders.program(vertex, "lighting/accumulate.frag", defines=defines)
        frame.use_framebuffer(self.writes, DEPTH, depth_write=False)
        textures = frame.target_samplers(self.gbuffer)
        if self.occlusion:
            textures["u_ssao"] = frame.target(self.occlusion)
        uniforms = {"u_light_offset": offset}
        if sphere:
            # Back faces of the bounding sphere, kept where the surface lies in front of them:
            # works with the camera inside the volume; depth clamp stops the far plane cutting it.
            mesh, scale = light_volume_mesh()
            frame.set_state(depth_test=True, depth_func="gequal", cull="front", blend="add")
            frame.bind(program, {**uniforms, "u_volume_scale": scale}, textures)
            frame.ctx.enable_direct(GL_DEPTH_CLAMP)
            try:
                frame.draw_mesh(mesh, program, instances=count)
            finally:
                frame.ctx.disable_direct(GL_DEPTH_CLAMP)
        else:
            # On the far plane, drawn where the depth is nearer: the background's pixels are
            # skipped, which an `if` in the shader cannot do on llvmpipe (surface_pass).
            frame.set_state(depth_test=True, depth_func="greater", blend="add")
            frame.bind(program, uniforms, textures)
            frame.draw_fullscreen(program, instances=count)


