"""Shadow maps sized by screen coverage (deferred.lighting.shadows.coverage, ``[shadows]
allocation = "coverage"``): the projected rectangle of a sphere against points sampled on it;
a light covering a small part of the screen gets a smaller map than one covering the view,
and its shadow still darkens where the full map's does; sizes hold under a small camera move
where the viewer asks (and follow the frame alone where not); more lights than fit at full
size all get maps, and their shadows."""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np
import pytest

from deferred.lighting.shadows.atlas import ShadowAtlas
from deferred.lighting.shadows.coverage import (
    MIN_TILE,
    fit_sizes,
    map_size,
    screen_coverage,
)
from deferred.render.renderer import Renderer
from deferred.scene.camera import Camera
from deferred.scene.loader import scene_from_dict

W, H = 192, 144
PLAIN = {"specular_intensity": 0.0, "color": [0.5, 0.5, 0.5]}
CAMERA = {"position": [0.0, 6.0, 0.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
          "fov": 40.0, "near": 0.1, "far": 30.0}
# covers the whole view: straight down from above the floor's centre
WIDE = {"type": "spot", "position": [-0.3, 4.0, -0.2], "direction": [0.1, -1.0, 0.05],
        "radius": 12.0, "intensity": 20.0, "inner_angle": 55.0, "outer_angle": 65.0,
        "shadow_resolution": 512, "shadows": True}
# a small pool of light in a corner of the view, over a small cube
SMALL = {"type": "spot", "position": [2.0, 1.5, 1.0], "direction": [0.3, -1.0, 0.0],
         "radius": 2.0, "intensity": 6.0, "inner_angle": 30.0, "outer_angle": 40.0,
         "shadow_resolution": 512, "shadows": True}
AMBIENT = {"type": "ambient", "color": [0.05, 0.05, 0.05], "ground": [0.05, 0.05, 0.05]}


def scene(lights: list[dict], allocation: str = "coverage", cubes=((0.0, 0.0), (2.3, 1.0)),
          **shadows):
    objects = [{"mesh": "builtin:plane", "scale": 8.0, "params": PLAIN}]
    objects += [{"mesh": "builtin:cube", "position": [x, 0.2, z], "scale": 0.2,
                 "params": PLAIN} for x, z in cubes]
    return scene_from_dict({"size": [W, H], "tonemap": "none", "camera": CAMERA,
                            "shadows": {"allocation": allocation, **shadows},
                            "object": objects, "light": [AMBIENT, *lights]})


def render(gl, the_scene, pipeline="deferred"):
    with Renderer(the_scene, pipeline, gl=gl) as renderer:
        image = renderer.render(hdr=True).hdr[..., :3].astype(np.float64)
        atlas = renderer.shadow_atlas
        if atlas is None:
            return image, [], {}
        sizes = {id(tile.light): tile.size for tile in atlas.tiles}
        return image, [sizes.get(id(light)) for light in the_scene.lights], atlas.slots


def sampled_coverage(centre, radius, view, projection) -> float:
    """The clipped screen rectangle of points sampled densely on the sphere."""
    theta, phi = np.meshgrid(np.linspace(0.0, np.pi, 400), np.linspace(0.0, 2 * np.pi, 800))
    points = np.stack([np.sin(theta) * np.cos(phi), np.cos(theta),
                       np.sin(theta) * np.sin(phi)], -1).reshape(-1, 3) * radius + centre
    clip = projection @ view @ np.c_[points, np.ones(len(points))].T
    ndc = np.clip(clip[:2] / clip[3], -1.0, 1.0)
    return float(np.prod(ndc.max(axis=1) - ndc.min(axis=1)) / 4.0)


@pytest.mark.parametrize(("centre", "radius"), [
    ((0.0, 0.0, -5.0), 0.5), ((1.5, -0.8, -4.0), 0.7), ((3.2, 0.0, -3.0), 1.0),
    ((0.0, 0.0, -2.0), 4.0)])
def test_screen_coverage_is_the_sampled_spheres_rectangle(centre, radius):
    camera = Camera((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0), 50.0, 0.1, 100.0)
    view, projection = camera.view(), camera.projection(16 / 9)
    centre = np.asarray(centre)
    got = screen_coverage(centre[None], np.array([radius]), view, projection)[0]
    want = 1.0 if radius >= -centre[2] else sampled_coverage(centre, radius, view, projection)
    assert got == pytest.approx(want, rel=0.01, abs=1e-4)
    # a box around only part of the sphere narrows it; one beyond it leaves nothing
    part = screen_coverage(centre[None], np.array([radius]), view, projection,
                           (centre - radius, centre + (0.0, 0.0, radius)))[0]
    assert part <= got + 1e-12
    assert screen_coverage(centre[None], np.array([radius]), view, projection,
                           (centre + radius + 1.0, centre + radius + 2.0))[0] == 0.0


def test_map_sizes_follow_coverage_with_a_margin_before_shrinking():
    assert map_size(1024, 1.0) == 1024
    assert map_size(1024, 0.25) == 512 and map_size(1024, 0.26) == 1024
    assert map_size(1024, 0.05) == 256  # 1024 x 0.22 = 229, rounded up
    assert map_size(1024, 1e-6) == MIN_TILE and map_size(1024, 0.0) == 0
    # held: kept until the need falls half a power of two below the smaller size
    assert map_size(1024, 0.24, previous=1024) == 1024
    low = (2.0 ** -0.5 / 2.0) ** 2  # 1024 x sqrt(low) = 256 x sqrt(2)
    assert map_size(1024, low * 1.01, previous=1024) == 1024
    assert map_size(1024, low * 0.99, previous=1024) == 512
    assert map_size(1024, 0.3, previous=256) == 1024  # grows at once


def test_maps_over_the_region_shrink_largest_and_least_covering_first():
    requests = [(1, 1, 1024, 1.0), (2, 6, 512, 0.5), (3, 1, 1024, 0.4), (4, 1, 256, 0.01)]
    sides = fit_sizes(requests, 1024)
    assert sum(maps * sides[key] ** 2 for key, maps, _, _ in requests) <= 1024 ** 2
    assert sides[3] < sides[1]  # of two equal maps, the one covering less shrinks
    assert all(side >= MIN_TILE for side in sides.values())
    assert fit_sizes(requests[:1], 1024) == {1: 1024}


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_a_light_covering_little_of_the_screen_gets_a_smaller_map_and_still_shadows(gl,
                                                                                    pipeline):
    lights = [WIDE, SMALL]
    coverage, (_, wide, small), _ = render(gl, scene(lights), pipeline)
    assert wide == 512 and small is not None and small < wide
    fixed, sizes, _ = render(gl, scene(lights, "fixed"), pipeline)
    assert sizes[1:] == [512, 512]
    bare, _, _ = render(gl, scene(lights, cubes=[(0.0, 0.0)]), pipeline)
    # the small cube's shadow: where the full map darkens the floor under the small light
    shade = fixed.sum(-1) < 0.5 * bare.sum(-1)
    near = np.zeros_like(shade)
    near[:, W // 2:] = True  # the small light's half of the view (the wide cube is central)
    shadow = shade & near
    assert shadow.sum() >= 15, shadow.sum()
    darkened = coverage.sum(-1) < 0.5 * bare.sum(-1)
    assert (darkened & shadow).sum() >= 0.8 * shadow.sum()
    assert (darkened & near).sum() <= 1.25 * shadow.sum()
    assert np.abs(coverage - fixed).mean() < 0.01 * fixed.mean()


def dolly(the_scene, distance: float):
    the_scene.camera = replace(the_scene.camera, position=(0.0, distance, 0.0))


def sizes_at(atlas, the_scene, distance: float, hold: bool) -> int:
    dolly(the_scene, distance)
    camera = the_scene.camera
    atlas.update(the_scene, camera.view(), W / H, camera.projection(W / H), hold_sizes=hold)
    return atlas.sizes[id(the_scene.lights[1])]


def test_sizes_hold_under_a_small_camera_move_where_the_viewer_asks(gl):
    """The camera rises to where the small light's map halves (found by bisection on the
    frame alone): moving back and forth a hair about that height keeps the size where sizes
    are held (the viewer), and follows each frame where not (renders)."""
    the_scene = scene([SMALL])
    atlas = ShadowAtlas(gl.ctx, 1024, 4, allocation="coverage")
    try:
        low, high = 6.0, 6.0
        big = sizes_at(atlas, the_scene, low, False)
        while sizes_at(atlas, the_scene, high, False) == big:
            high *= 1.5
        for _ in range(30):
            middle = (low + high) / 2.0
            low, high = (middle, high) if sizes_at(atlas, the_scene, middle, False) == big \
                else (low, middle)
        below, above = low - 0.01, high + 0.01
        assert sizes_at(atlas, the_scene, above, False) == big // 2
        sizes_at(atlas, the_scene, below, True)
        held = [sizes_at(atlas, the_scene, d, True) for d in (above, below, above, below)]
        assert held == [big] * 4
        free = [sizes_at(atlas, the_scene, d, False) for d in (above, below, above)]
        assert free == [big // 2, big, big // 2]
    finally:
        atlas.release()


def test_a_frame_depends_on_its_own_view_only(gl):
    """Rendered frames (sizes not held): a frame after others is the frame a new renderer
    draws."""
    the_scene = scene([WIDE, SMALL])
    with Renderer(the_scene, gl=gl) as renderer:
        for distance in (5.0, 9.0, 14.0, 7.0):
            dolly(the_scene, distance)
            last = renderer.render(hdr=True).hdr
    with Renderer(the_scene, gl=gl) as fresh:
        np.testing.assert_array_equal(fresh.render(hdr=True).hdr, last)


def test_more_lights_than_fit_at_full_size_all_get_shadows(gl):
    """Eight spots of 512^2 over eight cubes, in a 512^2 atlas: fixed maps give one light its
    map and leave seven unshadowed (with a warning); maps by coverage give every light one,
    and the image is the one of a large atlas with every map at full size."""
    cubes = [(-2.0 + 1.3 * (k % 4), -1.0 + 2.0 * (k // 4)) for k in range(8)]
    spots = [{**SMALL, "position": [x - 0.3, 1.5, z], "radius": 4.0, "outer_angle": 35.0,
              "inner_angle": 30.0, "intensity": 3.0} for x, z in cubes]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _, _, fixed_slots = render(gl, scene(spots, "fixed", cubes, atlas_size=512))
        assert len(fixed_slots) == 1 and any("unshadowed" in str(w.message) for w in caught)
        caught.clear()
        image, sizes, slots = render(gl, scene(spots, "coverage", cubes, atlas_size=512))
        assert not [w for w in caught if "unshadowed" in str(w.message)]
    assert len(slots) == 8 and all(sizes[1:])
    assert sum(size * size for size in sizes[1:]) <= 512 * 512
    full, full_sizes, _ = render(gl, scene(spots, "fixed", cubes, atlas_size=4096))
    unshadowed, _, _ = render(gl, scene([{**s, "shadows": False} for s in spots], "fixed",
                                        cubes))
    assert full_sizes[1:] == [512] * 8
    shadowed = full.sum(-1) < 0.7 * unshadowed.sum(-1)  # every cube's shadow
    assert shadowed.sum() > 8 * 10
    assert (image.sum(-1)[shadowed] < 0.7 * unshadowed.sum(-1)[shadowed]).mean() > 0.85
    peak = float(full.max())
    psnr = 10.0 * math.log10(peak * peak / float(np.mean((image - full) ** 2)))
    assert psnr > 30.0, psnr


def test_info_lists_every_light_that_fits_with_smaller_maps():
    """``deferred info``'s shadow maps by coverage: as if each light covered the view, the
    maps halved to fit (fixed: one light placed, the rest unshadowed)."""
    from deferred.cli.scene_report import light_lines
    from deferred.scene.timeline import SceneEvaluator

    spots = [{**SMALL, "position": [float(x), 1.5, 0.0]} for x in range(8)]
    lines = {}
    for allocation in ("coverage", "fixed"):
        the_scene = scene(spots, allocation, atlas_size=512)
        lines[allocation] = light_lines(SceneEvaluator(the_scene).evaluate(0.0))
    assert "shadow maps: 8 of 8 shadowed lights in an atlas of 512x512 " \
           "(max_shadowed_lights = 16)" in lines["coverage"]
    assert not any("unshadowed" in line for line in lines["coverage"])
    assert "  light[1] spot: 1 tile of 256x256" in lines["coverage"]
    assert "shadow maps: 1 of 8 shadowed lights in an atlas of 512x512 " \
           "(max_shadowed_lights = 16)" in lines["fixed"]
