"""Fur shadows its own skin (#27): the root shell, the skin between the strands' roots, is a
receiver of the deep opacity maps like every shell, so a shadowed light reaches it through the
whole fur in front. With the maps, only the fur's skin casts in the depth map (pushed a strand's
length away from the light; FurShadow.draw), so the skin is not shadowed twice, once by
the dithered depth casters and once by the maps. Measured on the skin alone (shell_range (0, 0),
no fins), lit from the camera: at the middle of the ball the light crosses the fur along the
normal."""

from __future__ import annotations

import numpy as np
import pytest

from deferred.lighting.shadows.opacity import OPACITY_LAYERS
from deferred.materials.techniques.fur import FurParams, fur_pattern, shell_depth
from deferred.materials.techniques.fur_shadow import OPACITY_SHELLS
from deferred.materials.techniques.fur_volume import VOLUME_LAYERS, strand_volume
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

W, H = 96, 72
FUR_LENGTH, SHELLS, K_SHADOW = 0.35, 16, 64.0
# stipple off: its rim-lit outer sample would light the deferred skin too; no comb lean (revie
# combs its shells sideways by default, which thins the fur along the normal)
FUR = {"revie_fur": {"stipple": False, "comb_strength": 0.0,
                     "albedo_base": [0.7, 0.6, 0.5], "albedo_tip": [0.7, 0.6, 0.5]},
       "shell_fur": {}}
LUMA = np.array([0.2126, 0.7152, 0.0722])


