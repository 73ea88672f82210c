"""The plugin API: everything a material, light, shading model or effect imports, in one module.

A plugin (the built-in materials, lights and effects, and the example package in
``examples/plugins``) imports from here and nowhere else in ``deferred``;
``docs/writing-a-material.md`` walks through it. The names, by what they are for:

- **interfaces**: :class:`Material` (with :class:`MaterialParams`, :class:`BlinnPhongParams`)
  and the parts it is composed of: its passes, :class:`Technique` (:class:`SurfacePasses`, the
  :class:`GBufferPass` and :class:`ForwardLitPass` every material has by default;
  :class:`PhasePasses`), its shadows, :class:`ShadowCaster` (:class:`NoShadow`,
  :class:`ShadowView`, ``SHADOW_CASTER_DEFINES``), :class:`Motion` (:class:`ReachMotion`,
  :class:`MotionOffsets`) and :class:`Simulation`; :class:`ShadingModel`, :class:`GBufferData`,
  :class:`Light` (:class:`LightParams`, :class:`LightDatum` for a type's own data;
  :class:`AreaLight` and :class:`AreaLightParams`, the base of polygonal area lights, with
  ``ltc_textures``, ``area_light_frame`` and ``disc_polygon_radius``), :class:`Effect`
  (:class:`EffectParams`, :class:`GBufferEffectParams` for an effect reading the G-buffer that
  may run in the forward pipeline), and the registries to register them with: ``materials``,
  ``lights``, ``shading_models``, ``effects``.
- **passes**: :class:`RenderPass`, :class:`ObjectPass` (with the :class:`PassInput` and
  :class:`Shape` it composes), :class:`FullscreenPass`, :class:`ClearPass`, :func:`copy_pass`,
  compositions of passes (:func:`compose_runs`, ``BEGIN``, ``END``: order-independent
  transparency),
  :class:`Phase` and :class:`Order`; :class:`Blend` (a pass output's blend factors and
  equations, beside the named modes); :func:`select_surfaces` (a full-screen pass's
  defines selecting one material's or shading model's pixels, ``gbuffer/select.glsl``); the
  :class:`Frame` a pass runs against;
  :class:`TargetSpec` for the targets a pass creates.
- **targets by name**: the G-buffer's (``ALBEDO_SPECULAR``, ``NORMAL_EXPONENT_ID``,
  ``LINEAR_DEPTH``, ``DEPTH``, ``GBUFFER_COLOR_TARGETS``) and the frame's
  (``LIGHT_ACCUMULATION``, ``DIFFUSE_LIGHT`` where the scene splits its light, ``COMPOSITE``,
  ``FINAL`` and their specs).
- **parameters**: the validated types (:data:`Albedo`, :data:`Radiance`, :data:`NonZeroVec3`),
  :class:`Params` and ``UniformOverrides``; ``require_regular_file`` for file parameters,
  ``number_too_long`` for a file whose parser refuses an integer of too many digits.
- **cost**: what a material's, simulation's or effect's ``work`` returns for the cost model,
  :class:`Work` terms (``Per`` render, frame or sample) from a :class:`WorkObject` and the
  :class:`RenderWork` asked for; ``check_memory`` refuses an allocation past the memory budget.
- **data**: :class:`MeshData` and :class:`GpuMesh` (the vertex format), the disk cache
  (:func:`cache_folder`, :func:`write_cached_arrays`, :func:`file_digest`), :class:`SceneObject`
  and :class:`Scene` (what passes are made for), images (:func:`read_image`,
  :func:`read_channels`, :func:`check_image`), the light helpers (``view_point(s)``,
  ``view_direction(s)``, ``radiances``), the names (:class:`LightVolume`, :class:`Pipeline`,
  :class:`LightPath`), the errors (:class:`InputError`, :class:`RenderError`) and
  ``MAX_COORDINATE``, the bound on a mesh's coordinates (a plugin reading points keeps it).
- **GLSL**: :data:`GLSL_INCLUDES`, the framework's shader files a plugin's GLSL may include,
  each with what it gives; :func:`register_shader_root` for a folder of GLSL every scene
  searches (a class's own is its ``shader_root``).

A plugin contributes passes, GLSL, parameters and G-buffer data; it cannot add a per-frame
resource every program reads (a binding source, ``deferred.core.frame.Frame``): those are the
renderer's (``Renderer.binding_sources``).
"""

from __future__ import annotations

