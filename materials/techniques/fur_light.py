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
"""

from __future__ import annotations

from typing import Any

from deferred.gbuffer import ALBEDO_SPECULAR, LINEAR_DEPTH, NORMAL_EXPONENT_ID
from deferred.passes import FullscreenPass, Order, Phase
from deferred.targets import LIGHT_ACCUMULATION
from deferred.targets_spec import TargetSpec

FUR_LIGHT_FRAGMENT = "techniques/fur_light.frag"


def fur_light_spec(surface: str) -> TargetSpec:
    return TargetSpec(4, "f4", f"{surface} fur: irradiance of the fur at each pixel or its "
                               "nearest neighbour holding it, and that pixel's linear depth "
                               "(< 0: a neighbour's; 0: none)", clear=None)


def fur_light_sampler(textures: dict[str, Any], target: str) -> dict[str, Any]:
    """A pass's samplers with its ``target`` (``u_<target>``, the pass reads it) bound as
    ``techniques/fur_light.glsl``'s ``u_fur_light``."""
    textures = dict(textures)
    textures["u_fur_light"] = textures.pop(f"u_{target}")
    return textures


def fur_light_pass(name: str, target: str, surface_id: int, surface: str,
                   defines: dict[str, str] | None = None) -> FullscreenPass:
    """The material-phase pass that fills ``target`` for the material of ``surface_id`` (its
    G-buffer id); ``defines``: FUR_STIPPLE and its pattern where stipple samples are skipped.
    It runs before every object's passes (``Order.FIRST``): the layers read it."""
    return FullscreenPass(
        name, Phase.MATERIAL, FUR_LIGHT_FRAGMENT,
        {"u_light_accumulation": LIGHT_ACCUMULATION, "u_albedo_specular": ALBEDO_SPECULAR,
         "u_normal_exponent_id": NORMAL_EXPONENT_ID, "u_linear_depth": LINEAR_DEPTH},
        (target,), defines={"FUR_OCCLUSION_TEST": "1", **(defines or {})},
        uniforms=lambda frame: {"u_surface_id": float(surface_id)},
        creates={target: fur_light_spec(surface)}, order=Order.FIRST)