def skin_scene(material: str, density: float, shadows: bool = True,
               direction=(0.0, 0.0, -1.0), size=(W, H), opacity_scale: float | None = None):
    # lod_error: every shell drawn, whatever the fur's size on screen
    params = {"fur_length": FUR_LENGTH, "shells": SHELLS, "lod_error": 0.1,
              "self_shadow": K_SHADOW,
              "self_shadow_density": density, "shell_range": [0.0, 0.0], "fins": False,
              **FUR[material]}
    return scene_from_dict({
        "size": list(size), "tonemap": "none", "background": [0.0, 0.0, 0.0],
        "camera": {"position": [0.0, 0.0, 2.0], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "shadows": {"atlas_size": 1024,
                    **({} if opacity_scale is None else {"opacity_scale": opacity_scale})},
        "object": [{"mesh": "builtin:sphere", "scale": 0.45, "material": material,
                    "params": params}],
        "light": [{"type": "directional", "direction": list(direction), "intensity": 2.0,
                   "cascades": 1, "shadows": shadows, "shadow_resolution": 1024,
                   "shadow_distance": 8.0}]})


def skin_luminance(gl, material: str, density: float, pipeline: str,
                   shadows: bool = True, **scene) -> np.ndarray:
    with Renderer(skin_scene(material, density, shadows, **scene), pipeline,
                  gl=gl) as renderer:
        hdr = renderer.render(hdr=True).hdr
    return hdr[..., :3].astype(np.float64) @ LUMA


def middle(radius: float = 0.15) -> np.ndarray:
    yy, xx = np.mgrid[:H, :W]
    return (xx - W / 2) ** 2 + (yy - H / 2) ** 2 < (radius * H) ** 2


def fur_optical_depth() -> tuple[float, float]:
    """numpy: the optical depth of the fur in front of the skin for a light along the normal,
    as the deep opacity maps hold it. The maps draw OPACITY_SHELLS shells over the skin, each
    adding -ln(1 - opacity) of the volume's mean coverage at its height (a map texel spans a
    few strands), into the layers ending OPACITY_LAYERS strand lengths behind the fur's front.
    With the front at the outermost shell, the skin lies that shell's height behind it,
    between the ends of layers 2 and 3, and reads them interpolated linearly (Yuksel and
    Keyser 2008, 3.2): the first value; with the front at the tips, all the shells' (the
    second)."""
    params = FurParams(fur_length=FUR_LENGTH, shells=SHELLS)
    coverage = strand_volume(fur_pattern(params))[..., 0].mean(axis=(1, 2))
    count = min(SHELLS, OPACITY_SHELLS) + 1
    heights = np.array([shell_depth(k, count) for k in range(1, count)])
    at = np.interp(np.clip(heights * VOLUME_LAYERS - 0.5, 0.0, VOLUME_LAYERS - 1),
                   np.arange(VOLUME_LAYERS), coverage)
    opacity = np.minimum(1.0 - (1.0 - at) ** (VOLUME_LAYERS / (count - 1)), 0.999)
    shells = -np.log(1.0 - opacity)
    front = heights.max()
    layers = [shells[front - heights <= end].sum() for end in OPACITY_LAYERS]
    return float(np.interp(front, [0.0, *OPACITY_LAYERS], [0.0, *layers])), float(shells.sum())


@pytest.mark.slow
@pytest.mark.parametrize("material", ["revie_fur", "shell_fur"])
def test_skin_keeps_the_fur_transmittance(gl, material):
    """Lit through dense fur, the skin keeps exp(-k x the fur's optical depth) of the light
    it has without self-shadowing (where gamma(h) = (K - 1) / K darkens it instead): the
    optical depth its light gives, -ln(T) / k, lies between the numpy reference's two values
    (the layers interpolated at the skin, all the shells), within 5%, for k = 0.5 and 1 (one
    depth: the transmittance is exponential in k), in both pipelines; the two pipelines'
    skins agree within 1% of the unshadowed skin's light."""
    inside = middle()
    gamma = (K_SHADOW - 1.0) / K_SHADOW
    interpolated, whole = fur_optical_depth()
    kept = {}
    for pipeline in ("forward", "deferred"):
        without = skin_luminance(gl, material, 0.0, pipeline)[inside].mean()
        assert without > 0.1  # lit
        for density in (0.5, 1.0):
            with_ = skin_luminance(gl, material, density, pipeline)[inside].mean()
            kept[(pipeline, density)] = with_ / without * gamma
    print(material, "transmittance", kept, "expected",
          {k: (float(np.exp(-k * whole)), float(np.exp(-k * interpolated))) for k in (0.5, 1.0)})
    for transmittance, density in ((t, k) for (_, k), t in kept.items()):
        assert 0.95 * interpolated < -np.log(transmittance) / density < 1.05 * whole
    for density in (0.5, 1.0):
        assert kept[("deferred", density)] == pytest.approx(kept[("forward", density)],
                                                            abs=0.01)


@pytest.mark.slow
@pytest.mark.parametrize("pipeline", ["forward", "deferred"])
def test_skin_without_self_shadowing_is_the_unshadowed_skin(gl, pipeline):
    """self_shadow_density 0 leaves the skin as without shadows: gamma(h) alone, and no depth
    shadow of the fur's own casters, pushed a strand's length from the light, in the ball's
    middle (the light within 30 degrees of the normal). Toward the terminator the outer shells
    still cast onto the skin (pushed along the light, a shell at height h clears a flat skin
    below it only where h < the cosine of the light's angle from the normal): here from about
    45 degrees on, up to a third of the light at the ball's rim."""
    inside = middle()
    shadowed = skin_luminance(gl, "shell_fur", 0.0, pipeline)
    unshadowed = skin_luminance(gl, "shell_fur", 0.0, pipeline, shadows=False)
    np.testing.assert_allclose(shadowed[inside], unshadowed[inside], rtol=1e-3)


@pytest.mark.slow
@pytest.mark.parametrize("material", ["revie_fur", "shell_fur"])
def test_skin_transmittance_has_no_steps_at_coarse_maps(gl, material):
    """With deep opacity maps a quarter of the shadow map's resolution (a texel spans about
    the fur's thickness here), the skin's transmittance (its light with self-shadowing over its
    light without) varies smoothly: the fur's front is interpolated between the maps' texels
    (lighting/shadows.glsl, interpolated_front). Read nearest, the front stepped at every texel's
    edge and so did the depth behind it: 4-5% of neighbouring pixels differed by more than 0.04,
    contour bands across the ball. Now under 2.5% against the skin with no shadow map (the fur's
    dithered shells cast in the depth map without self-shadowing, FurShadow.draw; with
    it only its skin does): what is left are the maps' own streaks along the light."""
    scene = {"direction": (1.0, -0.3, -0.5), "size": (192, 144), "opacity_scale": 0.25}
    with_ = skin_luminance(gl, material, 0.5, "forward", **scene)
    without = skin_luminance(gl, material, 0.0, "forward", shadows=False, **scene)
    lit = without > 0.05
    transmittance = np.where(lit, with_ / np.maximum(without, 1e-6), 0.0)
    steps = np.concatenate([
        np.abs(np.diff(transmittance, axis=1))[lit[:, 1:] & lit[:, :-1]],
        np.abs(np.diff(transmittance, axis=0))[lit[1:] & lit[:-1]]])
    print(material, "steps over 0.04", (steps > 0.04).mean(), "mean",
          transmittance[lit].mean())
    assert lit.sum() > 5000
    assert (steps > 0.04).mean() < 0.025
    assert 0.2 < transmittance[lit].mean() < 0.35


def sheet_luminance(gl, material: str, density: float, pipeline: str,
                    skin_only: bool) -> np.ndarray:
    """A sheet of fur (builtin:plane) seen from above at a slant, lit from above through it."""
    params = {"fur_length": 0.2, "shells": SHELLS, "lod_error": 0.1, "self_shadow": K_SHADOW,
              "self_shadow_density": density, "fins": False, **FUR[material],
              **({"shell_range": [0.0, 0.0]} if skin_only else {})}
    scene = scene_from_dict({
        "size": [W, H], "tonemap": "none", "background": [0.0, 0.0, 0.0],
        "camera": {"position": [0.0, 1.6, 1.2], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "shadows": {"atlas_size": 1024},
        "object": [{"mesh": "builtin:plane", "scale": 0.6, "material": material,
                    "params": params}],
        "light": [{"type": "directional", "direction": [0.0, -1.0, -0.2], "intensity": 2.0,
                   "cascades": 1, "shadows": True, "shadow_resolution": 1024,
                   "shadow_distance": 8.0}]})
    with Renderer(scene, pipeline, gl=gl) as renderer:
        hdr = renderer.render(hdr=True).hdr
    return hdr[..., :3].astype(np.float64) @ LUMA


@pytest.mark.slow
@pytest.mark.parametrize("material", ["revie_fur", "shell_fur"])
@pytest.mark.parametrize("skin_only", [True, False])
def test_open_sheet_of_fur_is_shadowed_once_in_deferred(gl, material, skin_only):
    """On an open mesh the maps' front and back are both the fur's tips, so the skin lies beyond
    the back and the generic light pass gives it the fur's whole transmittance; the deferred
    layers reading that skin must find the same lookup in the light they swap out, or the fur
    is darkened twice (without it deferred keeps about 0.42 of forward's light)."""
    box = np.zeros((H, W), bool)
    box[24:48, 32:64] = True
    forward = sheet_luminance(gl, material, 0.25, "forward", skin_only)
    deferred = sheet_luminance(gl, material, 0.25, "deferred", skin_only)
    unshadowed = sheet_luminance(gl, material, 0.0, "forward", skin_only)
    box &= unshadowed > 1e-3
    assert np.median(forward[box]) < 0.9 * np.median(unshadowed[box])  # the fur shadows
    assert np.median(deferred[box]) == pytest.approx(np.median(forward[box]), rel=0.05)
