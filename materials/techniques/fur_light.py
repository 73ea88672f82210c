"""The fur's light, gathered once per frame (Revie 2.4.4, Listing 2.2, done per pixel instead of
per layer fragment).

A fur layer fragment takes the light of the base-mesh point under it from the light
accumulation, divided by the G-buffer albedo: the first of that pixel and its 8 neighbours that
holds the fur at the expected depth (``materials/techniques/accumulated_light.glsl``'s search).
Done by
every fragment of every layer, the search was half a layer's cost on a CPU rasteriser (up to 9
pixels of 4 G-buffer reads each; a SIMD rasteriser runs every branch). This scene pass does
the part that does not depend on the layer once per pixel, into two targets:

- ``<target>``: the irradiance of the fur at the pixel, else of the first neighbour holding it,
  and where it came from (alpha 1: the pixel itself, -1: a neighbour, 0: none);
- ``<target>_depths``: the least and greatest linear depth of the fur over the 3x3 pixels.

A layer fragment (``materials/techniques/fur_light.glsl``) reads both texels at its base pixel and
takes the light where the expected depth lies within the depth range, widened by its tolerance. That
accepts every fragment the search accepted; it also accepts one whose expected depth falls
between two parts of the fur seen in the 3x3 pixels (along an edge where the fur occludes
itself), with the first pixel's light, where the search took the light of the pixel at the right
depth. revie_fur keeps the search: its last resort reads a stipple sample's own light, which
this gather does not hold, and a first version of it (the first pixel's depth only) left a
dotted rim on its short fur.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import moderngl

from deferred.api import (
    ALBEDO_SPECULAR,
    LIGHT_ACCUMULATION,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    FullscreenPass,
    Order,
    PassInput,
    Phase,
    TargetSpec,
)

if TYPE_CHECKING:
    from deferred.api import Frame, SceneObject

FUR_LIGHT_FRAGMENT = "materials/techniques/fur_light.frag"


def fur_light_targets(target: str) -> tuple[str, str]:
    """The two targets of a fur_light gather named ``target`` (what its readers read)."""
    return target, f"{target}_depths"


class FurLight(PassInput):
    """What an ``ObjectPass`` whose shader reads a fur_light gather through
    ``materials/techniques/fur_light.glsl`` takes as one of its ``inputs``: the gather's
    targets (:func:`fur_light_targets` of ``target``; the pass graph orders the pass after the
    gather) as ``u_fur_light`` and ``u_fur_light_depths``."""

    def __init__(self, target: str):
        self.target = target
        self.reads = fur_light_targets(target)

    def textures(self, frame: Frame, obj: SceneObject) -> dict[str, moderngl.Texture]:
        light, depths = self.reads
        return {"u_fur_light": frame.target(light), "u_fur_light_depths": frame.target(depths)}


def fur_light_pass(name: str, target: str, surface_id: int, material: str) -> FullscreenPass:
    """The material-phase pass that fills ``target``'s two targets for the material named
    ``material`` (G-buffer id ``surface_id``). It runs before every object's passes
    (``Order.FIRST``): the layers read it."""
    light, depths = fur_light_targets(target)
    return FullscreenPass(
        name, Phase.MATERIAL, FUR_LIGHT_FRAGMENT,
        {"u_light_accumulation": LIGHT_ACCUMULATION, "u_albedo_specular": ALBEDO_SPECULAR,
         "u_normal_exponent_id": NORMAL_EXPONENT_ID, "u_linear_depth": LINEAR_DEPTH},
        (light, depths),
        uniforms=lambda frame: {"u_surface_id": float(surface_id)},
        creates={light: TargetSpec(4, "f4", f"{material} fur: irradiance at each pixel, or "
                                            "at its first neighbour holding the fur (alpha "
                                            "1 / -1; 0: none)"),
                 depths: TargetSpec(2, "f4", f"{material} fur: least and greatest linear "
                                             "depth of the fur over the 3x3 pixels")},
        order=Order.FIRST)