from deferred.core.frame import Frame
from deferred.core.passes import (
    BEGIN,
    END,
    ClearPass,
    FullscreenPass,
    ObjectPass,
    Order,
    PassInput,
    Phase,
    RenderPass,
    Shape,
    compose_runs,
    copy_pass,
)
from deferred.errors import InputError, RenderError
from deferred.gbuffer import (
    ALBEDO_SPECULAR,
    DEPTH,
    GBUFFER_COLOR_TARGETS,
    LINEAR_DEPTH,
    MOTION,
    MOTION_SPEC,
    NORMAL_EXPONENT_ID,
    GBufferData,
)
from deferred.gl.blend import Blend
from deferred.gl.meshes import GpuMesh, MeshData, MeshPrimitives
from deferred.gl.resources import image_texture_bytes
from deferred.gl.shaderlib import register_shader_root
from deferred.gl.target_spec import TargetSpec
from deferred.gl.targets import (
    COMPOSITE,
    COMPOSITE_SPEC,
    DIFFUSE_LIGHT,
    DIFFUSE_LIGHT_SPEC,
    FINAL,
    FINAL_SPEC,
    LIGHT_ACCUMULATION,
    LIGHT_ACCUMULATION_SPEC,
)
from deferred.interfaces.area import (
    AreaLight,
    AreaLightParams,
    disc_polygon_radius,
    ltc_textures,
)
from deferred.interfaces.area import (
    light_frame as area_light_frame,
)
from deferred.interfaces.effect import (
    AMBIENT_OCCLUSION,
    Effect,
    EffectParams,
    FrameMoment,
    GBufferEffectParams,
    halton,
)
from deferred.interfaces.light import (
    Light,
    LightDatum,
    LightParams,
    ShadowParams,
    radiances,
    view_direction,
    view_directions,
    view_point,
    view_points,
)
from deferred.interfaces.material import BlinnPhongParams, Material, MaterialParams
from deferred.interfaces.registry import effects, lights, materials, shading_models
from deferred.interfaces.selection import select_surfaces
from deferred.interfaces.shading import ShadingModel
from deferred.interfaces.shadow_casting import (
    SHADOW_CASTER_DEFINES,
    NoShadow,
    ShadowCaster,
    ShadowView,
)
from deferred.interfaces.simulation import Motion, MotionOffsets, ReachMotion, Simulation
from deferred.interfaces.techniques import (
    ForwardLitPass,
    GBufferPass,
    PhasePasses,
    SurfacePasses,
    Technique,
)
from deferred.interfaces.work import Per, RenderWork, Work, WorkObject, counted
from deferred.io.cache import cache_folder, file_digest, write_cached_arrays
from deferred.io.images import check_image, read_channels, read_image, srgb_decode
from deferred.io.memory import check_memory
from deferred.names import LightPath, LightVolume, Pipeline, ShadowProjection
from deferred.params import Params, UniformOverrides
from deferred.scene import Scene, SceneObject
from deferred.scene.builtin_meshes import builtin_head_spheres
from deferred.scene.geometry import MAX_COORDINATE
from deferred.validation import (
    Albedo,
    NonZeroVec3,
    Radiance,
    number_too_long,
    require_regular_file,
)

