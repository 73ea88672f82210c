"""The scene's shadow atlas budget (a scene file's ``[shadows]`` table)."""

from __future__ import annotations

from dataclasses import dataclass

OPACITY_SCALES = (1.0, 0.5, 0.25, 0.125, 0.0625)  # ShadowBudget.opacity_scale's values

__all__ = ["OPACITY_SCALES", "ShadowBudget"]


@dataclass(frozen=True)
class ShadowBudget:
    """The scene's shadow atlas (a ``[shadows]`` table): one depth texture of ``atlas_size``
    texels on a side holding every shadowed light's maps, for at most ``max_shadowed_lights``
    lights (those beyond, or whose maps do not fit, are drawn unshadowed, with a warning).
    Deep opacity maps (fur) have ``opacity_scale`` of the shadow maps' texels on a side, over
    the part of the atlas the lights' maps take. ``allocation`` says how large a light's maps
    are (``deferred.lighting.shadows.coverage``): ``fixed``, each of its ``shadow_resolution``,
    or ``coverage``, by the part of the screen its shadowed region covers.
    ``cascade_updates``: ``"every_frame"``, ``"staggered"``
    (``deferred.lighting.shadows.stagger``), or None: the renderer's default (every frame; the
    viewer's staggered)."""

    atlas_size: int = 4096
    max_shadowed_lights: int = 16
    opacity_scale: float = 0.25
    allocation: str = "coverage"
    cascade_updates: str | None = None
