"""Area lights (rect, disc) by linearly transformed cosines: irradiance against a numerical
integration, the highlight's shape, the penumbra's width, every light path of both pipelines."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import psnr
from plane_reference import plane_points

from deferred.lights.rect import rotated_axes
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SIZE = (96, 72)
TOP_CAMERA = {"position": [0.0, 4.0, 0.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
              "fov": 60.0}
PATHS = [("deferred", "volumes"), ("deferred", "tiled"), ("deferred", "clustered"),
         ("forward", "naive"), ("forward", "tiled")]


def render_hdr(gl, scene_dict, pipeline="deferred", light_path=None):
    scene = scene_from_dict(scene_dict)
    renderer = Renderer(scene, pipeline, gl=gl, light_path=light_path)
    try:
        return scene, renderer.render(hdr=True).hdr[::-1, :, :3].astype(np.float64)
    finally:
        renderer.release()


def plane_scene(light, params=None, material="standard", size=SIZE, camera=TOP_CAMERA,
                objects=()):
    return {"size": list(size), "tonemap": "none", "camera": camera, "background": [0, 0, 0],
            "object": [{"mesh": "builtin:plane", "scale": 8.0, "material": material,
                        "params": params or {"color": [1.0, 1.0, 1.0],
                                             "specular_intensity": 0.0}}, *objects],
            "light": [light]}


def area_irradiance(points, normal, centre, axis_x, axis_y, facing, inside, samples=80):
    """Irradiance per unit radiance at ``points`` (..., 3) from the one-sided emitter
    ``centre + s axis_x + t axis_y`` for s, t in [-1, 1] where ``inside(s, t)``, facing
    ``facing``: the midpoint rule over the emitter, cos cos / d^2 dA."""
    u = (np.arange(samples) + 0.5) / samples * 2.0 - 1.0
    s, t = np.meshgrid(u, u)
    keep = inside(s, t)
    emitters = centre + s[keep][:, None] * axis_x + t[keep][:, None] * axis_y  # (m, 3)
    area = 4.0 * np.linalg.norm(axis_x) * np.linalg.norm(axis_y) / samples ** 2
    flat = points.reshape(-1, 3)
    total = np.zeros(len(flat))
    for start in range(0, len(flat), 512):
        d = emitters[None, :, :] - flat[start:start + 512, None, :]
        distance = np.linalg.norm(d, axis=-1)
        w = d / distance[..., None]
        cos_receiver = np.clip(w @ normal, 0.0, None)
        cos_emitter = np.clip(-(w @ facing), 0.0, None)
        total[start:start + 512] = (cos_receiver * cos_emitter / distance ** 2).sum(1) * area
    return total.reshape(points.shape[:-1])


def window(points, centre, radius):
    d = np.linalg.norm(points - centre, axis=-1)
    return np.clip(1.0 - (d / radius) ** 4, 0.0, 1.0) ** 2


def tilted_light(kind):
    direction = np.array([0.35, -1.0, 0.2])
    return {"type": kind, "position": [0.2, 0.7, -0.1], "direction": direction.tolist(),
            "size": [0.9, 0.45] if kind == "rect" else [0.8, 0.5], "rotation": 20.0,
            "color": [1.0, 0.8, 0.6], "intensity": 2.0, "radius": 6.0}


@pytest.mark.parametrize("pipeline, light_path", PATHS)
def test_rect_irradiance_matches_numerical_integration(gl, pipeline, light_path):
    """A white Lambertian plane under a tilted rectangle: each pixel's light within 3% of the
    emitter integrated numerically (the clipped polygon's exact irradiance, by LTC's identity
    lobe), on every light path."""
    if light_path in ("tiled", "clustered") and not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    light = tilted_light("rect")
    scene, image = render_hdr(gl, plane_scene(light), pipeline, light_path)
    params = scene.lights[0].params
    points = plane_points(scene, SIZE)
    x, y = rotated_axes(params)
    centre = np.asarray(params.position)
    facing = np.asarray(params.direction) / np.linalg.norm(params.direction)
    irradiance = area_irradiance(points, np.array([0.0, 1.0, 0.0]), centre,
                                 x * params.size[0] / 2, y * params.size[1] / 2, facing,
                                 lambda s, t: np.ones_like(s, bool))
    want = irradiance * window(points, centre, params.radius)
    want = want[..., None] * np.array(params.color) * params.intensity
    lit = want[..., 0] > 0.02 * want[..., 0].max()
    assert lit.mean() > 0.3  # much of the frame is lit, the falloff well sampled
    np.testing.assert_allclose(image[lit], want[lit], rtol=0.03, atol=1e-3)
    dark = want[..., 0] == 0.0  # behind the emitter's plane
    assert dark.any() and np.all(image[dark] < 1e-3)


def test_disc_irradiance_matches_numerical_integration(gl):
    """The disc (an ellipse here) as its area's regular 12-gon: within 3% of the ellipse's
    integral."""
    light = tilted_light("disc")
    scene, image = render_hdr(gl, plane_scene(light))
    params = scene.lights[0].params
    points = plane_points(scene, SIZE)
    x, y = rotated_axes(params)
    centre = np.asarray(params.position)
    facing = np.asarray(params.direction) / np.linalg.norm(params.direction)
    irradiance = area_irradiance(points, np.array([0.0, 1.0, 0.0]), centre,
                                 x * params.size[0] / 2, y * params.size[1] / 2, facing,
                                 lambda s, t: s * s + t * t <= 1.0, samples=120)
    want = (irradiance * window(points, centre, params.radius))[..., None] * \
        np.array(params.color) * params.intensity
    lit = want[..., 0] > 0.02 * want[..., 0].max()
    np.testing.assert_allclose(image[lit], want[lit], rtol=0.03, atol=1e-3)


def mirror_mask(scene, size, centre, axis_x, axis_y):
    """Pixels whose view ray, mirrored by the plane y = 0, meets the rectangle."""
    points = plane_points(scene, size)
    eye = np.asarray(scene.camera.position, np.float64)
    d = points - eye
    d[..., 1] *= -1.0  # reflected off the plane
    normal = np.cross(axis_x, axis_y)
    t = ((centre - points) @ normal) / (d @ normal)
    hit = points + d * t[..., None] - centre
    s = hit @ axis_x / (axis_x @ axis_x)
    u = hit @ axis_y / (axis_y @ axis_y)
    return (t > 0) & (np.abs(s) <= 1.0) & (np.abs(u) <= 1.0)


@pytest.mark.parametrize("material, rotation", [("pbr", 0.0), ("pbr", 90.0),
                                                ("standard", 35.0)])
def test_highlight_has_the_rectangles_shape(gl, material, rotation):
    """On a glossy plane the highlight is the rectangle's mirror image: the pixels above half
    the highlight's peak overlap the mirrored rectangle (intersection over union > 0.7), and
    turning the light turns the highlight."""
    size = (128, 96)
    camera = {"position": [0.0, 1.6, 2.6], "target": [0.0, 0.0, -0.4], "fov": 50.0}
    light = {"type": "rect", "position": [0.0, 1.0, -1.2], "direction": [0.0, -1.0, 0.0],
             "size": [1.2, 0.3], "rotation": rotation, "intensity": 4.0, "radius": 20.0}
    # Blinn-Phong unnormalised: a sharp lobe returns little of the light, so more of it
    params = {"base_color": [0.05, 0.05, 0.05], "roughness": 0.12, "metallic": 0.0} \
        if material == "pbr" else {"color": [0.0, 0.0, 0.0], "specular_intensity": 1.0,
                                   "specular_exponent": 2048.0}
    if material == "standard":
        light["intensity"] = 40.0
    scene, image = render_hdr(gl, plane_scene(light, params, material, size, camera))
    light_params = scene.lights[0].params
    x, y = rotated_axes(light_params)
    mask = mirror_mask(scene, size, np.asarray(light_params.position),
                       x * light_params.size[0] / 2, y * light_params.size[1] / 2)
    luminance = image.mean(-1)
    bright = luminance > 0.5 * luminance.max()
    iou = (bright & mask).sum() / (bright | mask).sum()
    assert mask.sum() > 40 and iou > 0.7, iou


def penumbra_width(gl, light_size: float) -> float:
    """Pixels from 10% to 90% of the light across a straight shadow edge under a square light
    of side ``light_size`` (the row through the edge's middle, several rows averaged, as a
    fraction of the same frame unshadowed)."""
    size = (160, 48)
    camera = {"position": [0.0, 3.0, 0.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
              "fov": 40.0}
    wall = {"mesh": "builtin:cube", "position": [-1.5, 0.5, 0.0], "scale": [2.0, 0.05, 2.0],
            "params": {"color": [0.0, 0.0, 0.0], "specular_intensity": 0.0}}
    light = {"type": "rect", "position": [0.0, 1.5, 0.0], "direction": [0.0, -1.0, 0.0],
             "size": [light_size, light_size], "intensity": 1.0, "radius": 20.0,
             "shadows": True, "shadow_resolution": 1024}
    camera_below = dict(camera, position=[0.0, 0.45, 0.0])  # under the occluder
    lit = render_hdr(gl, plane_scene(dict(light, shadows=False), size=size,
                                     camera=camera_below))[1]
    shadowed = render_hdr(gl, plane_scene(light, size=size, camera=camera_below,
                                          objects=[wall]))[1]
    ratio = (shadowed[..., 0] / np.maximum(lit[..., 0], 1e-6))[16:32].mean(0)
    low, high = np.argmax(ratio > 0.1), np.argmax(ratio > 0.9)
    assert ratio[:10].max() < 0.1 and ratio[-10:].min() > 0.9
    return float(high - low)


def test_penumbra_widens_with_the_lights_size(gl):
    """A straight occluder edge 1 unit below the light, 0.5 above the floor: the penumbra the
    floor sees grows with the light's size (PCSS: from about s x 0.5 / 1 wide), and a small
    light still leaves a soft edge of a few pixels."""
    sizes = (0.1, 0.4, 1.0)
    widths = [penumbra_width(gl, s) for s in sizes]
    assert widths[0] < widths[1] < widths[2], widths
    assert widths[2] > 3.0 * widths[0], widths
    # geometry: a square's penumbra is s x 0.5 / 1.0 wide, its 10-90% span 80% of that;
    # the frame shows 48 / (2 x 0.45 tan 20 degrees) pixels a unit
    pixels_per_unit = 48.0 / (2.0 * 0.45 * np.tan(np.radians(20.0)))
    for s, width in zip(sizes, widths, strict=True):
        predicted = 0.8 * 0.5 * s * pixels_per_unit
        assert 0.7 < width / predicted < 1.6, (s, width, predicted)


@pytest.mark.parametrize("light_path", ["volumes", "tiled", "clustered"])
def test_forward_and_deferred_agree_with_shadowed_area_lights(gl, light_path):
    """standard, pbr and both furs (shell_fur's kajiya_kay and revie_fur's marschner: the
    area light as a point light along its vector irradiance) under a shadowed rect and a disc:
    forward and deferred within 40 dB on every deferred light path."""
    if light_path != "volumes" and not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    objects = [
        {"mesh": "builtin:plane", "scale": 6.0, "params": {"color": [0.7, 0.7, 0.7],
                                                           "specular_intensity": 0.5,
                                                           "specular_exponent": 60.0}},
        {"mesh": "builtin:sphere", "position": [-0.8, 0.5, 0.0], "scale": 0.5,
         "material": "pbr", "params": {"base_color": [0.8, 0.3, 0.2], "roughness": 0.3}},
        {"mesh": "builtin:sphere", "position": [0.8, 0.5, 0.0], "scale": 0.45,
         "material": "shell_fur"},
        {"mesh": "builtin:cube", "position": [0.0, 0.3, 0.6], "scale": 0.3,
         "material": "revie_fur", "params": {"shading": "marschner"}},
    ]
    scene = {"size": [128, 96], "camera": {"position": [0.0, 2.0, 3.5],
                                           "target": [0.0, 0.3, 0.0], "fov": 50.0},
             "object": objects,
             "light": [{"type": "rect", "position": [0.5, 2.0, 1.0],
                        "direction": [-0.2, -1.0, -0.4], "size": [1.0, 0.6],
                        "intensity": 3.0, "radius": 8.0, "shadows": True},
                       {"type": "disc", "position": [-1.5, 1.2, 0.5],
                        "direction": [1.0, -0.5, 0.0], "size": [0.5, 0.5],
                        "color": [0.4, 0.6, 1.0], "intensity": 4.0, "radius": 6.0},
                       {"type": "ambient", "intensity": 0.1}]}
    deferred = render_hdr(gl, scene, "deferred", light_path)[1]
    forward = render_hdr(gl, scene, "forward", "tiled" if light_path != "volumes" else None)[1]
    assert deferred.max() > 0.2 and np.isfinite(deferred).all() and np.isfinite(forward).all()
    peak = float(deferred.max())
    assert psnr(np.clip(deferred / peak, 0, 1), np.clip(forward / peak, 0, 1)) >= 40.0
