"""Every built-in material receives the environment light through the ambient term it already
has: in a uniform environment of radiance L (whose irradiance over pi is L everywhere), each
renders as under the hemisphere ambient light of sky and ground L, fur and hair included, in
both pipelines."""

import numpy as np
import pytest

from deferred.io.images import write_image
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

RADIANCE = [0.6, 0.5, 0.4]
MATERIALS = ["standard", "revie_fur", "shell_fur", "cartoon_hair", "stipple_glass"]


@pytest.fixture
def uniform_map(tmp_path, monkeypatch):
    monkeypatch.setenv("DEFERRED_CACHE_DIR", str(tmp_path / "cache"))
    pixels = np.ones((16, 32, 4), np.float32)
    pixels[..., :3] = RADIANCE
    path = tmp_path / "uniform.exr"
    write_image(path, pixels, channels=("R", "G", "B", "A"))
    return str(path)


def image(gl, material, light, pipeline):
    scene = scene_from_dict({
        "size": [96, 72], "background": [0.0, 0.0, 0.0],
        "camera": {"position": [0.0, 0.3, 3.2], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"mesh": "builtin:sphere", "material": material, "scale": 0.8}],
        "light": [light]})
    renderer = Renderer(scene, pipeline, gl=gl)
    try:
        return renderer.render().image[..., :3].astype(np.int16)
    finally:
        renderer.release()


@pytest.mark.slow
@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
@pytest.mark.parametrize("material", MATERIALS)
def test_a_uniform_environment_lights_as_the_ambient_light(gl, uniform_map, material,
                                                           pipeline):
    ambient = image(gl, material, {"type": "ambient", "color": RADIANCE, "ground": RADIANCE},
                    pipeline)
    environment = image(gl, material, {"type": "environment", "map": uniform_map}, pipeline)
    assert ambient.max() > 40  # lit: the comparison can fail
    assert np.abs(ambient - environment).max() <= 2
