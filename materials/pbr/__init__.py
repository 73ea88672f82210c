"""The ``pbr`` material: glTF 2.0's metallic-roughness, lit by the ``pbr`` shading model
(``materials/shading_models/pbr.glsl``: Filament's standard model) in both pipelines.

Its parameters (:mod:`.params`) are glTF's: base colour (RGBA) and texture, metallic and
roughness and their texture (B and G), a normal map and its scale, occlusion and its strength,
emission, its texture and KHR_materials_emissive_strength, each texture with its UV set,
KHR_texture_transform and its sampler's wrap and filter modes; vertex colours multiply the base
colour, and a normal map reads the mesh's tangents (the file's, else MikkTSpace's frame:
``deferred.gl.tangents``).

Alpha modes: ``opaque``; ``mask`` cuts below ``alpha_cutoff`` in every pass, the shadow maps'
included; ``blend`` writes no G-buffer: its surface is lit in one pass after the opaque scene
(the deferred pipeline's material phase, the forward pipeline's transparent rank), by the same
lights and shadows, blended over what lies behind, far to near by object. ``double_sided``
draws both faces. The deferred pipeline adds an emissive surface's emission over its lit pixels
in the material phase (the G-buffer keeps no channel for it).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import moderngl

from deferred.api import (
    COMPOSITE,
    SHADOW_CASTER_DEFINES,
    ForwardLitPass,
    GBufferPass,
    Material,
    ObjectPass,
    Order,
    Phase,
    ShadowCaster,
    Technique,
    check_image,
    image_texture_bytes,
    materials,
)

from .params import SRGB_TEXTURES, TEXTURES, PbrParams, TextureParams, texture_params

if TYPE_CHECKING:
    from deferred.api import Frame, RenderPass, SceneObject, ShadowView

VERTEX = "common/mesh.vert"
FORWARD = "materials/pbr/forward.frag"
EMISSION = "materials/pbr/emission.frag"
CASTER = "materials/pbr/caster.frag"

MIN_FILTERS = {"nearest": moderngl.NEAREST, "linear": moderngl.LINEAR,
               "nearest_mipmap_nearest": moderngl.NEAREST_MIPMAP_NEAREST,
               "linear_mipmap_nearest": moderngl.LINEAR_MIPMAP_NEAREST,
               "nearest_mipmap_linear": moderngl.NEAREST_MIPMAP_LINEAR,
               "linear_mipmap_linear": moderngl.LINEAR_MIPMAP_LINEAR}


def texture_uniforms(name: str):
    """The uniforms a texture parameter becomes: its UV set, transform rows and mirrored
    wraps (its sampler is one of the material's textures)."""
    def uniforms(value) -> dict:
        texture = texture_params(value)
        if texture is None:
            return {}
        row_u, row_v = texture.rows()
        return {f"u_{name}_uv": texture.uv, f"u_{name}_transform_u": row_u,
                f"u_{name}_transform_v": row_v,
                f"u_{name}_mirror": (float(texture.wrap_s == "mirrored_repeat"),
                                     float(texture.wrap_t == "mirrored_repeat"))}
    return uniforms


def sampler_state(texture: TextureParams) -> tuple[tuple[int, int], tuple[bool, bool]]:
    """GL's (min, mag) filters and repeat flags of a texture: mirrored wraps repeat in GL and
    fold in the shader (``surface.glsl``); clamp_to_edge clamps."""
    mag = moderngl.NEAREST if texture.mag_filter == "nearest" else moderngl.LINEAR
    return ((MIN_FILTERS[texture.min_filter], mag),
            (texture.wrap_s != "clamp_to_edge", texture.wrap_t != "clamp_to_edge"))


class PbrPasses(Technique):
    """The passes of each alpha mode (module documentation)."""

    def passes(self, material: Material, phase: Phase, obj: SceneObject) -> list[RenderPass]:
        params = material.params
        cull = None if params.double_sided else "back"
        label = obj.label
        if params.alpha_mode == "blend":
            if phase not in (Phase.MATERIAL, Phase.FORWARD):
                return []
            return [ObjectPass(f"{label}.blend", phase, obj, fragment=FORWARD,
                               colors=(COMPOSITE,), depth_func="lequal", depth_write=False,
                               blend="alpha", cull=cull, order=Order.TRANSPARENT)]
        if phase == Phase.GEOMETRY:
            return [GBufferPass(f"{label}.gbuffer", phase, obj, cull=cull)]
        if phase == Phase.FORWARD:
            return [ForwardLitPass(f"{label}.forward", phase, obj, fragment=FORWARD, cull=cull)]
        if phase == Phase.MATERIAL and material.emits():
            return [ObjectPass(f"{label}.emission", phase, obj, fragment=EMISSION,
                               colors=(COMPOSITE,), depth_func="lequal", depth_write=False,
                               blend="add", cull=cull, order=Order.OPAQUE)]
        return []


class PbrShadow(ShadowCaster):
    """The mesh's depth; where the material cuts itself out (mask, and blend taken as cut at
    its cutoff), through its surface, discarding what it cuts."""

    def draw(self, frame: Frame, obj: SceneObject, view: ShadowView) -> None:
        material = obj.material
        if material.params.alpha_mode == "opaque":
            super().draw(frame, obj, view)
            return
        program = frame.shaders.program(VERTEX, CASTER, defines={
            **material.defines(obj), **SHADOW_CASTER_DEFINES})
        frame.bind(program, {}, offered={**frame.object_uniforms(obj), **view.camera_uniforms},
                   material=frame.material_inputs(material))
        frame.draw_mesh(obj.mesh, program)


@materials.register
class PbrMaterial(Material):
    name = "pbr"
    Params = PbrParams
    surface_shader = "materials/pbr/surface.glsl"
    shading_model = "pbr"
    techniques = (PbrPasses(),)
    shadow = PbrShadow()
    inputs_from_params = True  # uniforms from the params, textures from frame.resources
    uniform_overrides = {"alpha_mode": None, "double_sided": None,
                         **{f"{name}_texture": texture_uniforms(name)
                            for name in TEXTURES}}

    def textures_given(self) -> dict[str, TextureParams]:
        """The material's textures by name (``base_color``...), those it has."""
        given = {name: texture_params(getattr(self.params, f"{name}_texture"))
                 for name in TEXTURES}
        return {name: texture for name, texture in given.items() if texture is not None}

    def emits(self) -> bool:
        return any(self.params.emissive) and self.params.emissive_strength > 0.0

    def check_files(self, where: str | None) -> None:
        for name, texture in self.textures_given().items():
            key = f"{where}.{name}_texture" if where else f"{name}_texture"
            check_image(self.file_parameter(texture.path, f"{name} texture", key), key)

    def held_memory(self, obj) -> dict[str, int]:
        held = {}
        for texture in self.textures_given().values():
            path = self.resolve_path(texture.path)
            width, height, _ = check_image(path)
            held[f"texture {path} {sampler_state(texture)}"] = image_texture_bytes(width, height)
        return held

    def defines(self, obj: SceneObject) -> dict[str, str]:
        defines = super().defines(obj)
        defines["MESH_EXTRAS"] = "1"
        if self.params.alpha_mode != "opaque":
            defines[f"ALPHA_{self.params.alpha_mode.upper()}"] = "1"
        if self.params.alpha_mode == "mask":  # Forward+'s depth pre-pass cuts it too
            defines["SURFACE_DISCARDS"] = "1"
        if self.params.double_sided:
            defines["DOUBLE_SIDED"] = "1"
        for name in self.textures_given():
            defines[f"HAS_{name.upper()}_TEXTURE"] = "1"
        return defines

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        return {f"u_{name}_texture": frame.resources.image_texture(
                    self.resolve_path(texture.path), srgb=name in SRGB_TEXTURES,
                    sampler=sampler_state(texture))
                for name, texture in self.textures_given().items()}
