"""Fins cast shadows (#39): a fur plane standing edge-on under a light casts nothing with its
shells (edge-on slabs), but its fins, which the light sees face-on, shadow the floor below. In
the depth map, where the fur casts with its shells (``self_shadow_density`` 0: no deep opacity
maps); in the maps the shells' slabs hold the fur's optical depth (fur_shadow.py)."""

import numpy as np
import pytest

from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict


def fin_plane_scene(fins: bool, density: float):
    return scene_from_dict({
        "size": [96, 72], "background": [0.0, 0.0, 0.0],
        "camera": {"position": [0.0, 2.2, 1.4], "target": [0.0, 0.0, 0.0], "fov": 45.0},
        "object": [{"name": "floor", "mesh": "builtin:plane", "scale": 2.0,
                    "params": {"color": [0.8, 0.8, 0.8], "specular_intensity": 0.0}},
                   {"name": "fur", "mesh": "builtin:plane", "material": "revie_fur",
                    "position": [0.0, 0.6, 0.0], "rotation": [90.0, 0.0, 0.0], "scale": 0.3,
                    "params": {"fur_length": 0.5, "shells": 16, "fins": fins,
                               "comb_strength": 0.0, "self_shadow_density": density}}],
        "light": [{"type": "ambient", "color": [0.05, 0.05, 0.05]},
                  {"type": "directional", "direction": [0.0, -1.0, 0.02], "shadows": True}]})


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_a_fin_covered_plane_casts_a_shadow(gl, pipeline):
    images = {}
    for fins in (False, True):
        with Renderer(fin_plane_scene(fins, 0.0), pipeline, gl=gl) as renderer:
            images[fins] = renderer.render().image[..., :3].astype(np.float64).mean(axis=-1)
    # the floor, lit alike in both frames away from the plane's foot, darker there with fins
    darker = images[False] - images[True]
    assert np.abs(np.median(darker)) < 1.0
    assert (darker > 10.0).sum() >= 20, (darker > 10.0).sum()
