"""The subsurface material (skin, wax, marble): light scattered under the surface by a
separable screen-space blur of the diffuse light alone (Jimenez et al. 2015), with the profile
of Burley's normalized diffusion from the material's mean free path (``radius``, world units,
per channel times ``falloff``), the highlight left sharp (the ``subsurface`` shading model
splits its light), and light through thin parts from the lights' shadow maps (Jimenez et al.
2010). Each object's profile is a row of the scene's profile table
(``deferred.materials.shading_models.subsurface_rows``), its row in the G-buffer datum
``subsurface_profile``.

Both pipelines: deferred, the lighting writes the diffuse light apart and two full-screen
passes at the end of the lighting phase blur it across and then down, adding the blurred light
less the unblurred into the light accumulation; forward, the material's lit pass writes its
diffuse light beside the colour, a second pass over its own pixels (depth "equal", after every
opaque surface) marks where it is seen, and the same two passes blur it into the composition.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from pydantic import Field

from deferred.api import (
    COMPOSITE,
    DIFFUSE_LIGHT,
    LIGHT_ACCUMULATION,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    Albedo,
    BlinnPhongParams,
    ClearPass,
    ForwardLitPass,
    FullscreenPass,
    Material,
    ObjectPass,
    Order,
    Per,
    Phase,
    RenderWork,
    SurfacePasses,
    TargetSpec,
    Technique,
    Work,
    WorkObject,
    counted,
    materials,
    shading_models,
)

from ..shading_models import subsurface_rows
from ..techniques.subsurface_profile import TAPS, profile_shape

if TYPE_CHECKING:
    from deferred.api import Frame

BLUR = "subsurface_blur"  # the diffuse light blurred across
SURFACE = "subsurface_surface"  # forward: (view depth, profile row + 1) where it is seen
DATUM = "subsurface_profile"  # the G-buffer datum of the profile's row
# seconds a pixel of the material's takes each of the blur's two passes (TAPS taps, each
# reading the light and where it falls): measured on the reference machine, benchmarks/README.md
# ("Area lights and subsurface scattering")
BLUR_PIXEL_SECONDS = 1.5e-6
SHAPE_FLOOR = 1e-7  # world units: the profile's narrowest shape d, its rounding's step


class SubsurfaceParams(BlinnPhongParams):
    color: Albedo = Field((0.85, 0.62, 0.5), description="diffuse albedo: the colour light "
                          "leaves with after scattering")
    radius: float = Field(0.05, gt=0.0, le=100.0, description="the profile's mean free path, "
                          "world units: how far light travels under the surface")
    falloff: Albedo = Field((1.0, 0.45, 0.3), description="the mean free path of each channel "
                            "as a fraction of radius (skin: red goes farthest)")
    transmission: float = Field(1.0, ge=0.0, le=8.0, description="light through thin parts "
                                "from shadowed lights behind them (0: none)")
    specular_intensity: float = Field(0.3, ge=0.0, le=1.0, description="Blinn-Phong intensity")
    specular_exponent: float = Field(40.0, ge=1.0, le=2048.0,
                                     description="Blinn-Phong exponent")


class SubsurfaceForwardPass(ForwardLitPass):
    """The lit pass writing the diffuse light beside the colour (forward)."""

    fragment = "materials/subsurface/forward.frag"
    colors = (COMPOSITE, DIFFUSE_LIGHT)


def blur_passes(phase: Phase, order: int, forward: bool) -> list[FullscreenPass]:
    """The blur across (into ``subsurface_blur``), then down (added into the light
    accumulation, or forward's composition, as the blurred light less the unblurred)."""
    where = {"u_subsurface_surface": SURFACE} if forward else {
        "u_linear_depth": LINEAR_DEPTH, "u_normal_exponent_id": NORMAL_EXPONENT_ID,
        "u_subsurface_profile": DATUM}
    defines = {"SUBSURFACE_TAPS": str(TAPS), **({"FORWARD_SUBSURFACE": "1"} if forward else {})}

    def uniforms(direction):
        def make(frame: Frame) -> dict[str, Any]:
            model = shading_models.get("subsurface").type_id
            return {"u_direction": direction, **({} if forward else
                                                 {"u_subsurface_model": model})}
        return make

    across = FullscreenPass(f"{phase.value}.subsurface_blur_x", phase,
                            "materials/subsurface/blur.frag", {"u_source": DIFFUSE_LIGHT, **where},
                            (BLUR,), defines=defines, uniforms=uniforms((1.0, 0.0)),
                            creates={BLUR: TargetSpec.from_format(
                                "RGBA16F", "the diffuse light blurred across",
                                clear=(0.0, 0.0, 0.0, 0.0))},
                            order=order)
    down = FullscreenPass(f"{phase.value}.subsurface_blur_y", phase,
                          "materials/subsurface/blur.frag",
                          {"u_source": BLUR, "u_diffuse_light": DIFFUSE_LIGHT, **where},
                          (COMPOSITE if forward else LIGHT_ACCUMULATION,), blend="add",
                          defines={**defines, "BLUR_ADD": "1"}, uniforms=uniforms((0.0, 1.0)),
                          order=order + 1)
    return [across, down]


def mask_pass(material, obj) -> ObjectPass:
    """Forward: the object's seen pixels (depth "equal", after every opaque surface)."""
    return ObjectPass(f"{obj.label}.subsurface_mask", Phase.FORWARD, obj,
                      fragment="materials/subsurface/mask.frag", colors=(SURFACE,),
                      depth_func="equal", depth_write=False, order=Order.OPAQUE + 1)


class SubsurfaceScattering(Technique):
    """The blur's passes (once a scene) and forward's mask (an object)."""

    def passes(self, material, phase: Phase, obj) -> list:
        return [mask_pass(material, obj)] if phase == Phase.FORWARD else []

    def scene_passes(self, objects, phase: Phase) -> list:
        if phase == Phase.LIGHTING:
            return blur_passes(Phase.LIGHTING, Order.LAST - 1, forward=False)
        if phase == Phase.FORWARD:
            clear = ClearPass("forward.subsurface_clear", Phase.FORWARD, {
                DIFFUSE_LIGHT: TargetSpec.from_format(
                    "RGBA16F", "the diffuse light of the subsurface surfaces",
                    clear=(0.0, 0.0, 0.0, 0.0)),
                SURFACE: TargetSpec.from_format(
                    "RG32F", "where a subsurface surface is seen: its view depth, its profile "
                    "row + 1", clear=(0.0, 0.0, 0.0, 0.0))})
            return [clear, *blur_passes(Phase.FORWARD, Order.OPAQUE + 2, forward=True)]
        return []


@materials.register
class SubsurfaceMaterial(Material):
    name = "subsurface"
    Params = SubsurfaceParams
    surface_shader = "materials/subsurface/surface.glsl"
    shading_model = "subsurface"
    techniques = (SurfacePasses(forward=SubsurfaceForwardPass), SubsurfaceScattering())
    uniform_overrides = {"radius": None, "falloff": None, "transmission": None}

    def work(self, obj: WorkObject, job: RenderWork) -> list[Work]:
        """Its mesh (forward: drawn again by the mask pass), and the blur's two passes over the
        pixels it covers, once its bounds are known."""
        works = [obj.surface_work(2.0 if job.pipeline == "forward" else 1.0)]
        pixels = obj.covered_pixels(job)
        if pixels is not None:
            works.append(Work(f"{obj.label}: the subsurface blur over {counted(pixels)} pixels",
                              2.0 * pixels, BLUR_PIXEL_SECONDS, obj.key("radius"), Per.SAMPLE))
        return works

    def subsurface_profile(self) -> tuple:
        """(the profile's shape d per channel, the transmission's strength): a row of the
        scene's profile table."""
        params = self.params
        path = [params.radius * f for f in params.falloff]
        # rounded so that equal profiles share a row; never 0 (a radius or falloff too small
        # to round above it scatters nowhere, where 0 would divide by zero)
        shape = tuple(max(round(float(d), 7), SHAPE_FLOOR)
                      for d in profile_shape(path, params.color))
        return shape, float(params.transmission)

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        row = subsurface_rows(frame.scene).index(self.subsurface_profile())
        return {**super().uniforms(frame), "u_subsurface_row": float(row)}
