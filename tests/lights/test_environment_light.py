"""The environment light: the white furnace, the irradiance against a numpy projection of the
map on the spherical harmonics, a mirror showing a bright texel where the reflection predicts,
rotation, the disk cache and its refusals."""

import numpy as np
import pytest
from pbr_reference import interior, render_hdr, sphere_hits

from deferred.errors import InputError
from deferred.io.images import write_image
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SIZE = (96, 96)
CAMERA = {"position": [0.0, 0.0, 4.0], "target": [0.0, 0.0, 0.0], "fov": 35.0}
SPHERE = "builtin:sphere?segments=128&rings=64"


@pytest.fixture(autouse=True)
def cache(tmp_path, monkeypatch):
    folder = tmp_path / "cache"
    monkeypatch.setenv("DEFERRED_CACHE_DIR", str(folder))
    return folder


def write_map(path, pixels):
    rgba = np.ones((*pixels.shape[:2], 4), np.float32)
    rgba[..., :3] = pixels
    write_image(path, rgba, channels=("R", "G", "B", "A"))
    return str(path)


def one_sphere(map_path, material, params, rotation=0.0, size=SIZE, camera=CAMERA):
    return scene_from_dict({
        "size": list(size), "tonemap": "none", "background": [0.0, 0.0, 0.0], "camera": camera,
        "object": [{"mesh": SPHERE, "material": material, "params": params}],
        "light": [{"type": "environment", "map": map_path, "rotation": rotation}]})


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_white_furnace(gl, tmp_path, pipeline):
    """White dielectric and white metal spheres at roughness 0.2, 0.5 and 1.0 in a uniform
    white environment return its radiance, within 3%."""
    white = write_map(tmp_path / "white.exr", np.ones((16, 32, 3), np.float32))
    objects = []
    centres = {}
    for row, metallic in enumerate((0.0, 1.0)):
        for column, roughness in enumerate((0.2, 0.5, 1.0)):
            centre = [(column - 1) * 2.2, (0.5 - row) * 2.2, 0.0]
            centres[(metallic, roughness)] = centre
            objects.append({"mesh": SPHERE, "material": "pbr", "position": centre,
                            "params": {"base_color": [1.0, 1.0, 1.0], "metallic": metallic,
                                       "roughness": roughness}})
    camera = {"position": [0.0, 0.0, 12.0], "target": [0.0, 0.0, 0.0], "fov": 35.0}
    size = (192, 128)
    scene = scene_from_dict({"size": list(size), "tonemap": "none",
                             "background": [0.0, 0.0, 0.0], "camera": camera,
                             "object": objects,
                             "light": [{"type": "environment", "map": white}]})
    image = render_hdr(gl, scene, pipeline)
    for (metallic, roughness), centre in centres.items():
        _, _, hit = sphere_hits(scene.camera, size, centre)
        inside = interior(hit)
        assert inside.sum() > 200
        error = np.abs(image[inside] - 1.0).max()
        assert error < 0.03, (metallic, roughness, error)


def sh_irradiance(pixels, directions):
    """The irradiance over pi at unit ``directions`` from the map ``pixels`` (top row first),
    through its projection on the 9 real spherical harmonics l <= 2."""
    height, width = pixels.shape[:2]
    theta = (np.arange(height) + 0.5) / height * np.pi
    phi = ((np.arange(width) + 0.5) / width - 0.5) * 2.0 * np.pi
    tt, pp = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(tt) * np.sin(pp), np.cos(tt), -np.sin(tt) * np.cos(pp)], -1)
    solid_angle = np.sin(tt) * (np.pi / height) * (2.0 * np.pi / width)

    def basis(v):
        x, y, z = v[..., 0], v[..., 1], v[..., 2]
        return np.stack([np.full_like(x, 0.282095), 0.488603 * y, 0.488603 * z,
                         0.488603 * x, 1.092548 * x * y, 1.092548 * y * z,
                         0.315392 * (3.0 * z * z - 1.0), 1.092548 * x * z,
                         0.546274 * (x * x - y * y)], -1)

    coefficients = np.einsum("hwk,hwc,hw->kc", basis(d), pixels, solid_angle)
    bands = np.array([1.0, 2 / 3, 2 / 3, 2 / 3, 0.25, 0.25, 0.25, 0.25, 0.25])
    return basis(directions) @ (coefficients * bands[:, None])


def smooth_map(height=32, width=64):
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    vv, uu = np.meshgrid(v, u, indexing="ij")
    return np.stack([0.2 + 1.5 * (1.0 - vv) ** 2, 0.3 + 0.8 * np.sin(np.pi * uu) ** 2,
                     0.1 + vv * 0.9 + 0.6 * np.exp(-((uu - 0.3) ** 2 + (vv - 0.4) ** 2) * 30)],
                    -1).astype(np.float32)


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_rough_sphere_irradiance_is_the_maps_sh_projection(gl, tmp_path, pipeline):
    """A white diffuse sphere of an existing material (standard, no specular) shows the map's
    irradiance: the numpy projection on 9 harmonics, at each pixel's normal."""
    pixels = smooth_map()
    scene = one_sphere(write_map(tmp_path / "sky.exr", pixels), "standard",
                       {"color": [1.0, 1.0, 1.0], "specular_intensity": 0.0})
    image = render_hdr(gl, scene, pipeline)
    _, normals, hit = sphere_hits(scene.camera, SIZE, (0.0, 0.0, 0.0))
    inside = interior(hit)
    want = sh_irradiance(pixels, normals[inside])
    np.testing.assert_allclose(image[inside], want, rtol=0.02, atol=0.01)
    # the pbr material's diffuse lobe sees the same irradiance: a rough black-specular-free
    # check is not possible (its specular is never zero), so only that it is brighter where
    # the map is
    assert want[:, 0].std() > 0.05  # the map is not uniform: the test can fail


