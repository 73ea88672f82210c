"""The fur's light, gathered once per frame (Revie 2.4.4, Listing 2.2, done per pixel instead of
per shell fragment).

A fur layer fragment takes the light of the base-mesh point under it from the light
accumulation, divided by the G-buffer albedo; where the G-buffer shows another surface there,
the first of the 8 neighbours that holds the fur (``techniques/accumulated_light.glsl``). Done
by every fragment of every layer, that search is most of a layer's cost on a CPU rasteriser:
up to 9 pixels of 4 G-buffer reads each, and a SIMD rasteriser runs both sides of every branch.
This scene pass does it once per pixel: ``fur_light`` holds, per pixel, the irradiance of the
fur there, or of the first neighbour holding it, with the linear depth of the pixel it came
from (negated for a neighbour's; 0: none), so a layer fragment reads one texel and checks the
depth itself (``techniques/fur_light.glsl``).

The search checked each candidate's depth against the layer's expected depth and took the first
that passed; the gather can only check the first holding the fur. Where the surface's depth
changes fast from pixel to pixel (silhouettes) a fragment then falls back to its own pixel more
often. On shell_fur's long fur that changes 30 of 480,000 pixels of Table 1's frame; on
revie_fur's short stippled fur it left a dotted rim (1.2% of the pixels of Figure 2.5 off by
more than 16/255), so revie_fur keeps the search.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import moderngl

from deferred.gbuffer import ALBEDO_SPECULAR, LINEAR_DEPTH, NORMAL_EXPONENT_ID
from deferred.passes import FullscreenPass, Order, Phase
from deferred.targets import LIGHT_ACCUMULATION
from deferred.targets_spec import TargetSpec

if TYPE_CHECKING:
    from deferred.frame import Frame

FUR_LIGHT_FRAGMENT = "techniques/fur_light.frag"


def fur_light_spec(surface: str) -> TargetSpec:
    return TargetSpec(4, "f4", f"{surface} fur: irradiance of the fur at each pixel or its "
                               "nearest neighbour holding it, and that pixel's linear depth "
                               "(< 0: a neighbour's; 0: none)", clear=None)


class FurLightReader:
    """Mixin for an ``ObjectPass`` whose shader reads a fur_light target through
    ``techniques/fur_light.glsl``: give the target as ``fur_light`` and among ``extra_reads``
    (the pass graph orders the passes by it); it is bound as ``u_fur_light``."""

    fur_light: str | None = None

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        textures = super().textures(frame)  # type: ignore[misc]
        if self.fur_light is not None:
            textures = dict(textures)
            textures["u_fur_light"] = textures.pop(f"u_{self.fur_light}")
        return textures


def fur_light_pass(name: str, target: str, surface_id: int, surface: str) -> FullscreenPass:
    """The material-phase pass that fills ``target`` for the material of ``surface_id`` (its
    G-buffer id). It runs before every object's passes (``Order.FIRST``): the layers read it."""
    return FullscreenPass(
        name, Phase.MATERIAL, FUR_LIGHT_FRAGMENT,
        {"u_light_accumulation": LIGHT_ACCUMULATION, "u_albedo_specular": ALBEDO_SPECULAR,
         "u_normal_exponent_id": NORMAL_EXPONENT_ID, "u_linear_depth": LINEAR_DEPTH},
        (target,), defines={"FUR_OCCLUSION_TEST": "1"},
        uniforms=lambda frame: {"u_surface_id": float(surface_id)},
        creates={target: fur_light_spec(surface)}, order=Order.FIRST)
