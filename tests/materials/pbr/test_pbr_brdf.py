"""The pbr material against an independent numpy evaluation of its BRDF: spheres under one
directional light, both pipelines."""

import numpy as np
import pytest
from conftest import psnr
from pbr_reference import interior, shade, sphere_hits

from deferred.scene.loader import scene_from_dict

SIZE = (160, 96)
CAMERA = {"position": [0.0, 0.0, 6.0], "target": [0.0, 0.0, 0.0], "fov": 35.0}
SPHERE = "builtin:sphere?segments=192&rings=96"
LIGHT = np.array([-0.45, -0.5, -0.75])
SPHERES = [  # centre, base colour, metallic, roughness
    ((-1.1, 0.0, 0.0), (0.8, 0.3, 0.2), 0.0, 0.35),
    ((1.1, 0.0, 0.0), (0.95, 0.75, 0.4), 1.0, 0.5),
]


def scene():
    return scene_from_dict({
        "size": list(SIZE), "tonemap": "none", "background": [0.0, 0.0, 0.0],
        "camera": CAMERA,
        "object": [{"mesh": SPHERE, "material": "pbr", "position": list(centre),
                    "params": {"base_color": list(base), "metallic": metallic,
                               "roughness": roughness}}
                   for centre, base, metallic, roughness in SPHERES],
        "light": [{"type": "directional", "direction": LIGHT.tolist(),
                   "color": [1.0, 0.95, 0.9], "intensity": 3.0}]})


def reference(made):
    want = np.zeros((SIZE[1], SIZE[0], 3))
    covered = np.zeros((SIZE[1], SIZE[0]), bool)
    to_light = -LIGHT / np.linalg.norm(LIGHT)
    radiance = np.array([1.0, 0.95, 0.9]) * 3.0
    for centre, base, metallic, roughness in SPHERES:
        points, normals, hit = sphere_hits(made.camera, SIZE, centre)
        to_viewer = np.asarray(CAMERA["position"]) - points
        to_viewer /= np.linalg.norm(to_viewer, axis=-1, keepdims=True)
        shaded = shade(normals, to_viewer, to_light, radiance, base, metallic, roughness)
        want[hit] = shaded[hit]
        covered |= hit
    return want, interior(covered)


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_pbr_spheres_match_numpy_brdf(render, pipeline):
    made = scene()
    result, _ = render(made, pipeline)
    image = result.hdr[..., :3]
    want, inside = reference(made)
    peak = float(want[inside].max())
    assert psnr(image[inside], want[inside], peak) >= 40.0
    # the metal sphere's highlight is where the numpy one is (the metal's colour in it)
    metal = np.zeros_like(inside)
    metal[:, SIZE[0] // 2:] = True
    brightest = np.unravel_index(np.argmax(np.where(inside & metal, want.sum(-1), 0)),
                                 inside.shape)
    got = np.unravel_index(np.argmax(np.where(inside & metal, image.sum(-1), 0)), inside.shape)
    assert abs(brightest[0] - got[0]) <= 2 and abs(brightest[1] - got[1]) <= 2
