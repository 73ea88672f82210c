"""The standard material: colour, texture, specular parameters reach the G-buffer."""

import numpy as np

from deferred.gbuffer.layout import decode
from deferred.io.images import write_image
from deferred.scene.loader import load_scene


def test_texture_and_specular_land_in_the_gbuffer(render, tmp_path):
    quadrants = np.zeros((64, 64, 3), np.uint8)
    quadrants[:32, :32] = (255, 0, 0)
    quadrants[:32, 32:] = (0, 255, 0)
    quadrants[32:, :32] = (0, 0, 255)
    quadrants[32:, 32:] = (255, 255, 255)
    write_image(tmp_path / "quadrants.png", quadrants)
    (tmp_path / "scene.toml").write_text("""
size = [120, 120]
[camera]
position = [0.0, 3.0, 0.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
[[object]]
mesh = "builtin:plane"
[object.params]
texture = "quadrants.png"
color = [1.0, 0.5, 1.0]
specular_intensity = 0.25
specular_exponent = 100.0
[[light]]
type = "ambient"
""")
    _, renderer = render(load_scene(tmp_path / "scene.toml"))
    t = renderer.targets
    g = decode(t.read("albedo_specular"), t.read("normal_exponent_id"), t.read("linear_depth"))
    albedo = g["albedo"][::-1]  # top row first, like the image
    surface = g["material_id"][::-1] > 0
    rows, cols = np.nonzero(surface)
    top, left = rows.min() + 5, cols.min() + 5
    bottom, right = rows.max() - 5, cols.max() - 5
    # image top-left is the texture's top-left (UV v up, image rows down), times colour
    np.testing.assert_allclose(albedo[top, left], [1.0, 0.0, 0.0], atol=0.02)
    np.testing.assert_allclose(albedo[top, right], [0.0, 0.5, 0.0], atol=0.02)
    np.testing.assert_allclose(albedo[bottom, left], [0.0, 0.0, 1.0], atol=0.02)
    np.testing.assert_allclose(albedo[bottom, right], [1.0, 0.5, 1.0], atol=0.02)
    assert np.allclose(g["specular_intensity"][surface[::-1]], 0.25, atol=1 / 255)
    assert np.allclose(g["specular_exponent"][surface[::-1]], 100.0)
