"""Each light type on a plane against a numpy reference of the same formula."""

import math

import numpy as np
import pytest
from plane_reference import plane_points

from deferred.gl.context import Features, GLContext
from deferred.lights.point import distance_falloff
from deferred.lights.spot import cone_falloff
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SIZE = (96, 72)
CAMERA = {"position": [0.0, 4.0, 0.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
          "fov": 60.0}


def blinn_phong(points, to_light, radiance, specular, exponent, camera):
    n = np.array([0.0, 1.0, 0.0])
    n_dot_l = np.clip(to_light @ n, 0.0, None)
    v = np.asarray(camera, dtype=np.float64) - points
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    h = to_light + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    spec = specular * np.clip(h @ n, 0.0, None) ** exponent
    return radiance * (n_dot_l * (1.0 + spec))[..., None] * (n_dot_l > 0)[..., None]


def render_plane(gl, light, pipeline, storage, specular=0.0, exponent=16.0):
    if storage and not gl.features.storage_buffers:
        pytest.skip("the driver has no GL 4.3 storage buffers")
    scene = scene_from_dict({
        "size": list(SIZE), "tonemap": "none", "camera": CAMERA,
        "object": [{"mesh": "builtin:plane", "scale": 8.0,
                    "params": {"color": [1.0, 1.0, 1.0], "specular_intensity": specular,
                               "specular_exponent": exponent}}],
        "light": [light]})
    context = GLContext(gl.ctx, Features(storage_buffers=storage, compute_shaders=False))
    renderer = Renderer(scene, pipeline, gl=context)
    try:
        hdr = renderer.render().hdr[::-1, :, :3]  # back to bottom row first
    finally:
        renderer.release()
    return scene, hdr


MODES = [("deferred", True), ("deferred", False), ("forward", True), ("forward", False)]


@pytest.mark.parametrize("pipeline, storage", MODES)
def test_point_light_falloff_reaches_zero_at_radius(gl, pipeline, storage):
    position = np.array([0.3, 1.0, -0.2])
    light = {"type": "point", "position": position.tolist(), "color": [1.0, 0.5, 0.25],
             "intensity": 3.0, "radius": 1.8}
    scene, image = render_plane(gl, light, pipeline, storage)
    points = plane_points(scene, SIZE)
    to_light = position - points
    d = np.linalg.norm(to_light, axis=-1)
    radiance = np.array([1.0, 0.5, 0.25]) * 3.0 * distance_falloff(d, 1.8)[..., None]
    want = blinn_phong(points, to_light / d[..., None], radiance, 0.0, 1.0, CAMERA["position"])
    np.testing.assert_allclose(image, want, rtol=1e-2, atol=2e-3)
    outside = d > 1.8
    assert outside.mean() > 0.2 and np.all(image[outside] == 0.0)
    assert np.all(image[d < 1.5][:, 0] > 0.0)


@pytest.mark.parametrize("pipeline, storage", MODES)
def test_spot_light_cone_against_numpy(gl, pipeline, storage):
    position = np.array([0.0, 1.5, 0.0])
    axis = np.array([0.3, -1.0, 0.1])
    axis /= np.linalg.norm(axis)
    light = {"type": "spot", "position": position.tolist(), "direction": axis.tolist(),
             "color": [0.2, 1.0, 0.6], "intensity": 4.0, "radius": 4.0,
             "inner_angle": 15.0, "outer_angle": 30.0}
    scene, image = render_plane(gl, light, pipeline, storage)
    points = plane_points(scene, SIZE)
    to_light = position - points
    d = np.linalg.norm(to_light, axis=-1)
    direction = to_light / d[..., None]
    cone = cone_falloff(-direction @ axis, math.cos(math.radians(30.0)),
                        math.cos(math.radians(15.0)))
    radiance = np.array([0.2, 1.0, 0.6]) * 4.0 * (distance_falloff(d, 4.0) * cone)[..., None]
    want = blinn_phong(points, direction, radiance, 0.0, 1.0, CAMERA["position"])
    np.testing.assert_allclose(image, want, rtol=1e-2, atol=2e-3)
    assert (cone == 0.0).mean() > 0.3 and np.all(image[cone == 0.0] == 0.0)
    assert (cone == 1.0).any() and ((cone > 0.0) & (cone < 1.0)).any()


@pytest.mark.parametrize("pipeline, storage", MODES)
def test_directional_light_with_blinn_phong_highlight(gl, pipeline, storage):
    direction = np.array([-0.3, -1.0, -0.2])
    light = {"type": "directional", "direction": direction.tolist(), "color": [1.0, 1.0, 1.0],
             "intensity": 0.8}
    scene, image = render_plane(gl, light, pipeline, storage, specular=0.5, exponent=24.0)
    points = plane_points(scene, SIZE)
    to_light = np.broadcast_to(-direction / np.linalg.norm(direction), points.shape)
    want = blinn_phong(points, to_light, np.array([0.8, 0.8, 0.8]), 0.5, 24.0,
                       CAMERA["position"])
    np.testing.assert_allclose(image, want, rtol=1e-2, atol=3e-3)
    assert want[..., 0].max() - want[..., 0].min() > 0.1  # the highlight is really there


@pytest.mark.parametrize("pipeline, storage", MODES)
def test_ambient_hemisphere(gl, pipeline, storage):
    light = {"type": "ambient", "color": [0.3, 0.4, 0.5], "ground": [0.9, 0.0, 0.0],
             "intensity": 2.0}
    _, image = render_plane(gl, light, pipeline, storage)
    # the plane faces straight up: pure sky colour
    np.testing.assert_allclose(image, np.broadcast_to([0.6, 0.8, 1.0], image.shape), atol=2e-3)
    light["up"] = [0.0, -1.0, 0.0]  # upside-down world: pure ground colour
    _, image = render_plane(gl, light, pipeline, storage)
    np.testing.assert_allclose(image, np.broadcast_to([1.8, 0.0, 0.0], image.shape), atol=2e-3)
