"""The fur volume's triplanar lookup (shaders/techniques/fur.glsl) picks one plane per cell
where the planes' weights overlap: the fur is as bright in a blend zone as on an axis (mixing
the planes' coverages would make coarse fur brighter there)."""

import numpy as np
import pytest

from deferred.scene.loader import scene_from_dict

COARSE = {"pattern": "coarse", "density": 1500, "fur_length": 0.25, "shells": 32,
          "thickness_tip": 0.45}


def mean_luminance(render, material, rotation, pipeline):
    """The fur's mean luminance in the middle of a ball under an even ambient light, the ball
    turned by ``rotation`` (so the middle's normal lies on an axis or between axes)."""
    scene = scene_from_dict({
        "size": [200, 200], "background": [0.0, 0.0, 0.0], "tonemap": "none",
        "camera": {"position": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0], "fov": 30.0},
        "object": [{"mesh": "builtin:sphere", "material": material, "rotation": rotation,
                    "params": COARSE}],
        "light": [{"type": "ambient", "color": [1.0, 1.0, 1.0], "ground": [1.0, 1.0, 1.0]}]})
    result, _ = render(scene, pipeline)
    middle = result.hdr[70:130, 70:130, :3]
    return float((middle @ np.array([0.2126, 0.7152, 0.0722])).mean())


@pytest.mark.parametrize("material,pipeline", [("revie_fur", "deferred"),
                                               ("revie_fur", "forward"),
                                               ("shell_fur", "deferred")])
def test_blend_zone_is_as_bright_as_an_axis(render, material, pipeline):
    axis = mean_luminance(render, material, [0.0, 0.0, 0.0], pipeline)
    for rotation in ([0.0, 45.0, 0.0], [35.26, 45.0, 0.0]):  # two planes, three planes
        blend = mean_luminance(render, material, rotation, pipeline)
        print(f"{material} {pipeline} {rotation}: {blend / axis - 1.0:+.1%}")
        assert abs(blend / axis - 1.0) < 0.05
