"""Screen-door transparency in a deferred pipeline (Revie 2.3.4, Figure 2.14).

The glass is written into the G-buffer at one pixel in two or four (``pattern``), so the pixels
between keep the scene behind it; both are lit by the lighting phase as usual. In the material
phase the glass's stipple samples are obliterated with the rest of the opaque scene, and later,
with the transparent passes (far to near), each glass pixel blends its tile's glass sample by
``opacity`` over whatever the composition buffer holds. The forward technique is an ordinary
alpha-blended lit pass.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

from pydantic import Field

from deferred.api import (
    COMPOSITE,
    LIGHT_ACCUMULATION,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    Albedo,
    BlinnPhongParams,
    Material,
    ObjectPass,
    Order,
    Phase,
    PhasePasses,
    RenderPass,
    materials,
)

from ..techniques.stipple import Stipple, pattern_defines

if TYPE_CHECKING:
    from deferred.api import SceneObject


class StippleGlassParams(BlinnPhongParams):
    color: Albedo = Field((0.55, 0.75, 0.85), description="glass tint, each in [0, 1]")
    opacity: float = Field(0.35, ge=0.0, le=1.0, description="glass over the scene behind")
    pattern: Literal[2, 4] = Field(4, description="stipple density: 1 in 2 or 1 in 4 pixels")
    specular_intensity: float = Field(0.9, ge=0.0, le=1.0, description="Blinn-Phong intensity")
    specular_exponent: float = Field(96.0, ge=1.0, le=2048.0, description="Blinn-Phong exponent")


class DeinterlacePass(ObjectPass):
    """Blend each glass pixel's tile sample over the composition buffer."""

    fragment = "materials/stipple_glass/deinterlace.frag"
    colors = (COMPOSITE,)
    depth_func = "lequal"
    depth_write = False
    blend = "alpha"
    order = Order.TRANSPARENT
    extra_reads = (LIGHT_ACCUMULATION, NORMAL_EXPONENT_ID, LINEAR_DEPTH)


def deinterlace_pass(material: Material, obj: SceneObject) -> list[RenderPass]:
    return [DeinterlacePass(f"{obj.label}.deinterlace", Phase.MATERIAL, obj)]


def forward_pass(material: Material, obj: SceneObject) -> list[RenderPass]:
    """The forward technique: an alpha-blended lit pass."""
    return [ObjectPass(f"{obj.label}.forward", Phase.FORWARD, obj,
                       fragment="materials/stipple_glass/forward.frag", colors=(COMPOSITE,),
                       depth_write=False, blend="alpha", order=Order.TRANSPARENT)]


@materials.register
class StippleGlassMaterial(Material):
    name = "stipple_glass"
    Params = StippleGlassParams
    surface_shader = "materials/stipple_glass/surface.glsl"
    uniform_overrides = {"pattern": None}  # a define (STIPPLE_PATTERN)
    # transparent: nothing in the opaque G-buffer phase; stippled instead, its samples
    # obliterated with the opaque scene and blended back over it with the transparent passes
    techniques = (Stipple("materials/stipple_glass/stipple.frag"),
                  PhasePasses(Phase.MATERIAL, deinterlace_pass),
                  PhasePasses(Phase.FORWARD, forward_pass))

    def defines(self, obj: SceneObject) -> dict[str, str]:
        # the other parity classes than fur's (0, 0), so glass and fur samples coexist
        parity = (1, 1) if self.params.pattern == 4 else (1, 0)
        return {**super().defines(obj), **pattern_defines(self.params.pattern, parity)}
