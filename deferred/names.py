"""Names that several layers use, defined once: the pipelines, the light paths each runs, and
how a light type is bounded. Each is a string enum: a member equals its name as a string (what a
user types, what a scene file holds) and prints as it (in messages, JSON and f-strings).
(The phases of a frame are :class:`deferred.core.passes.Phase`.)
"""

from __future__ import annotations

from enum import Enum


class NameEnum(str, Enum):
    """A string enum whose members print as their value."""

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)


class Pipeline(NameEnum):
    """The two pipelines (``--pipeline``): G-buffer then lights, or one lit pass per object."""

    DEFERRED = "deferred"
    FORWARD = "forward"


class LightPath(NameEnum):
    """How lights reach the pixels (``--light-path``; ``deferred.lighting``)."""

    VOLUMES = "volumes"  # deferred: an instanced pass per light type, spheres for local lights
    TILED = "tiled"  # deferred tiled shading / Forward+: lists per screen tile (compute)
    CLUSTERED = "clustered"  # deferred: lists per tile and depth slice (compute)
    NAIVE = "naive"  # forward: every light looped per fragment


# each pipeline's light paths, in the order the bench runs them
LIGHT_PATHS: dict[Pipeline, tuple[LightPath, ...]] = {
    Pipeline.DEFERRED: (LightPath.VOLUMES, LightPath.TILED, LightPath.CLUSTERED),
    Pipeline.FORWARD: (LightPath.NAIVE, LightPath.TILED),
}
# the paths that cull lights into lists with compute shaders (GL 4.3)
LIST_PATHS = (LightPath.TILED, LightPath.CLUSTERED)
# the scene's `background` that shows its environment light's map instead of a colour
ENVIRONMENT_BACKGROUND = "environment"
# a path named for one pipeline, asked of the other: what that one runs instead
EQUIVALENT_PATHS: dict[Pipeline, dict[LightPath, LightPath]] = {
    Pipeline.DEFERRED: {LightPath.NAIVE: LightPath.VOLUMES},
    Pipeline.FORWARD: {LightPath.VOLUMES: LightPath.NAIVE, LightPath.CLUSTERED: LightPath.TILED},
}


class LightVolume(NameEnum):
    """How the deferred lighting bounds a light type (``Light.volume``)."""

    FULLSCREEN = "fullscreen"  # every pixel (directional, ambient)
    SPHERE = "sphere"  # the record's position.xyz and radius position.w (point, spot)


class ShadowProjection(NameEnum):
    """How a light type's shadow maps see the scene (``Light.shadow_projection``;
    ``deferred.lighting.shadows``)."""

    CASCADES = "cascades"  # directional: orthographic cascades over the camera's depth range
    PERSPECTIVE = "perspective"  # spot: one perspective map along the cone's axis
    CUBE = "cube"  # point: six 90-degree perspective tiles of the atlas


class ShadowAllocation(NameEnum):
    """How the shadow atlas sizes a light's maps (``[shadows] allocation``)."""

    FIXED = "fixed"  # each map of its light's shadow_resolution
    COVERAGE = "coverage"  # by the screen its light's shadowed region covers, at most that


class ShadowFilter(NameEnum):
    """A shadow map's filter (``shadow_filter``)."""

    PCF = "pcf"  # 3x3 bilinear hardware comparisons (4x4 texels)
    SOFT = "soft"  # a 16-tap Poisson disk of radius ``shadow_softness`` texels
    PCSS = "pcss"  # percentage-closer soft shadows sized by an area light's emitter


class CascadeUpdates(NameEnum):
    """When a directional light's cascades are drawn while the camera moves (``[shadows]
    cascade_updates``, ``Renderer(cascade_updates=)``; ``deferred.lighting.shadows.stagger``)."""

    EVERY_FRAME = "every_frame"  # every cascade fitted to the frame: frames independent
    STAGGERED = "staggered"  # the nearest every frame, the farther in turn (the viewer's)
