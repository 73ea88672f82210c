"""The pbr material's alpha modes: a mask cuts where alpha is under the cutoff (in the image
and in the shadow maps, both pipelines); a blended surface shows both colours in proportion,
whatever the objects' order, and hides behind an opaque one."""

import numpy as np
import pytest
from pbr_reference import render_hdr
from plane_reference import plane_points

from deferred.io.images import write_image
from deferred.scene.loader import scene_from_dict

TOP = {"position": [0.0, 4.0, 0.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
       "fov": 40.0}
SIZE = (96, 96)


def alpha_ramp(path, rising=True):
    """RGBA8 image whose alpha runs from 0 to 1 along u (or back)."""
    ramp = (np.arange(64) + 0.5) / 64
    pixels = np.ones((4, 64, 4), np.float32)
    pixels[..., 3] = ramp if rising else 1.0 - ramp
    write_image(path, (pixels * 255 + 0.5).astype(np.uint8), channels=("R", "G", "B", "A"))
    return str(path)


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_mask_cuts_below_the_cutoff(gl, tmp_path, pipeline):
    cutoff = 0.3
    scene = scene_from_dict({
        "size": list(SIZE), "tonemap": "none", "background": [0.0, 0.0, 0.0], "camera": TOP,
        "object": [{"mesh": "builtin:plane", "material": "pbr",
                    "params": {"base_color": [0.0, 0.0, 0.0], "emissive": [1.0, 1.0, 1.0],
                               "alpha_mode": "mask", "alpha_cutoff": cutoff,
                               "base_color_texture": alpha_ramp(tmp_path / "ramp.png")}}]})
    image = render_hdr(gl, scene, pipeline)[::-1]  # bottom row first, as plane_points
    points = plane_points(scene, SIZE)
    u = points[..., 0] / 2.0 + 0.5
    on_plane = (np.abs(points[..., 0]) < 0.97) & (np.abs(points[..., 2]) < 0.97)
    kept = image[..., 0] > 0.5
    away = np.abs(u - cutoff) > 1.5 / 64 + 2.0 / SIZE[0]  # clear of the boundary's texels
    expected = u >= cutoff
    assert np.array_equal(kept[on_plane & away], expected[on_plane & away])
    assert expected[on_plane & away].mean() > 0.5 and (~expected[on_plane & away]).sum() > 300


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_mask_cuts_its_shadow(gl, tmp_path, pipeline):
    """A masked plane over the ground, lit from the side: the ground beside it is shadowed
    where the plane is kept and lit where it is cut."""
    cutoff = 0.3
    scene = scene_from_dict({
        "size": list(SIZE), "tonemap": "none", "background": [0.0, 0.0, 0.0], "camera": TOP,
        "object": [
            {"mesh": "builtin:plane", "material": "standard", "scale": 3.0,
             "params": {"color": [1.0, 1.0, 1.0], "specular_intensity": 0.0}},
            {"mesh": "builtin:plane", "material": "pbr", "position": [0.0, 0.5, 0.0],
             "scale": 0.5,
             "params": {"alpha_mode": "mask", "alpha_cutoff": cutoff, "double_sided": True,
                        "base_color_texture": alpha_ramp(tmp_path / "ramp.png", False)}}],
        "light": [{"type": "directional", "direction": [1.0, -1.0, 0.0], "shadows": True,
                   "shadow_resolution": 1024}]})
    image = render_hdr(gl, scene, pipeline)[::-1]
    ground = plane_points(scene, SIZE)  # the ground beside the small plane
    row = np.argmin(np.abs(ground[:, SIZE[0] // 2, 2]))
    x = ground[row, :, 0]
    light = image[row, :, 0]
    # the plane spans x in [-0.5, 0.5]; kept where 1 - u >= cutoff, u = x + 0.5: x <= 0.2,
    # its shadow moved 0.5 along +x: the ground is shadowed up to x = 0.7
    lit = light[(x > 0.78) & (x < 1.2)]
    shadowed = light[(x > 0.55) & (x < 0.62)]
    assert lit.size and shadowed.size
    assert shadowed.max() < 0.2 * lit.min()


def two_planes(front_first, blend_in_front=True):
    back = {"mesh": "builtin:plane", "material": "pbr", "rotation": [90.0, 0.0, 0.0],
            "position": [0.0, 0.0, 0.0], "scale": 2.0,
            "params": {"base_color": [0.0, 0.0, 0.0], "emissive": [0.0, 1.0, 0.0]}}
    front = {"mesh": "builtin:plane", "material": "pbr", "rotation": [90.0, 0.0, 0.0],
             "position": [0.0, 0.0, 0.5], "scale": 1.0,
             "params": {"base_color": [0.0, 0.0, 0.0, 0.25], "emissive": [1.0, 0.0, 0.0],
                        "alpha_mode": "blend"}}
    if not blend_in_front:
        front["params"], back["params"] = back["params"], front["params"]
        front["scale"], back["scale"] = 2.0, 1.0
    objects = [front, back] if front_first else [back, front]
    return scene_from_dict({
        "size": [64, 64], "tonemap": "none", "background": [0.0, 0.0, 1.0],
        "camera": {"position": [0.0, 0.0, 5.0], "target": [0.0, 0.0, 0.0], "fov": 30.0},
        "object": objects})


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_blend_in_front_shows_both_colours_in_proportion(gl, pipeline):
    image = render_hdr(gl, two_planes(True), pipeline)
    np.testing.assert_allclose(image[32, 32], [0.25, 0.75, 0.0], atol=2e-3)
    np.testing.assert_allclose(image[32, 4], [0.0, 1.0, 0.0], atol=2e-3)  # the back alone
    np.testing.assert_array_equal(image, render_hdr(gl, two_planes(False), pipeline))
    hidden = render_hdr(gl, two_planes(True, blend_in_front=False), pipeline)
    np.testing.assert_allclose(hidden[32, 32], [0.0, 1.0, 0.0], atol=2e-3)


@pytest.mark.parametrize("double_sided", [False, True])
def test_double_sided_shows_the_back_lit_as_its_front(gl, double_sided):
    """A plane seen from behind: culled unless double-sided, then lit with its normal turned
    toward the viewer (a light behind the camera lights it), the same in both pipelines
    (Forward+'s pre-pass draws the back faces too)."""
    def plane(flip):
        return scene_from_dict({
            "size": [48, 48], "tonemap": "none", "background": [0.0, 0.0, 1.0],
            "camera": {"position": [0.0, 3.0, 0.0], "target": [0.0, 0.0, 0.0],
                       "up": [0.0, 0.0, -1.0], "fov": 40.0},
            "object": [{"mesh": "builtin:plane", "material": "pbr",
                        "rotation": [180.0 if flip else 0.0, 0.0, 0.0],
                        "params": {"base_color": [0.8, 0.2, 0.2], "metallic": 0.0,
                                   "roughness": 0.6, "double_sided": double_sided}}],
            "light": [{"type": "directional", "direction": [0.2, -1.0, 0.1]}]})

    front = render_hdr(gl, plane(False))
    for pipeline in ("deferred", "forward"):
        back = render_hdr(gl, plane(True), pipeline)
        if double_sided:
            np.testing.assert_allclose(back[24, 24], front[24, 24], rtol=1e-3, atol=1e-4)
        else:
            np.testing.assert_array_equal(back[24, 24], [0.0, 0.0, 1.0])
