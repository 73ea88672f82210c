"""Glass casts coloured shadows: a red pane over a white floor, lit from the side, leaves a red
shadow whose colour, over the lit floor's, is the pane's transmittance (within 5%), in both
pipelines and every light path; the pane is not tinted by its own shadow, and a scene with
glass but no transparent caster reaching a light keeps its plain shadows."""

import numpy as np
import pytest
from plane_reference import plane_points

from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SIZE = (96, 96)
RED = (1.0, 0.15, 0.1)
OPACITY = 0.2
# what the pane lets through at normal incidence: (1 - opacity) (1 - F0) colour
TRANSMITTANCE = (1.0 - OPACITY) * (1.0 - 0.04) * np.asarray(RED)


def scene(light, glass=True):
    pane = {"mesh": "builtin:plane", "material": "glass", "position": [0.0, 0.5, 0.0],
            "scale": 0.5, "params": {"color": list(RED), "opacity": OPACITY, "refraction": 0.0}}
    return scene_from_dict({
        "size": list(SIZE), "tonemap": "none", "background": [0.0, 0.0, 0.0],
        "camera": {"position": [0.0, 4.0, 0.0], "target": [0.0, 0.0, 0.0],
                   "up": [0.0, 0.0, -1.0], "fov": 40.0},
        "object": [
            {"mesh": "builtin:plane", "material": "standard", "scale": 3.0,
             "params": {"color": [1.0, 1.0, 1.0], "specular_intensity": 0.0}},
            *([pane] if glass else [])],
        "light": [light]})


LIGHTS = {
    "directional": {"type": "directional", "direction": [1.0, -1.0, 0.0], "shadows": True,
                    "shadow_resolution": 1024},
    "spot": {"type": "spot", "position": [-2.0, 2.5, 0.0], "direction": [1.0, -1.0, 0.0],
             "outer_angle": 40.0, "inner_angle": 30.0, "radius": 10.0, "intensity": 8.0,
             "shadows": True, "shadow_resolution": 1024},
    # a cube map: the shadow spans its +X and -Y faces
    "point": {"type": "point", "position": [-2.5, 3.0, 0.0], "radius": 12.0, "intensity": 10.0,
              "shadows": True, "shadow_resolution": 1024},
}


@pytest.mark.parametrize("pipeline, light_path", [
    ("deferred", "tiled"), ("deferred", "volumes"), ("deferred", "clustered"),
    ("forward", "naive"), ("forward", "tiled")])
@pytest.mark.parametrize("light", list(LIGHTS))
def test_a_red_pane_casts_a_shadow_of_its_transmittance(gl, pipeline, light_path, light):
    def render(glass):
        with Renderer(scene(LIGHTS[light], glass), pipeline, gl=gl, strict=True,
                      light_path=light_path) as renderer:
            return renderer.render(hdr=True).hdr[::-1, :, :3].astype(np.float64)

    shadowed, bare = render(True), render(False)
    ground = plane_points(scene(LIGHTS[light]), SIZE)
    row = np.argmin(np.abs(ground[:, SIZE[0] // 2, 2]))
    x = ground[row, :, 0]
    # the pane spans x in [-0.5, 0.5] at height 0.5: the camera sees it over the floor within
    # 0.57 of the middle; its shadow falls 0.5 further along +x (the spot's and the point's a
    # little further)
    under = (x > 0.62) & (x < 0.95)
    beside = (x > 1.35) & (x < 1.6)
    assert under.sum() >= 5 and beside.sum() >= 3
    ratio = shadowed[row][under] / bare[row][under]
    np.testing.assert_allclose(ratio, np.broadcast_to(TRANSMITTANCE, ratio.shape),
                               rtol=0.05, atol=0.05 * TRANSMITTANCE.max())
    np.testing.assert_allclose(shadowed[row][beside], bare[row][beside], atol=1e-3)


def test_the_pane_is_not_tinted_by_its_own_shadow(gl):
    def render(shadows):
        light = {**LIGHTS["directional"], "shadows": shadows}
        with Renderer(scene(light), "deferred", gl=gl, strict=True) as renderer:
            return renderer.render(hdr=True).hdr[::-1, :, :3].astype(np.float64)

    shadowed, plain = render(True), render(False)
    ground = plane_points(scene(LIGHTS["directional"]), SIZE)
    # where the camera sees the pane over unshadowed floor: the pane's own light as without
    # shadows
    row = np.argmin(np.abs(ground[:, SIZE[0] // 2, 2]))
    x = ground[row, :, 0]
    over = (x > -0.45) & (x < -0.05)
    np.testing.assert_allclose(shadowed[row][over], plain[row][over], atol=2e-3)
