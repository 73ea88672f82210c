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
    NonZeroVec3,
    PassInput,
    Phase,
    RenderPass,
    SurfacePasses,
    Technique,
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
    vertex_constants,
)
from ..techniques.fur_shadow import FurShadow
from ..techniques.shells import ShellPass
from ..techniques.stipple import Stipple, pattern_defines

if TYPE_CHECKING:
    import moderngl

    from deferred.api import Frame, Material, SceneObject

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


class CombField(PassInput):
    """``u_comb_field``, a revie_fur object's comb field (``techniques/comb_field.py``) from its
    mesh's vertex colours or its ``comb``, made when either changes: an input of every pass of
    the object and of its shadow caster."""

    def textures(self, frame: Frame, obj: SceneObject) -> dict[str, moderngl.Texture]:
        mesh, params = obj.mesh, obj.material.params
        comb = None if mesh.has_comb else tuple(params.comb)
        texture = frame.resources.current(
            ("revie_fur_comb_field", obj.node), (id(mesh), comb),
            lambda ctx: comb_field_texture(ctx, comb_field(mesh, comb)))
        return {"u_comb_field": texture}


COMB_FIELD = CombField()


# Options of the shell and fin passes: in the material phase both take their light from the
# light accumulation and the G-buffer (shell.frag); in the forward phase they light themselves.
MATERIAL_LAYERS: dict[str, Any] = {
    "vertex": FUR_VERTEX, "fragment": SHELL_FRAGMENT, "colors": (COMPOSITE,),
    "extra_reads": (LIGHT_ACCUMULATION, ALBEDO_SPECULAR, NORMAL_EXPONENT_ID, LINEAR_DEPTH)}
FORWARD_LAYERS: dict[str, Any] = {
    "vertex": FUR_VERTEX, "fragment": FORWARD_SHELL_FRAGMENT, "colors": (COMPOSITE,)}


class FurLayers(Technique):
    """The fins and shells over the stipple obliteration: in the material phase lit from the
    light accumulation, in the forward pipeline by themselves; fins first, the shells
    composite over them, which fill the gaps between shell rims at grazing angles."""

    def passes(self, material: Material, phase: Phase, obj: SceneObject) -> list[RenderPass]:
        params = material.params
        if phase not in (Phase.MATERIAL, Phase.FORWARD) or params.shells == 0:
            return []
        layers, prefix = (MATERIAL_LAYERS, "") if phase == Phase.MATERIAL else \
            (FORWARD_LAYERS, "forward_")
        constants = vertex_constants(obj)
        passes: list[RenderPass] = []
        if params.fins:
            passes.append(FinPass(f"{obj.label}.{prefix}fins", phase, obj, inputs=(COMB_FIELD,),
                                  constants=constants, **layers))
        passes.append(ShellPass(f"{obj.label}.{prefix}shells", phase, obj, dither=True,
                                inputs=(COMB_FIELD,), constants=constants, **layers))
        return passes


@materials.register
class RevieFurMaterial(FurMaterial):
    name = "revie_fur"
    Params = RevieFurParams
    surface_shader = "materials/revie_fur/surface.glsl"
    inputs_from_params = True  # uniforms from the params, textures from frame.resources
    # pass counts and switches compiled as defines are not uniforms; density becomes tiles
    uniform_overrides = {**FUR_UNIFORM_OVERRIDES, "stipple": None, "occlusion_test": None,
                         "shading": None,
                         "comb": None}  # the comb field's texture instead (CombField)
    timeline_fixed = ("shading",)  # the shading model, and so the G-buffer layout
    debug_views = FUR_DEBUG_VIEWS
    # the base mesh (grain normals) and its forward twin, the stippled outer shell and its
    # obliteration (rim-bent normals), then the fins and shells; every pass reads the comb
    techniques = (
        SurfacePasses(vertex=FUR_VERTEX, inputs=(COMB_FIELD,),
                      constants=lambda obj: vertex_constants(obj, 0.0)),
        Stipple("materials/revie_fur/stipple.frag", vertex=FUR_VERTEX, inputs=(COMB_FIELD,),
                constants=lambda obj: vertex_constants(obj, 1.0),
                when=lambda material: material.params.stipple),
        FurLayers())
    shadow = FurShadow(FUR_VERTEX, inputs=(COMB_FIELD,))

    def __init__(self, params: RevieFurParams | None = None, base_dir: Path | None = None):
        super().__init__(params, base_dir)
        self.shading_model = "marschner" if self.params.shading == "marschner" else "blinn_phong"

    def defines(self, obj: SceneObject) -> dict[str, str]:
        defines = {**super().defines(obj), **pattern_defines(4, STIPPLE_PARITY)}
        if self.params.stipple:
            defines["FUR_STIPPLE"] = "1"
        if self.params.occlusion_test:
            defines["FUR_OCCLUSION_TEST"] = "1"
        if self.params.shading == "marschner":
            defines["FUR_MARSCHNER"] = "1"
        return {**defines, **debug_defines(self.params)}
