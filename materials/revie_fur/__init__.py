"""Revie's deferred fur ("Implementing Fur Using Deferred Shading", GPU Pro 2, chapter 2).

Passes per phase (section 2.4):
- geometry: the base mesh into the G-buffer with anisotropic grain normals (2.4.2, Listing 2.5);
- stipple: the outermost shell into one pixel of every 2x2 tile, rim-bent normals at the
  silhouette (2.3.2, 2.3.4, Listings 2.3 and 2.6), after the screen phase;
- lighting: nothing special, both samples are lit like any pixel (2.4.3);
- material: stipple obliteration, then concentric shells and fins that take their light from
  the light accumulation at the base and stipple samples (2.4.4, Listings 2.1 and 2.2);
- forward: the same fur lit per fragment, for preview and for the benchmark (2.4).

The shells, their fur volume, level of detail and fins are the shared fur technique
(``techniques/fur.py``); what is Revie's here is how the fur is lit.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from pydantic import Field

from deferred.api import (
    ALBEDO_SPECULAR,
    COMPOSITE,
    LIGHT_ACCUMULATION,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    Albedo,
    BlinnPhongParams,
    ForwardLitPass,
    GBufferPass,
    NonZeroVec3,
    Phase,
    RenderPass,
    materials,
)

from ..techniques.comb_field import comb_field, comb_field_texture
from ..techniques.fins import FinPass
from ..techniques.fur import (
    FUR_DEBUG_VIEWS,
    FUR_UNIFORM_OVERRIDES,
    FurMaterial,
    FurParams,
    debug_defines,
)
from ..techniques.shells import DitheredShells, ShellPass
from ..techniques.stipple import (
    StippleObliterationPass,
    StipplePass,
    pattern_defines,
    stipple_scene_passes,
)

if TYPE_CHECKING:
    import moderngl

    from deferred.api import Frame, SceneObject

FUR_VERTEX = "materials/revie_fur/fur.vert"
SHELL_FRAGMENT = "materials/revie_fur/shell.frag"
FORWARD_SHELL_FRAGMENT = "materials/revie_fur/forward_shell.frag"
STIPPLE_PARITY = (0, 0)  # the (even, even) pixel of each 2x2 tile, as Listing 2.6


class RevieFurParams(FurParams, BlinnPhongParams):
    albedo_base: Albedo = Field((0.10, 0.06, 0.035), description="albedo at the strand roots")
    albedo_tip: Albedo = Field((0.78, 0.58, 0.38), description="albedo at the tips (surface)")
    specular_intensity: float = Field(0.25, ge=0.0, le=1.0, description="Blinn-Phong intensity")
    specular_exponent: float = Field(24.0, ge=1.0, le=2048.0, description="Blinn-Phong exponent")
    rim_strength: float = Field(1.5, ge=0.0, le=16.0,
                                description="silhouette normal bending (0 turns it off)")
    rim_falloff: float = Field(3.0, gt=0.0, le=64.0, description="exponent of 1 - N.V")
    anisotropic: bool = Field(True, description="grain normals (highlights across the grain)")
    stipple: bool = Field(True, description="stippled outer shell (rim light, occlusion fix)")
    comb: NonZeroVec3 = Field((0.0, -1.0, 0.0),
                              description="object-space comb where the mesh has no vertex colours")
    comb_strength: float = Field(0.6, ge=0.0, le=8.0, description="how far strands lean")
    occlusion_test: bool = Field(True, description="reject light samples the G-buffer shows "
                                                   "occluded (off: Figure 2.8's error)")
    shading: Literal["classic", "marschner"] = Field(
        "classic", description="classic: the paper's grain normals and rim bending, lit "
                               "Blinn-Phong; marschner: the hair shading model (R, TT, TRT "
                               "about the strand direction; no grain normal, no rim bending)")
    roughness: float = Field(0.2, gt=0.0, le=1.0,
                             description="marschner: longitudinal roughness beta, radians")


class CombFieldInputs:
    """Passes of a revie_fur object: ``u_comb_field``, the object's comb field
    (``techniques/comb_field.py``) from its mesh's vertex colours or its ``comb``, made when
    either changes."""

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        return {**super().textures(frame), **comb_field_inputs(frame, self.object(frame))}


def comb_field_inputs(frame: Frame, obj: SceneObject) -> dict[str, moderngl.Texture]:
    """``u_comb_field`` of a revie_fur object (:class:`CombFieldInputs`)."""
    mesh, params = obj.mesh, obj.material.params
    comb = None if mesh.has_comb else tuple(params.comb)
    texture = frame.resources.current(
        ("revie_fur_comb_field", obj.node), (id(mesh), comb),
        lambda ctx: comb_field_texture(ctx, comb_field(mesh, comb)))
    return {"u_comb_field": texture}


class CombedGBufferPass(CombFieldInputs, GBufferPass):
    pass


class CombedStipplePass(CombFieldInputs, StipplePass):
    pass


class CombedObliterationPass(CombFieldInputs, StippleObliterationPass):
    pass


class CombedFinPass(CombFieldInputs, FinPass):
    pass


class CombedShellPass(CombFieldInputs, DitheredShells, ShellPass):
    pass


class CombedForwardPass(CombFieldInputs, ForwardLitPass):
    pass


# Options of the shell and fin passes: in the material phase both take their light from the
# light accumulation and the G-buffer (shell.frag); in the forward phase they light themselves.
MATERIAL_LAYERS: dict[str, Any] = {
    "vertex": FUR_VERTEX, "fragment": SHELL_FRAGMENT, "colors": (COMPOSITE,),
    "extra_reads": (LIGHT_ACCUMULATION, ALBEDO_SPECULAR, NORMAL_EXPONENT_ID, LINEAR_DEPTH)}
FORWARD_LAYERS: dict[str, Any] = {
    "vertex": FUR_VERTEX, "fragment": FORWARD_SHELL_FRAGMENT, "colors": (COMPOSITE,)}


@materials.register
class RevieFurMaterial(FurMaterial):
    name = "revie_fur"
    Params = RevieFurParams
    surface_shader = "materials/revie_fur/surface.glsl"
    inputs_from_params = True  # uniforms from the params, textures from frame.resources
    # pass counts and switches compiled as defines are not uniforms; density becomes tiles
    uniform_overrides = {**FUR_UNIFORM_OVERRIDES, "stipple": None, "occlusion_test": None,
                         "shading": None,
                         "comb": None}  # the comb field's texture instead (CombFieldInputs)
    timeline_fixed = ("shading",)  # the shading model, and so the G-buffer layout

    def __init__(self, params: RevieFurParams | None = None, base_dir: Path | None = None):
        super().__init__(params, base_dir)
        self.shading_model = "marschner" if self.params.shading == "marschner" else "blinn_phong"

    debug_views = FUR_DEBUG_VIEWS
    fur_vertex = FUR_VERTEX
    deferred_opacity = True  # its shells correct their samples' light light by light (shell.frag)

    def shadow_textures(self, frame: Frame, obj: SceneObject) -> dict[str, moderngl.Texture]:
        return comb_field_inputs(frame, obj)

    def defines(self, obj: SceneObject) -> dict[str, str]:
        defines = {**super().defines(obj), **pattern_defines(4, STIPPLE_PARITY)}
        if self.params.stipple:
            defines["FUR_STIPPLE"] = "1"
        if self.params.occlusion_test:
            defines["FUR_OCCLUSION_TEST"] = "1"
        if self.params.shading == "marschner":
            defines["FUR_MARSCHNER"] = "1"
        return {**defines, **debug_defines(self.params)}

    # -- passes ------------------------------------------------------------------------------
    @classmethod
    def scene_passes(cls, objects: list[SceneObject], phase: Phase) -> list[RenderPass]:
        stippled = any(obj.material.params.stipple for obj in objects)
        return stipple_scene_passes(phase) if stippled else []

    def geometry_passes(self, obj: SceneObject) -> list[RenderPass]:
        return [CombedGBufferPass(f"{obj.label}.gbuffer", Phase.GEOMETRY, obj, vertex=FUR_VERTEX,
                            constants=self.vertex_constants(obj, 0.0))]

    def stipple_passes(self, obj: SceneObject) -> list[RenderPass]:
        if not self.params.stipple:
            return []
        return [CombedStipplePass(f"{obj.label}.stipple", Phase.STIPPLE, obj, vertex=FUR_VERTEX,
                            fragment="materials/revie_fur/stipple.frag",
                            constants=self.vertex_constants(obj, 1.0))]

    def material_passes(self, obj: SceneObject) -> list[RenderPass]:
        passes: list[RenderPass] = []
        if self.params.stipple:
            passes.append(CombedObliterationPass(f"{obj.label}.stipple_obliteration",
                                                  Phase.MATERIAL, obj, vertex=FUR_VERTEX,
                                                  constants=self.vertex_constants(obj, 1.0)))
        if self.params.shells > 0:
            # fins first: the shells composite over them, which fill the gaps between shell
            # rims at grazing angles
            if self.params.fins:
                passes.append(CombedFinPass(f"{obj.label}.fins", Phase.MATERIAL, obj,
                                      constants=self.vertex_constants(obj), **MATERIAL_LAYERS))
            passes.append(CombedShellPass(f"{obj.label}.shells", Phase.MATERIAL, obj,
                                    constants=self.vertex_constants(obj), **MATERIAL_LAYERS))
        return passes

    def forward_passes(self, obj: SceneObject) -> list[RenderPass]:
        passes: list[RenderPass] = [CombedForwardPass(f"{obj.label}.forward", Phase.FORWARD, obj,
                                                   vertex=FUR_VERTEX,
                                                   constants=self.vertex_constants(obj, 0.0))]
        if self.params.shells > 0:
            if self.params.fins:
                passes.append(CombedFinPass(f"{obj.label}.forward_fins", Phase.FORWARD, obj,
                                      constants=self.vertex_constants(obj), **FORWARD_LAYERS))
            passes.append(CombedShellPass(f"{obj.label}.forward_shells", Phase.FORWARD, obj,
                                    constants=self.vertex_constants(obj), **FORWARD_LAYERS))
        return passes
