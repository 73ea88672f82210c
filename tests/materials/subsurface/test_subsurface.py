"""The subsurface material: the blur of the diffuse light against a numpy reference of the
profile across a shadow edge, the highlight left sharp, light through thin parts by the
profile's transmittance, forward against deferred."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import psnr

from deferred.materials.techniques.subsurface_profile import (
    kernel,
    marginal,
    profile,
    profile_shape,
    transmittance,
)
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

# under the wall of edge_scene, looking down at the plane
TOP = {"position": [0.0, 0.5, 0.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
       "fov": 30.0}
TOP_HALF_HEIGHT = 0.5 * np.tan(np.radians(15.0))  # of the plane y = 0 as TOP sees it


def render(gl, scene, pipeline="deferred", light_path=None):
    renderer = Renderer(scene_from_dict(scene), pipeline, gl=gl, light_path=light_path)
    try:
        return renderer.render(hdr=True).hdr[::-1, :, :3].astype(np.float64)
    finally:
        renderer.release()


def edge_scene(material, params, size=(192, 32)):
    """A plane lit from straight above, half of it in the shadow of a wall's straight edge
    (along the view's columns: x = 0)."""
    wall = {"mesh": "builtin:cube", "position": [-1.5, 1.0, 0.0], "scale": [2.0, 0.05, 2.0],
            "params": {"color": [0.0, 0.0, 0.0], "specular_intensity": 0.0}}
    return {"size": list(size), "tonemap": "none", "background": [0, 0, 0], "camera": TOP,
            "object": [{"mesh": "builtin:plane", "scale": 4.0, "material": material,
                        "params": params}, wall],
            "light": [{"type": "directional", "direction": [0.0, -1.0, 0.0], "intensity": 1.0,
                       "shadows": True, "shadow_resolution": 2048, "shadow_filter": "pcf"}]}


def pixel_x(size):
    """World x of each column's centre on the plane y = 0 seen by TOP."""
    width, height = size
    half_width = TOP_HALF_HEIGHT * width / height
    return ((np.arange(width) + 0.5) / width * 2.0 - 1.0) * half_width


def blurred_edge(row, x, shape):
    """``row`` (one channel along x, evenly spaced) convolved with the profile's continuous
    marginal of ``shape``: K integrated over each column (tabulated finely once)."""
    step = x[1] - x[0]
    fine = (np.arange(-8 * len(x), 8 * len(x)) + 0.5) * (step / 8.0)
    table = marginal(fine, shape)
    per_column = table.reshape(-1, 8).mean(1) * step  # offsets -len .. len-1 columns
    out = np.zeros_like(row)
    for i in range(len(x)):
        weights = per_column[len(x) - i:2 * len(x) - i]
        out[i] = (weights * row).sum() / weights.sum()
    return out


def tapped_edge(row, pixels_per_unit, shapes, channel):
    """What the shader computes along a row of an even surface: the taps of the profile
    (offsets rounded to whole pixels, clamped at the frame's edge to the centre's light)."""
    offsets, weights = kernel(tuple(float(d) for d in shapes))
    shift = np.round(offsets * pixels_per_unit).astype(int)
    out = np.zeros_like(row)
    for i in range(len(row)):
        at = i + shift
        inside = (at >= 0) & (at < len(row))
        taken = np.where(inside, row[np.clip(at, 0, len(row) - 1)], row[i])
        out[i] = (weights[:, channel] * taken).sum()
    return out


def fall_width(values, top):
    """Columns from 10% to 90% of ``top``."""
    return int(np.argmax(values > 0.9 * top) - np.argmax(values > 0.1 * top))


@pytest.mark.parametrize("radius", [0.04, 0.1])
def test_a_lit_edge_falls_off_with_the_profiles_width(gl, radius):
    """Across a shadow edge the subsurface plane's light is the standard plane's (same albedo,
    no highlight) convolved with the 1D profile of its mean free path, channel by channel:
    a wider radius a wider fall, red wider than blue (falloff)."""
    size = (192, 32)
    color, falloff = [0.8, 0.8, 0.8], [1.0, 0.6, 0.3]
    plain = render(gl, edge_scene("standard", {"color": color, "specular_intensity": 0.0},
                                  size))
    scattered = render(gl, edge_scene("subsurface", {"color": color, "radius": radius,
                                                     "falloff": falloff,
                                                     "specular_intensity": 0.0,
                                                     "transmission": 0.0}, size))
    x = pixel_x(size)
    pixels_per_unit = size[1] / (2.0 * TOP_HALF_HEIGHT)
    shapes = profile_shape(radius * np.array(falloff), color)
    rows = slice(8, 24)
    widths = []
    for channel in range(3):
        plain_row = plain[rows, :, channel].mean(0)
        got = scattered[rows, :, channel].mean(0)
        top = plain_row.max()
        assert top > 0.5 and plain_row[:20].max() < 0.02 * top  # lit right, dark left
        # the shader's taps exactly
        tapped = tapped_edge(plain_row, pixels_per_unit, shapes, channel)
        assert np.abs(got - tapped).max() < 0.01 * top
        # and the continuous profile: the same fall, within the steps of its 21 taps
        want = blurred_edge(plain_row, x, shapes[channel])
        error = np.abs(got - want) / top
        assert error.mean() < 0.01 and error.max() < 0.15, (channel, error.mean(),
                                                            error.max())
        width, wanted = fall_width(got, top), fall_width(want, top)
        assert abs(width - wanted) <= max(0.2 * wanted, 2), (channel, width, wanted)
        widths.append(width)
    assert widths[0] > widths[1] > widths[2] >= 3, widths  # red scatters farthest


def test_the_profile_and_its_marginal_integrate_to_one():
    r = np.linspace(1e-5, 3.0, 300001)
    d = 0.07
    assert abs(np.trapezoid(profile(r, d) * 2.0 * np.pi * r, r) - 1.0) < 2e-3
    x = np.linspace(-3.0, 3.0, 60001)
    assert abs(np.trapezoid(marginal(x, d), x) - 1.0) < 5e-3
    # the transmittance is the profile beyond the thickness: 1 at 0, its tail after
    assert transmittance(0.0, d) == pytest.approx(1.0)
    t = 0.1
    beyond = r >= t
    assert transmittance(t, d) == pytest.approx(
        np.trapezoid((profile(r, d) * 2.0 * np.pi * r)[beyond], r[beyond]), rel=2e-3)


def test_the_highlight_is_not_blurred(gl):
    """A sharp highlight on a uniformly lit plane: the subsurface plane equals the standard one
    (the blur of an even diffuse light changes nothing, and it never sees the highlight), where
    blurring the whole light would take most of the highlight's peak away."""
    size = (128, 96)
    camera = {"position": [0.0, 1.0, 2.0], "target": [0.0, 0.0, 0.0], "fov": 50.0}
    params = {"color": [0.1, 0.1, 0.1], "specular_intensity": 1.0, "specular_exponent": 600.0}
    scene = {"size": list(size), "tonemap": "none", "background": [0, 0, 0], "camera": camera,
             "light": [{"type": "directional", "direction": [0.0, -0.45, 1.0],
                        "intensity": 1.0}]}
    standard = render(gl, {**scene, "object": [{"mesh": "builtin:plane", "scale": 6.0,
                                                "params": params}]})
    scattered = render(gl, {**scene, "object": [{"mesh": "builtin:plane", "scale": 6.0,
                                                 "material": "subsurface",
                                                 "params": {**params, "radius": 0.2,
                                                            "transmission": 0.0}}]})
    peak = standard.max()
    assert peak > 4.0 * np.median(standard)  # a sharp highlight over the diffuse light
    assert np.abs(scattered - standard).max() < 0.01 * peak
    # blurring everything would have spread it: the profile across the peak's row
    row = standard[np.unravel_index(standard[..., 0].argmax(), standard.shape[:2])[0], :, 0]
    x = np.linspace(-1.0, 1.0, size[0]) * 2.0 * np.tan(np.radians(25.0)) * size[0] / size[1]
    assert blurred_edge(row, x, float(profile_shape(0.2, 0.1))).max() < 0.7 * row.max()


def slab_brightness(gl, thickness, transmission=1.0):
    """A thin slab lit from straight below, seen from above: the mean light of its middle."""
    size = (48, 48)
    slab = {"mesh": "builtin:cube", "position": [0.0, 0.5, 0.0],
            "scale": [1.0, thickness / 1.5, 1.0], "material": "subsurface",
            "params": {"color": [0.9, 0.9, 0.9], "radius": 0.05, "falloff": [1.0, 1.0, 1.0],
                       "transmission": transmission, "specular_intensity": 0.0}}
    scene = {"size": list(size), "tonemap": "none", "background": [0, 0, 0],
             "camera": {"position": [0.0, 2.5, 0.0], "target": [0.0, 0.0, 0.0],
                        "up": [0.0, 0.0, -1.0], "fov": 20.0},
             "object": [slab],
             "light": [{"type": "directional", "direction": [0.0, 1.0, 0.0], "intensity": 1.0,
                        "shadows": True, "shadow_resolution": 2048}]}
    image = render(gl, scene)
    return image[16:32, 16:32].mean((0, 1))


def test_light_goes_through_thin_parts_by_the_profiles_transmittance(gl):
    """A slab lit from behind shows the light through it: none without transmission, and from
    two thicknesses in the ratio of the profile's transmittance at them (within 10%)."""
    thin, thick = 0.02, 0.08
    assert np.all(slab_brightness(gl, thin, transmission=0.0) < 1e-4)
    a, b = slab_brightness(gl, thin), slab_brightness(gl, thick)
    d = float(profile_shape(0.05, 0.9))
    assert a[0] > 0.05
    np.testing.assert_allclose(b / a, transmittance(thick, d) / transmittance(thin, d),
                               rtol=0.1)
    # the light arriving: the albedo times the transmittance (the back faces the light)
    np.testing.assert_allclose(a, 0.9 * transmittance(thin, d), rtol=0.15)


@pytest.mark.parametrize("light_path", ["volumes", "tiled", "clustered"])
def test_forward_and_deferred_agree(gl, light_path):
    """The bunny in subsurface beside a standard one, lit by a shadowed directional light (its
    light through the ears), a point and a rect light: forward within 40 dB of deferred."""
    if light_path != "volumes" and not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    scene = {"size": [160, 120], "tonemap": "none",
             "camera": {"position": [0.0, 0.7, 2.2], "target": [0.0, 0.4, 0.0], "fov": 45.0},
             "object": [{"mesh": "builtin:plane", "scale": 3.0},
                        {"mesh": "examples/meshes/bunny.ply", "position": [-0.35, 0.0, 0.0],
                         "scale": 0.6, "material": "subsurface", "params": {"radius": 0.03}},
                        {"mesh": "examples/meshes/bunny.ply", "position": [0.4, 0.0, 0.0],
                         "scale": 0.6, "material": "subsurface",
                         "params": {"radius": 0.01, "color": [0.6, 0.8, 0.6]}}],
             "light": [{"type": "directional", "direction": [0.3, -0.4, 1.0], "intensity": 2.0,
                        "shadows": True},
                       {"type": "point", "position": [1.0, 1.0, 1.0], "intensity": 2.0,
                        "radius": 5.0},
                       {"type": "rect", "position": [-1.0, 1.2, 1.0],
                        "direction": [0.6, -0.5, -0.6], "size": [0.6, 0.4], "intensity": 2.0,
                        "radius": 5.0},
                       {"type": "ambient", "intensity": 0.1}]}
    deferred = render(gl, scene, "deferred", light_path)
    forward = render(gl, scene, "forward", "tiled" if light_path != "volumes" else "naive")
    peak = float(deferred.max())
    assert psnr(np.clip(deferred / peak, 0, 1), np.clip(forward / peak, 0, 1)) >= 40.0


@pytest.mark.parametrize("params", [{"radius": 3e-151}, {"falloff": [1.0, 0.0, 0.0]}])
def test_a_profile_too_narrow_to_scatter_renders_finite_in_both_pipelines(gl, params):
    """A mean free path (or a channel's falloff) too small for the profile's rounding scatters
    nowhere: a finite image, in either pipeline, not a division by zero (found by the schema
    fuzz test: radius 3e-151 gave NaN pixels)."""
    scene = edge_scene("subsurface", {**params, "transmission": 1.0}, size=(48, 16))
    for pipeline in ("deferred", "forward"):
        image = render(gl, scene, pipeline)
        assert np.isfinite(image).all() and image.max() > 0.1, pipeline


def test_the_cost_model_counts_the_blur_over_the_pixels_covered():
    from deferred.interfaces.work import RenderWork, Screen, WorkObject
    from deferred.materials.subsurface import BLUR_PIXEL_SECONDS, SubsurfaceMaterial

    material = SubsurfaceMaterial()
    unseen = WorkObject(material, 1000, "bunny", "s.toml: object[0]")
    assert len(material.work(unseen, RenderWork((640, 360)))) == 1  # bounds not known yet
    screen = Screen(distance=10.0, radius=10.0, focal_pixels=500.0)  # the camera inside it
    seen = WorkObject(material, 1000, "bunny", "s.toml: object[0]", screen=screen)
    deferred, blur = material.work(seen, RenderWork((640, 360)))
    assert blur.seconds == pytest.approx(2 * 640 * 360 * BLUR_PIXEL_SECONDS)
    assert blur.where == "s.toml: object[0].params.radius"
    forward, _ = material.work(seen, RenderWork((640, 360), pipeline="forward"))
    assert forward.units == 2 * deferred.units  # the mask pass draws the mesh again
