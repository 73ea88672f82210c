"""Shadow inputs at their edges: a directional light's shadow_distance short of the camera's
near plane (down to 1e-300) shadows nothing in view, without numpy's divide-by-zero warnings
from the cascade splits; a thousand lights over the shadow budget are one short warning."""

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


def test_a_thousand_lights_over_the_budget_are_one_short_warning(tmp_path, capfd):
    """1,000 shadowed point lights and a budget of 16: one line with the count and the first
    few of each reason (it was 38,230 characters naming each)."""
    from command_line import run

    lights = "".join(f'[[light]]\ntype = "point"\nposition = [{i % 40 * 0.1:.1f}, 2.0, '
                     f'{i // 40 * 0.1:.1f}]\nradius = 1.0\nshadows = true\n'
                     f"shadow_resolution = 64\n\n" for i in range(1000))
    scene = tmp_path / "scene.toml"
    scene.write_text('[[object]]\nmesh = "builtin:plane"\nmaterial = "standard"\n\n' + lights)
    code, _, err = run(capfd, "render", scene, "-o", tmp_path / "out.png", "--size", "32x24")
    assert code == 0, err[-500:]
    warnings = [line for line in err.splitlines() if "shadow budget" in line]
    assert len(warnings) == 1 and len(warnings[0]) < 200, warnings
    assert warnings[0] == ("warning: scene.toml: 984 lights unshadowed, over the shadow budget: "
                           "lights 16, 17, 18, 19, 20 and 979 more (max_shadowed_lights = 16)")
