"""The pbr material's textures: KHR_texture_transform, UV sets and wrap modes where numpy
predicts them; every texture, alpha mode, an environment and shadows, forward against deferred;
bad texture parameters refused naming the key."""

import numpy as np
import pytest
from conftest import psnr
from plane_reference import plane_points

from deferred.errors import InputError
from deferred.io.images import write_image
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

TOP = {"position": [0.0, 4.0, 0.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
       "fov": 40.0}
SIZE = (96, 96)
QUADRANTS = np.array([[[1, 0, 0], [0, 1, 0]], [[0, 0, 1], [1, 1, 0]]], np.float32)


def write_png(path, rgb):
    """An 8-bit RGBA image, top row first."""
    rgba = np.ones((*rgb.shape[:2], 4), np.float32)
    rgba[..., :3] = rgb
    write_image(path, (rgba * 255 + 0.5).astype(np.uint8), channels=("R", "G", "B", "A"))
    return str(path)


def render(gl, scene, pipeline="deferred", hdr=True):
    renderer = Renderer(scene, pipeline, gl=gl)
    try:
        result = renderer.render(hdr=hdr)
        return result.hdr[..., :3] if hdr else result.image[..., :3]
    finally:
        renderer.release()


def quadrant_plane(texture, uv1=False):
    return scene_from_dict({
        "size": list(SIZE), "tonemap": "none", "background": [0.0, 0.0, 0.0], "camera": TOP,
        "object": [{"mesh": "builtin:plane", "material": "pbr",
                    "params": {"base_color": [0.0, 0.0, 0.0], "emissive": [1.0, 1.0, 1.0],
                               "emissive_texture": texture}}]})


def expected(scene, transform):
    """The quadrant each pixel shows, from the plane's UVs through the transform (glTF's
    space: v down), repeated or mirrored."""
    points = plane_points(scene, SIZE)[::-1]  # top row first
    u = points[..., 0] / 2.0 + 0.5
    v = 0.5 - points[..., 2] / 2.0
    s, t = u, 1.0 - v  # glTF's texture space
    c, n = np.cos(transform["rotation"]), np.sin(transform["rotation"])
    (sx, sy), (ox, oy) = transform["scale"], transform["offset"]
    s, t = c * sx * s + n * sy * t + ox, -n * sx * s + c * sy * t + oy
    if transform.get("wrap_s") == "mirrored_repeat":
        s = 1.0 - np.abs(np.mod(s, 2.0) - 1.0)
    rows = np.floor(np.mod(t, 1.0) * 2).astype(int)
    columns = np.floor(np.mod(s, 1.0) * 2).astype(int)
    fraction_s, fraction_t = np.mod(s * 2, 1.0), np.mod(t * 2, 1.0)
    clear = (np.minimum(fraction_s, 1 - fraction_s) > 0.08) & \
        (np.minimum(fraction_t, 1 - fraction_t) > 0.08) & \
        (np.abs(points[..., 0]) < 0.95) & (np.abs(points[..., 2]) < 0.95)
    return QUADRANTS[rows, columns], clear


@pytest.mark.parametrize("transform", [
    {"offset": [0.0, 0.0], "rotation": 0.0, "scale": [1.0, 1.0]},
    {"offset": [0.25, 0.1], "rotation": 0.0, "scale": [2.0, 1.5]},
    {"offset": [0.5, -0.2], "rotation": 0.6, "scale": [1.5, 1.5]},
    {"offset": [0.0, 0.0], "rotation": 0.0, "scale": [2.5, 1.0],
     "wrap_s": "mirrored_repeat"},
])
def test_texture_transform_where_numpy_puts_it(gl, tmp_path, transform):
    path = write_png(tmp_path / "quadrants.png", QUADRANTS)
    texture = {"path": path, "mag_filter": "nearest", "min_filter": "nearest", **transform}
    scene = quadrant_plane(texture)
    image = render(gl, scene)
    want, clear = expected(scene, transform)
    assert clear.sum() > 1000
    np.testing.assert_allclose(image[clear], want[clear], atol=1e-3)


def test_second_uv_set_and_clamped_wrap(gl, tmp_path):
    """uv = 1 reads the mesh's second set (the first where it has none: the same image);
    clamp_to_edge holds the edge texels beyond [0, 1]."""
    path = write_png(tmp_path / "quadrants.png", QUADRANTS)
    base = {"path": path, "mag_filter": "nearest", "min_filter": "nearest",
            "scale": [3.0, 1.0], "offset": [-1.0, 0.0]}
    first = render(gl, quadrant_plane({**base, "uv": 0, "wrap_s": "clamp_to_edge"}))
    second = render(gl, quadrant_plane({**base, "uv": 1, "wrap_s": "clamp_to_edge"}))
    np.testing.assert_array_equal(first, second)
    points = plane_points(quadrant_plane(base), SIZE)[::-1]
    on_plane = (np.abs(points[..., 0]) < 0.95) & (np.abs(points[..., 2]) < 0.95)
    s = (points[..., 0] / 2.0 + 0.5) * 3.0 - 1.0
    top = on_plane & (points[..., 2] < -0.1)  # the image's top row of quadrants
    left, right = top & (s < -0.1), top & (s > 1.1)
    assert left.sum() > 100 and right.sum() > 100
    # beyond the left edge the first column's texel (red), beyond the right the second's
    np.testing.assert_allclose(first[left], np.tile([1.0, 0.0, 0.0], (left.sum(), 1)),
                               atol=1e-3)
    np.testing.assert_allclose(first[right], np.tile([0.0, 1.0, 0.0], (right.sum(), 1)),
                               atol=1e-3)


def every_texture(tmp_path):
    rng = np.random.default_rng(5)
    size = 32
    yy, xx = np.meshgrid(np.arange(size), np.arange(size), indexing="ij")
    checker = ((xx // 8 + yy // 8) % 2)[..., None] * np.array([0.7, 0.5, 0.2]) + 0.2
    bumps = np.stack([0.5 + 0.3 * np.sin(xx / 3.0), 0.5 + 0.3 * np.cos(yy / 4.0),
                      np.ones((size, size))], -1)
    bumps[..., 2] = np.sqrt(np.clip(1.0 - ((bumps[..., 0] - 0.5) * 2) ** 2 -
                                    ((bumps[..., 1] - 0.5) * 2) ** 2, 0.0, 1.0)) * 0.5 + 0.5
    metal_rough = np.stack([np.zeros((size, size)), 0.2 + 0.7 * xx / size, yy / size], -1)
    occlusion = np.repeat((0.5 + 0.5 * rng.random((size, size)))[..., None], 3, -1)
    glow = np.where(((xx - 16) ** 2 + (yy - 16) ** 2 < 20)[..., None], 1.0, 0.0) * \
        np.array([1.0, 0.6, 0.2])
    return {name: write_png(tmp_path / f"{name}.png", pixels.astype(np.float32))
            for name, pixels in (("base", checker), ("normal", bumps),
                                 ("metal_rough", metal_rough), ("occlusion", occlusion),
                                 ("glow", glow))}


def test_every_feature_forward_agrees_with_deferred(gl, tmp_path):
    files = every_texture(tmp_path)
    textured = {"base_color_texture": files["base"], "normal_texture": files["normal"],
                "metallic_roughness_texture": {"path": files["metal_rough"], "uv": 1},
                "occlusion_texture": files["occlusion"],
                "emissive_texture": {"path": files["glow"], "scale": [2.0, 2.0]},
                "emissive": [2.0, 2.0, 2.0], "normal_scale": 0.8}
    scene = scene_from_dict({
        "size": [160, 120], "background": "environment",
        "camera": {"position": [0.0, 1.6, 4.2], "target": [0.0, 0.2, 0.0], "fov": 45.0},
        "object": [
            {"mesh": "builtin:sphere", "material": "pbr", "position": [-1.0, 0.3, 0.0],
             "scale": 0.6, "params": textured},
            {"mesh": "builtin:torus", "material": "pbr", "position": [0.6, 0.3, 0.2],
             "params": {"base_color": [0.9, 0.7, 0.3], "metallic": 1.0, "roughness": 0.3}},
            {"mesh": "builtin:plane", "material": "pbr", "scale": 3.0,
             "params": {"base_color": [0.6, 0.6, 0.6], "roughness": 0.8, "metallic": 0.0}},
            {"mesh": "builtin:plane", "material": "pbr", "position": [0.4, 0.6, 1.0],
             "rotation": [70.0, 0.0, 0.0], "scale": 0.4,
             "params": {"alpha_mode": "mask", "double_sided": True,
                        "base_color_texture": files["occlusion"], "alpha_cutoff": 0.5}},
            {"mesh": "builtin:sphere", "material": "pbr", "position": [0.0, 0.4, 1.2],
             "scale": 0.35,
             "params": {"alpha_mode": "blend", "base_color": [0.2, 0.5, 0.9, 0.4],
                        "roughness": 0.2, "metallic": 0.0}},
            {"mesh": "builtin:cube", "material": "standard", "position": [1.5, 0.3, -0.8],
             "scale": 0.4}],
        "light": [{"type": "environment", "intensity": 0.6},
                  {"type": "directional", "direction": [-0.4, -1.0, -0.5], "intensity": 2.0,
                   "shadows": True}]})
    deferred = render(gl, scene, "deferred", hdr=False).astype(np.float64)
    forward = render(gl, scene, "forward", hdr=False).astype(np.float64)
    assert deferred.std() > 20.0  # a scene, not a blank
    assert psnr(deferred, forward, 255.0) >= 40.0


def test_bad_texture_parameters_name_the_key(tmp_path):
    with pytest.raises(InputError, match=r"base_color_texture"):
        scene_from_dict({"object": [{"mesh": "builtin:plane", "material": "pbr", "params": {
            "base_color_texture": "missing.png"}}]}, base_dir=tmp_path)
    with pytest.raises(InputError, match=r"normal_texture"):
        scene_from_dict({"object": [{"mesh": "builtin:plane", "material": "pbr", "params": {
            "normal_texture": {"path": "n.png", "wrap_s": "sideways"}}}]}, base_dir=tmp_path)
    with pytest.raises(InputError, match=r"alpha_mode"):
        scene_from_dict({"object": [{"mesh": "builtin:plane", "material": "pbr", "params": {
            "alpha_mode": "cutout"}}]})


def test_mesh_second_uv_set_and_vertex_colours(gl, tmp_path):
    """A mesh's own second UV set (here the first turned half a turn: what a transform of
    rotation pi and offset (1, 1) does to the first) and its vertex colours (multiplying the
    base colour as base_color does) reach the surface."""
    from dataclasses import fields

    from deferred.scene.builtin_meshes import builtin_plane

    path = write_png(tmp_path / "quadrants.png", QUADRANTS)
    texture = {"path": path, "mag_filter": "nearest", "min_filter": "nearest"}
    plane = builtin_plane()
    values = {field.name: getattr(plane, field.name) for field in fields(plane)}

    def lit(mesh, base_color, base_texture):
        scene = quadrant_plane(texture)
        scene.objects[0].mesh = mesh
        scene.objects[0].material.params = scene.objects[0].material.params.model_copy(
            update={"emissive": [0.0, 0.0, 0.0], "emissive_texture": None, "metallic": 0.0,
                    "base_color": base_color, "base_color_texture": base_texture})
        scene.add_light("directional", direction=[0.3, -1.0, 0.2])
        return render(gl, scene)

    halves = np.where(plane.positions[:, :1] < 0.0, [[1.0, 1.0, 1.0, 1.0]],
                      [[0.4, 0.7, 1.0, 1.0]]).astype(np.float32)
    turned = type(plane)(**{**values, "uv1": (1.0 - plane.uvs).astype(np.float32),
                            "colors": halves})
    second = lit(turned, [1.0, 1.0, 1.0], {**texture, "uv": 1})
    transformed = lit(turned, [1.0, 1.0, 1.0], {**texture, "uv": 0, "rotation": np.pi,
                                                 "offset": [1.0, 1.0]})
    first = lit(turned, [1.0, 1.0, 1.0], {**texture, "uv": 0})
    np.testing.assert_allclose(second, transformed, atol=2e-3)
    assert np.abs(second - first).max() > 0.2  # the second set is not the first
    grey = type(plane)(**{**values, "colors": np.full_like(halves, 0.5)})
    np.testing.assert_allclose(lit(grey, [1.0, 1.0, 1.0], None),
                               lit(plane, [0.5, 0.5, 0.5], None), atol=2e-3)
