"""A directional light's shadow_distance short of the camera's near plane (down to 1e-300)
shadows nothing in view, without numpy's divide-by-zero warnings from the cascade splits."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from deferred.scene.loader import scene_from_dict


def scene(distance: float | None):
    light = {"type": "directional", "shadows": True, "direction": [-0.3, -1.0, -0.2]}
    if distance is not None:
        light["shadow_distance"] = distance
    return scene_from_dict({
        "camera": {"position": [0.0, 2.0, 4.0], "target": [0.0, 0.0, 0.0]},
        "object": [{"mesh": "builtin:plane", "scale": 6.0},
                   {"mesh": "builtin:cube", "position": [0.0, 0.6, 0.0]}],
        "light": [light]})


@pytest.mark.parametrize("distance", [1e-300, 1e-30, 0.01])
def test_a_shadow_distance_inside_the_near_plane_shadows_nothing(render, distance):
    unshadowed, _ = render(scene_from_dict({
        **{"camera": {"position": [0.0, 2.0, 4.0], "target": [0.0, 0.0, 0.0]}},
        "object": [{"mesh": "builtin:plane", "scale": 6.0},
                   {"mesh": "builtin:cube", "position": [0.0, 0.6, 0.0]}],
        "light": [{"type": "directional", "direction": [-0.3, -1.0, -0.2]}]}), size=(48, 32))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result, _ = render(scene(distance), size=(48, 32))
    np.testing.assert_allclose(result.hdr, unshadowed.hdr, atol=1e-6)
    shadowed, _ = render(scene(None), size=(48, 32))
    assert not np.allclose(shadowed.hdr, unshadowed.hdr, atol=1e-3)  # the default shadows