def bright_texel_map(texel, height=32, width=64):
    pixels = np.full((height, width, 3), 0.02, np.float32)
    pixels[texel[0], texel[1]] = 400.0
    return pixels


def map_turn(rotation):
    """World directions to the map's, the map turned by ``rotation`` degrees about +Y."""
    angle = np.radians(-rotation)
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def map_uv(d):
    return (0.5 + np.arctan2(d[..., 0], -d[..., 2]) / (2.0 * np.pi),
            np.arccos(np.clip(d[..., 1], -1.0, 1.0)) / np.pi)


def texel_toward(world, rotation, height=32, width=64):
    """The map's texel that a world direction shows, the map turned by ``rotation``."""
    u, v = map_uv(map_turn(rotation) @ (np.asarray(world) / np.linalg.norm(world)))
    return int(v * height), int(u * width) % width


def predicted_pixel(scene, texel, rotation, height=32, width=64):
    """The sphere pixel whose mirror reflection points at the texel's centre."""
    points, normals, hit = sphere_hits(scene.camera, SIZE, (0.0, 0.0, 0.0))
    view = points - np.asarray(scene.camera.position)
    view /= np.linalg.norm(view, axis=-1, keepdims=True)
    reflected = view - 2.0 * np.sum(view * normals, -1, keepdims=True) * normals
    u, v = map_uv(reflected @ map_turn(rotation).T)
    centre = np.array([(texel[0] + 0.5) / height, (texel[1] + 0.5) / width])
    distance = np.hypot(v - centre[0], np.minimum(np.abs(u - centre[1]),
                                                  1.0 - np.abs(u - centre[1])))
    distance[~interior(hit)] = np.inf
    return np.unravel_index(np.argmin(distance), distance.shape)


@pytest.mark.parametrize("rotation", [0.0, 70.0, -120.0])
def test_mirror_sphere_shows_the_bright_texel_where_the_reflection_predicts(gl, tmp_path,
                                                                             rotation):
    # the texel showing a direction behind the camera, up and to the right: its reflection is
    # well inside the sphere (not at the silhouette, where every direction behind it is)
    texel = texel_toward((0.5, 0.45, 1.0), rotation)
    scene = one_sphere(write_map(tmp_path / "dot.exr", bright_texel_map(texel)), "pbr",
                       {"base_color": [1.0, 1.0, 1.0], "metallic": 1.0, "roughness": 0.0},
                       rotation=rotation)
    image = render_hdr(gl, scene).sum(-1)
    want = predicted_pixel(scene, texel, rotation)
    got = np.unravel_index(np.argmax(image), image.shape)
    assert image[got] > 10.0  # the texel, not the dark map
    assert abs(got[0] - want[0]) <= 2 and abs(got[1] - want[1]) <= 2, (got, want)


def test_maps_are_cached_by_the_files_hash(gl, tmp_path, cache):
    path = write_map(tmp_path / "sky.exr", smooth_map())
    scene = one_sphere(path, "standard", {"color": [1.0, 1.0, 1.0]})
    first = render_hdr(gl, scene)
    files = list((cache / "environment").glob("*.npz"))
    assert len(files) == 1
    stamp = files[0].stat().st_mtime_ns
    again = render_hdr(gl, one_sphere(path, "standard", {"color": [1.0, 1.0, 1.0]}))
    np.testing.assert_array_equal(first, again)
    assert files[0].stat().st_mtime_ns == stamp  # read, not made again
    # another file of the same bytes is the same entry; other bytes another one
    copy = tmp_path / "copy.exr"
    copy.write_bytes((tmp_path / "sky.exr").read_bytes())
    render_hdr(gl, one_sphere(str(copy), "standard", {"color": [1.0, 1.0, 1.0]}))
    assert len(list((cache / "environment").glob("*.npz"))) == 1
    files[0].write_bytes(b"not an npz")  # a broken entry is made again, not an error
    np.testing.assert_allclose(render_hdr(gl, scene), first, atol=1e-3)


def test_builtin_sky_and_background(gl):
    scene = scene_from_dict({
        "size": [64, 48], "tonemap": "none", "background": "environment", "camera": CAMERA,
        "object": [{"mesh": "builtin:sphere", "material": "pbr", "scale": 0.5}],
        "light": [{"type": "environment", "intensity": 2.0}]})
    images = {pipeline: render_hdr(gl, scene, pipeline) for pipeline in ("deferred", "forward")}
    for image in images.values():
        sky = image[2, 2]
        assert sky[2] > sky[0] > 0.0  # blue above the horizon, behind the sphere
        assert image[-3, 2].sum() < sky.sum()  # the ground below it is darker
    np.testing.assert_allclose(images["deferred"], images["forward"], rtol=0.02, atol=0.01)


def test_bad_environment_input(tmp_path):
    (tmp_path / "map.png").write_bytes(b"")
    with pytest.raises(InputError, match="environment map not found"):
        scene_from_dict({"light": [{"type": "environment", "map": "missing.hdr"}]},
                        base_dir=tmp_path)
    with pytest.raises(InputError, match="background"):
        Renderer(scene_from_dict({"background": "environment"}), "deferred")
