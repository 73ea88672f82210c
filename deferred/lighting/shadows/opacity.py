"""Deep opacity maps (Yuksel and Keyser 2008): whether a scene draws them, and the square of the
atlas they cover and their size; the layers' depths and the first-depth map's clear value."""

from __future__ import annotations

from deferred.lighting.shadows.plan import plan_atlas, scene_casts_shadows
from deferred.names import Pipeline, ShadowAllocation
from deferred.scene.scene import Scene

OPACITY_SHADOWS_DEFINE = "OPACITY_SHADOWS"
# where the four opacity layers end, in units of the thickest volume's layer: finer near the
# volume's front, where light falls fastest (Yuksel and Keyser 2008, section 3: layer sizes)
OPACITY_LAYERS = (0.25, 0.5, 1.0, 2.0)
OPACITY_FAR = 3.0e38  # the first-depth map's clear value: no volume along the texel
# grows each tile's fronts by a texel where a texel's centre missed the volume
OPACITY_FRONT_FRAGMENT = "shadows/opacity_front.frag"


def scene_has_opacity(scene: Scene, pipeline: str) -> bool:
    """Whether a shadowed scene draws deep opacity maps: an object's material asks for them
    (``opacity_shadows``) and reads them in this pipeline (every such material in the forward
    pipeline; in the deferred one only where ``deferred_opacity`` says its deferred passes
    do)."""
    return scene_casts_shadows(scene.lights) and any(
        obj.material.shadow.opacity_shadows(obj) and (
            pipeline == Pipeline.FORWARD or obj.material.shadow.deferred_opacity)
        for obj in scene.objects)


def opacity_extent(scene: Scene) -> int:
    """Texels on a side of the square, from the atlas's corner, that the maps of the scene's
    shadowed lights take (as :func:`~deferred.lighting.shadows.plan.plan_atlas` places them:
    largest first, from the corner): the part of the atlas the deep opacity maps and the
    transmittance maps cover.
    By screen coverage (``allocation = "coverage"``) the maps are at most these and packed
    into this square, or into the whole atlas where these do not all fit (smaller maps let
    more lights in: :func:`~deferred.lighting.shadows.coverage.fit_sizes`)."""
    budget = scene.shadow_budget
    plan, left_out = plan_atlas(scene.lights, budget.atlas_size, budget.max_shadowed_lights)
    if budget.allocation == ShadowAllocation.COVERAGE and \
            any(not why.startswith("max_shadowed_lights") for _, why in left_out):
        return budget.atlas_size
    return max((max(x, y) + size for _, squares in plan.values() for x, y, size in squares),
               default=1)


def opacity_size(scene: Scene, pipeline: str) -> int:
    """Texels on a side of the scene's deep opacity maps (0: none drawn): the atlas's square
    its lights' maps take (:func:`opacity_extent`) at the budget's ``opacity_scale`` (the
    volume's shadow is soft: the opacity maps need fewer texels than the depth maps)."""
    if not scene_has_opacity(scene, pipeline):
        return 0
    return max(round(opacity_extent(scene) * scene.shadow_budget.opacity_scale), 1)

