"""Wind in the motion vectors (#39): with the camera and the object still, shell_fur's strands
swaying in a gusting wind move in the motion target (StrandMotion: the tips' simulated
deflection of this frame and of the frame before); without wind the fur's vectors stay zero."""

import numpy as np
import pytest

from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

FPS = 24.0


def windy_ball(wind: float):
    return scene_from_dict({
        "size": [96, 72], "background": [0.02, 0.02, 0.03],
        "camera": {"position": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"name": "ball", "mesh": "builtin:sphere", "material": "shell_fur",
                    "scale": 0.7,
                    "params": {"fur_length": 0.4, "shells": 8, "settle": 1.0,
                               "wind": [wind, 0.0, 0.0], "gust": 1.0,
                               "gust_frequency": 2.0}}],
        "light": [{"type": "ambient"}],
        "effect": [{"type": "taa"}]})


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_a_still_camera_sees_the_wind_in_the_motion_vectors(gl, pipeline):
    moved = {}
    for wind in (0.0, 6.0):
        with Renderer(windy_ball(wind), pipeline, gl=gl) as renderer:
            renderer.render(time=1.0)
            renderer.render(time=1.0 + 1.0 / FPS)
            assert renderer.last_frame.history_kept
            motion = renderer.targets.read("motion")
        moved[wind] = np.linalg.norm(motion, axis=-1)
    assert moved[0.0].max() < 0.02  # without wind only the settling under gravity
    # the swaying tips: a share of the fur moves by a visible fraction of a pixel
    assert (moved[6.0] > 0.05).sum() > 100, (moved[6.0] > 0.05).sum()
