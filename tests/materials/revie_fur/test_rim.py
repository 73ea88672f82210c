"""The back-lit rim of volume lights in the deferred fur (#39): a point light behind a fur ball
lights its silhouette in the deferred pipeline as in the forward one (Revie 2.3.2, Listing 2.3:
the rim-bent normal), with and without the light's shadow (and the fur's deep opacity maps)."""

import numpy as np
import pytest

from deferred.scene.loader import scene_from_dict

LUMA = np.array([0.2126, 0.7152, 0.0722])


def back_lit_ball(light_type: str, shadows: bool):
    light = {"type": light_type, "position": [0.3, 0.4, -1.6], "color": [1.0, 0.7, 0.4],
             "intensity": 4.0, "radius": 4.0, "shadows": shadows}
    if light_type == "spot":
        light.update({"direction": [-0.3, -0.4, 1.6], "inner_angle": 30.0,
                      "outer_angle": 45.0})
    return scene_from_dict({
        "size": [160, 120], "background": [0.0, 0.0, 0.0],
        "camera": {"position": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"name": "fur", "mesh": "builtin:sphere", "material": "revie_fur",
                    "scale": 0.6, "params": {"fur_length": 0.12, "shells": 16}}],
        "light": [{"type": "ambient", "color": [0.02, 0.02, 0.02]}, light]})


@pytest.mark.parametrize(("light_type", "shadows"),
                         [("point", False), ("point", True), ("spot", False)])
def test_a_light_behind_a_fur_ball_lights_its_rim_as_in_forward(render, light_type, shadows):
    scene = back_lit_ball(light_type, shadows)
    forward = render(scene, "forward")[0].image[..., :3] @ LUMA
    deferred = render(back_lit_ball(light_type, shadows), "deferred")[0].image[..., :3] @ LUMA
    # the silhouette: where the forward fur glows (the ball's face is dark, the light behind)
    rim = forward > 40.0
    assert rim.sum() > 80, rim.sum()
    ratio = deferred[rim].mean() / forward[rim].mean()
    assert 0.9 <= ratio <= 1.1, ratio
    # and not by lighting the face: away from the rim both stay dark
    face = ~rim & (forward > 0.0) & (deferred > 0.0)
    assert deferred[face].mean() <= forward[face].mean() * 1.1 + 1.0