# The framework's GLSL a plugin may include (``#include "<file>"``), and what each gives.
GLSL_INCLUDES: dict[str, str] = {
    "common/surface.glsl": "struct Surface (what a material's surface function returns) and "
                           "the surface-id helpers",
    "common/surface_input.glsl": "struct SurfaceInput (the fragment's interpolated inputs) "
                                 "and the framework's completion of a Surface",
    "common/object_transform.glsl": "the object's model and normal matrices and the camera's "
                                    "view (vertex shaders)",
    "common/motion.glsl": "this frame's and the last frame's unjittered clip positions of an "
                          "object-space point (motion vectors; vertex shaders)",
    "common/lighting.glsl": "struct LightRecord and the shading-model interface (a light's "
                            "GLSL function)",
    "lighting/shadows.glsl": "light_shadow_cascades, _perspective, _cube: the lit fraction of "
                            "a shadowed light at a point, per channel (a light's GLSL "
                            "function multiplies by its projection's), coloured through "
                            "transparent casters (SHADOW_TRANSMITTANCE); with deep opacity maps "
                            "(OPACITY_SHADOWS), times the transmittance through them: at the "
                            "point's depth for an OPACITY_RECEIVER (the volume's own shading), "
                            "through the whole volume beyond its back for any other surface",
    "common/forward_lighting.glsl": "every light of the frame at one surface point (forward "
                                    "passes)",
    "lighting/area.glsl": "struct AreaLight and shade_area (an area light's GLSL); a shading "
                          "model's area function's integrals: the polygon's clipped cosine "
                          "integral (area_irradiance), a GGX lobe's share by linearly "
                          "transformed cosines (area_ggx), the light as a point light "
                          "(area_as_point_light)",
    "lighting/area_light.glsl": "shade_area_light: an area light type's light once it has its "
                                "polygon (AreaLight): the light through thin parts, the shadow "
                                "of its cube tiles, the shading models' area answer",
    "lighting/environment.glsl": "struct Environment and the image-based light's lookups: "
                                 "irradiance (9 spherical harmonics) and GGX-prefiltered "
                                 "radiance by roughness (a shading model's environment "
                                 "function)",
    "gbuffer/layout.glsl": "the G-buffer's encoding and decoding",
    "gbuffer/select.glsl": "surface_selected(surface id), pixel_selected(sampler, pixel): "
                           "whether a pixel is one of the materials or shading models "
                           "select_surfaces(...) names (its defines)",
    "gbuffer/write.glsl": "the G-buffer's outputs and gbuffer_write (G-buffer passes)",
    "materials/techniques/stipple.glsl": "stipple patterns (Revie 2.3.4, Listing 2.6)",
    "materials/techniques/rim.glsl": "rim scattering by bent normals (Revie 2.3.2, Listing 2.3)",
    "materials/techniques/grain_normal.glsl": "the anisotropic grain normal (Revie 2.3.3, "
                                              "Listing 2.5)",
    "materials/techniques/shells.glsl": "concentric shell offsets (Revie 2.3.1, Listing 2.1)",
    "materials/techniques/fur.glsl": "the fur volume's coverage and brightness lookups",
    "materials/techniques/accumulated_light.glsl": "a fur layer's light from the light "
                                                   "accumulation (Revie 2.4.4, Listing 2.2)",
    "materials/techniques/fur_light.glsl": "a fur layer's light from a fur_light gather",
    "materials/techniques/fur_relight.glsl": "a fur layer's full-screen light moved from its "
                                             "sample to the layer (after "
                                             "common/light_buffer.glsl and "
                                             "generated/lights.glsl)",
    "materials/techniques/strand_tangent.glsl": "a strand tangent as G-buffer data "
                                                "(Kajiya-Kay)",
    "materials/techniques/hatching.glsl": "tonal-art-map hatching, on the surface (Praun et "
                                          "al.) or projected on the screen (Lake et al.; "
                                          "Costigan 4.3.8)",
}

__all__ = [
    "ALBEDO_SPECULAR", "AMBIENT_OCCLUSION", "AreaLight", "AreaLightParams", "BEGIN",
    "LightDatum", "area_light_frame", "disc_polygon_radius", "ltc_textures",
    "COMPOSITE", "COMPOSITE_SPEC", "DEPTH", "DIFFUSE_LIGHT", "DIFFUSE_LIGHT_SPEC", "END", "FINAL",
    "FINAL_SPEC", "FrameMoment", "GBUFFER_COLOR_TARGETS", "GLSL_INCLUDES", "LIGHT_ACCUMULATION",
    "LIGHT_ACCUMULATION_SPEC", "LINEAR_DEPTH", "MAX_COORDINATE", "MOTION", "MOTION_SPEC",
    "NORMAL_EXPONENT_ID",
    "Albedo", "Blend",
    "BlinnPhongParams", "ClearPass", "Effect", "EffectParams", "ForwardLitPass", "Frame",
    "GBufferEffectParams",
    "FullscreenPass", "GBufferData", "GBufferPass", "GpuMesh", "InputError", "Light",
    "LightParams", "LightPath", "LightVolume", "Material", "MaterialParams", "MeshData",
    "MeshPrimitives", "Motion", "MotionOffsets", "NoShadow", "SHADOW_CASTER_DEFINES",
    "ShadowCaster",
    "ShadowParams", "ShadowProjection", "ShadowView",
    "NonZeroVec3", "ObjectPass", "Order", "Params", "PassInput", "Phase", "PhasePasses",
    "Per", "Pipeline", "Radiance", "ReachMotion",
    "RenderError", "RenderPass", "RenderWork", "Scene", "SceneObject", "ShadingModel", "Shape",
    "Simulation", "SurfacePasses", "TargetSpec", "Technique",
    "UniformOverrides", "Work", "WorkObject", "builtin_head_spheres", "cache_folder",
    "check_image", "check_memory", "compose_runs", "copy_pass", "counted", "effects",
    "file_digest", "halton",
    "image_texture_bytes", "lights", "materials", "number_too_long",
    "radiances", "read_channels", "read_image", "register_shader_root", "require_regular_file",
    "select_surfaces",
    "srgb_decode",
    "shading_models",
    "view_direction", "view_directions", "view_point", "view_points", "write_cached_arrays",
]
