"""Coloured shadows of transparent casters: transmittance maps beside the depth atlas.

A caster that lets light through (``ShadowCaster.transmits``: glass) draws no depth into the
atlas; it draws into two maps over the atlas's square its lights' maps take (from its corner,
:func:`~deferred.lighting.shadows.opacity.opacity_extent`), texel for texel with the atlas:
``shadow_transmittance`` (RGBA8), the product of the transmittances of the transparent surfaces
each texel sees (multiplied in, cleared to 1), and ``shadow_transparent_depth`` (R32F), the
depth of the nearest of them (min blending, cleared to 1: the far plane). A receiver beyond
that depth along the light takes the colour (``lighting/shadows.glsl``,
``SHADOW_TRANSMITTANCE``): filtered bilinearly, each texel's colour where the receiver lies
beyond its nearest transparent caster and white where not, so a transparent surface does not
tint itself. The depth maps' lit fraction multiplies it: what lies beyond an opaque caster is
dark whatever the colour, so the transparent casters need no test against the opaque ones.
Where several transparent surfaces stack along a light, a receiver between them takes the
product of them all (one depth is kept a texel).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from deferred.lighting.shadows.plan import scene_casts_shadows

if TYPE_CHECKING:
    from deferred.scene.scene import Scene

TRANSMITTANCE_DEFINE = "SHADOW_TRANSMITTANCE"
TRANSMITTANCE_BYTES = 8  # a texel: RGBA8 transmittance and R32F depth
# the transmittance map's outputs: multiplied in, and the nearest depth kept
TRANSMITTANCE_BLEND = ("multiply", "min")


def scene_has_transparent_casters(scene: Scene) -> bool:
    """Whether a shadowed scene draws transmittance maps: an object's caster lets light
    through (``ShadowCaster.transmits``)."""
    return scene_casts_shadows(scene.lights) and any(
        obj.material.shadow.transmits(obj) for obj in scene.objects)
