"""The shadow atlas kept from frame to frame (deferred.lighting.shadows.caster_pass): a map
whose light, square and casters are as they were is not drawn again, and the image is the one
a new renderer draws for the same frame; a caster that moves moves its shadow; casters outside
a map's frustum are not drawn into it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from deferred.lighting.shadows.atlas import ShadowTile, frustum_planes
from deferred.lighting.shadows.frusta import spot_frustum
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

PLAIN = {"specular_intensity": 0.0, "color": [0.5, 0.5, 0.5]}
CAMERA = {"position": [0.0, 5.0, 0.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
          "fov": 40.0, "near": 0.1, "far": 30.0}
SPOT = {"type": "spot", "position": [0.0, 3.0, 0.0], "direction": [0.0, -1.0, 0.0],
        "radius": 12.0, "intensity": 30.0, "inner_angle": 30.0, "outer_angle": 35.0,
        "shadow_resolution": 256, "shadows": True}
SUN = {"type": "directional", "direction": [-0.5, -1.0, -0.3], "intensity": 2.0,
       "cascades": 3, "shadow_resolution": 512, "shadow_distance": 10.0, "shadows": True}


def scene(light: dict, cube_at=(0.0, 1.0, 0.0), far_cube: bool = False):
    objects = [{"mesh": "builtin:plane", "scale": 8.0, "params": PLAIN},
               {"mesh": "builtin:cube", "position": list(cube_at), "scale": 0.4,
                "params": PLAIN}]
    if far_cube:  # within the spot's reach, outside its cone
        objects.append({"mesh": "builtin:cube", "position": [6.0, 1.0, 0.0], "scale": 0.4,
                        "params": PLAIN})
    return scene_from_dict({"size": [96, 72], "tonemap": "none", "camera": CAMERA,
                            "object": objects, "light": [
                                {"type": "ambient", "color": [0.2, 0.2, 0.2]}, light]})


def shadow_draws(renderer: Renderer) -> int:
    return renderer.last_frame.stats.draws_by_pass.get("shadows", 0)


@pytest.mark.parametrize("light", [SPOT, SUN], ids=["spot", "cascades"])
@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_a_kept_map_gives_the_image_a_new_renderer_draws(gl, light, pipeline):
    the_scene = scene(light)
    with Renderer(the_scene, pipeline, gl=gl) as renderer:
        first = renderer.render(hdr=True)
        assert shadow_draws(renderer) > 0
        again = renderer.render(hdr=True)  # nothing changed: no map drawn again
        assert shadow_draws(renderer) == 0
        np.testing.assert_array_equal(again.hdr, first.hdr)
        # the camera moves: a spot's map is kept, cascades follow the camera
        the_scene.camera = replace(the_scene.camera, position=(0.3, 5.0, 0.2))
        moved = renderer.render(hdr=True)
        assert (shadow_draws(renderer) == 0) == (light is SPOT)
    with Renderer(the_scene, pipeline, gl=gl) as fresh:
        np.testing.assert_array_equal(fresh.render(hdr=True).hdr, moved.hdr)


def shadow_centre(gl, light: dict, cube_at) -> float:
    """The x (pixels) of the middle of the cube's shadow on the floor, from a renderer's
    image and the same scene unshadowed."""
    with Renderer(scene({**light, "shadows": False}, cube_at), "deferred", gl=gl) as plain:
        unshadowed = plain.render(hdr=True).hdr[..., :3].sum(axis=-1)
    with Renderer(scene(light, cube_at), "deferred", gl=gl) as fresh:
        shadowed = fresh.render(hdr=True).hdr[..., :3].sum(axis=-1)
    mask = unshadowed - shadowed > 0.1
    assert mask.sum() > 20
    return float(np.nonzero(mask)[1].mean())


@pytest.mark.parametrize("light", [SPOT, SUN], ids=["spot", "cascades"])
def test_a_moving_caster_moves_its_shadow(gl, light):
    the_scene = scene(light, cube_at=(-0.6, 1.0, 0.0))
    with Renderer(the_scene, "deferred", gl=gl) as renderer:
        before = renderer.render(hdr=True).hdr
        the_scene.objects[1].position = (0.6, 1.0, 0.0)
        after = renderer.render(hdr=True).hdr
        assert shadow_draws(renderer) > 0
    with Renderer(scene(light, cube_at=(0.6, 1.0, 0.0)), "deferred", gl=gl) as fresh:
        np.testing.assert_array_equal(after, fresh.render(hdr=True).hdr)
    with Renderer(scene(light, cube_at=(-0.6, 1.0, 0.0)), "deferred", gl=gl) as fresh:
        np.testing.assert_array_equal(before, fresh.render(hdr=True).hdr)
    # the shadow went right with the cube, by about its move (1.2 of the floor's 3.6 in view)
    moved = shadow_centre(gl, light, (0.6, 1.0, 0.0)) - \
        shadow_centre(gl, light, (-0.6, 1.0, 0.0))
    assert moved > 15


def test_casters_outside_a_spot_frustum_are_not_drawn(gl):
    with Renderer(scene(SPOT), "deferred", gl=gl) as renderer:
        renderer.render()
        alone = shadow_draws(renderer)
        image = renderer.render(hdr=True, time=0.0).hdr
    with Renderer(scene(SPOT, far_cube=True), "deferred", gl=gl) as renderer:
        result = renderer.render(hdr=True)
        assert shadow_draws(renderer) == alone  # the far cube: in reach, out of the cone
        tile = renderer.shadow_atlas.tiles[0]
        assert not tile.casts(np.array([6.0, 1.0, 0.0]), 0.6)
        assert tile.casts(np.array([0.0, 1.0, 0.0]), 0.6)
        assert result.hdr.shape == image.shape


def test_frustum_planes_bound_a_spot_map():
    from deferred.scene.loader import scene_from_dict as load

    light = load({"object": [], "light": [SPOT]}).lights[0]
    _, view, projection, *_ = spot_frustum(light, 256)
    planes = frustum_planes(projection @ view)
    inside = np.array([0.0, 1.0, 0.0, 1.0])  # under the light, on its axis
    assert (planes @ inside > 0).all()
    below_far = np.array([0.0, 3.0 - 12.5, 0.0, 1.0])  # past its radius
    assert (planes @ below_far).min() < 0
    assert ShadowTile.casts.__doc__
