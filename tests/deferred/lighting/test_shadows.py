"""Shadow maps (deferred.lighting.shadows): a cube over a plane shadows it where the analytic
shadow lies (as dark as the ambient-only render inside, as bright as the unshadowed render
outside, the edge within 2 shadow texels), for directional, spot and point lights; no acne at
grazing light; every light path and both pipelines give one image; cascades show no seam; the
shadow holds still under sub-pixel camera moves; bad parameters are one-line errors."""

from __future__ import annotations

import re
import subprocess
import sys
import warnings

import numpy as np
import pytest

from deferred.errors import InputError
from deferred.lighting.shadows.atlas import SHADOW_ATLAS, check_records_fit
from deferred.lighting.shadows.frusta import practical_splits
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

W, H = 160, 120
CUBE_CENTRE = np.array([0.0, 1.0, 0.0])
CUBE_HALF = 0.35  # builtin:cube is 1.5 wide: scale 0.4
CAMERA = {"position": [0.0, 5.0, 0.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
          "fov": 40.0, "near": 0.1, "far": 30.0}
LIGHTS = {
    "directional": {"type": "directional", "direction": [-0.8, -1.0, -0.3], "intensity": 2.0,
                    "cascades": 1, "shadow_resolution": 1024, "shadow_distance": 8.0},
    "spot": {"type": "spot", "position": [1.0, 3.0, 0.6], "direction": [-0.35, -1.0, -0.2],
             "radius": 12.0, "intensity": 30.0, "inner_angle": 55.0, "outer_angle": 65.0,
             "shadow_resolution": 512},
    "point": {"type": "point", "position": [1.0, 2.6, 0.6], "radius": 12.0, "intensity": 30.0,
              "shadow_resolution": 256},
}
AMBIENT = {"type": "ambient", "color": [0.3, 0.3, 0.3], "ground": [0.3, 0.3, 0.3]}
PLAIN = {"specular_intensity": 0.0, "color": [0.5, 0.5, 0.5]}


def scene(light: dict | None, cube: bool = True, shadows: bool = True, **extra):
    objects = [{"mesh": "builtin:plane", "scale": 8.0, "params": PLAIN}]
    if cube:
        objects.append({"mesh": "builtin:cube", "position": list(CUBE_CENTRE),
                        "scale": CUBE_HALF / 0.75, "params": PLAIN})
    lights = [AMBIENT] + ([{**light, "shadows": shadows}] if light else [])
    return scene_from_dict({"size": [W, H], "tonemap": "none", "camera": CAMERA,
                            "object": objects, "light": lights, **extra})


def render(gl, the_scene, pipeline="deferred", light_path=None):
    with Renderer(the_scene, pipeline, gl=gl, light_path=light_path) as renderer:
        result = renderer.render(hdr=True)
        atlas = renderer.shadow_atlas
        tiles = [(tile.view_projection, tile.size) for tile in atlas.tiles] if atlas else []
        return result.hdr[..., :3].astype(np.float64), tiles


def plane_points():
    """World position on y = 0 of each pixel's ray (top-down rows), and whether the ray hits
    the cube first."""
    eye = np.array(CAMERA["position"])
    tan = np.tan(np.radians(CAMERA["fov"]) / 2.0)
    x = ((np.arange(W) + 0.5) / W * 2.0 - 1.0) * tan * W / H
    y = (1.0 - (np.arange(H) + 0.5) / H * 2.0) * tan
    xx, yy = np.meshgrid(x, y)
    # camera looking down -Y with up -Z: view x = world +X, view y = world -Z
    rays = np.stack([xx, -np.ones_like(xx), -yy], -1)
    t = eye[1] / -rays[..., 1]
    points = eye + rays * t[..., None]
    low, high = CUBE_CENTRE - CUBE_HALF, CUBE_CENTRE + CUBE_HALF
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (low - eye) / rays, (high - eye) / rays
    near = np.nanmax(np.minimum(t0, t1), axis=-1)
    far = np.nanmin(np.maximum(t0, t1), axis=-1)
    return points, near <= far


def cross2(a, b) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def hull(points: np.ndarray) -> np.ndarray:
    """Convex hull of 2-D points, counter-clockwise (monotone chain)."""
    pts = sorted(map(tuple, points))

    def half(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and cross2(np.subtract(out[-1], out[-2]),
                                             np.subtract(p, out[-2])) <= 0:
                out.pop()
            out.append(p)
        return out
    lower, upper = half(pts), half(reversed(pts))
    return np.array(lower[:-1] + upper[:-1])


def signed_distance(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """Distance to a convex counter-clockwise polygon's boundary, negative inside."""
    inside = np.ones(points.shape[:-1], bool)
    distance = np.full(points.shape[:-1], np.inf)
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        edge = b - a
        rel = points - a
        inside &= (edge[0] * rel[..., 1] - edge[1] * rel[..., 0]) >= 0
        t = np.clip((rel @ edge) / (edge @ edge), 0.0, 1.0)
        distance = np.minimum(distance, np.linalg.norm(rel - t[..., None] * edge, axis=-1))
    return np.where(inside, -distance, distance)


def analytic_shadow(kind: str, points: np.ndarray) -> np.ndarray:
    """Signed distance (x, z on the plane) to the cube's shadow on y = 0."""
    corners = np.array([CUBE_CENTRE + CUBE_HALF * np.array([sx, sy, sz])
                        for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    light = LIGHTS[kind]
    if kind == "directional":
        d = np.asarray(light["direction"], float)
        projected = corners - d * (corners[:, 1:2] / d[1])
    else:
        source = np.asarray(light["position"], float)
        projected = source + (corners - source) * (source[1] / (source[1] - corners[:, 1:2]))
    return signed_distance(points[..., [0, 2]], hull(projected[:, [0, 2]]))


def texel_size(kind: str, tiles, points: np.ndarray) -> np.ndarray:
    """A shadow texel's footprint on the plane at each point: its size across the light's
    rays, over the cosine of the rays' angle with the plane's normal."""
    projection, size = tiles[0]
    # row 0 of the view and projection is P00 times the light's unit right vector
    scale = np.linalg.norm(projection[0, :3])
    if kind == "directional":  # orthographic: 2 / (size * P00) world units a texel
        d = np.asarray(LIGHTS[kind]["direction"], float)
        return np.full(points.shape[:-1], 2.0 / (size * scale)) * np.linalg.norm(d) / abs(d[1])
    source = np.asarray(LIGHTS[kind]["position"], float)
    # perspective: the map covers 2 tan(half) per unit of distance (P00 = 1 / tan(half))
    distance = np.linalg.norm(points - source, axis=-1)
    return distance * 2.0 / (size * scale) * distance / source[1]


@pytest.mark.parametrize("kind", ["directional", "spot", "point"])
def test_cube_shadows_the_plane_where_the_analytic_shadow_lies(gl, kind):
    light = LIGHTS[kind]
    shadowed, tiles = render(gl, scene(light))
    unshadowed, _ = render(gl, scene(light, shadows=False))
    ambient, _ = render(gl, scene(None))
    points, on_cube = plane_points()
    distance = analytic_shadow(kind, points)
    texel = texel_size(kind, tiles, points)
    lit = (unshadowed - ambient).sum(-1)
    usable = ~on_cube & (lit > 0.05 * lit.max())
    # the plateaus from 4 texels off the edge: the filter reaches 2, the biases move it ~1
    inside = usable & (distance < -4.0 * texel)
    outside = usable & (distance > 4.0 * texel)
    assert inside.sum() > 150 and outside.sum() > 2000
    # inside: the ambient-only radiance, outside: the unshadowed one (2%)
    assert np.all(np.abs(shadowed[inside] - ambient[inside]) <= 0.02 * ambient[inside] + 1e-4)
    assert np.all(np.abs(shadowed[outside] - unshadowed[outside])
                  <= 0.02 * unshadowed[outside] + 1e-4)
    # the edge (where half the light arrives) within 2 shadow texels of the analytic one
    fraction = (shadowed - ambient).sum(-1) / np.maximum(lit, 1e-6)
    wrong = usable & ((fraction < 0.5) != (distance < 0.0))
    assert np.all(np.abs(distance[wrong]) <= 2.0 * texel[wrong])


GRAZING = {
    "directional": {**LIGHTS["directional"], "direction": [-1.0, -0.12, -0.3]},
    "spot": {**LIGHTS["spot"], "position": [3.5, 0.45, 0.0], "direction": [-1.0, -0.12, 0.0],
             "inner_angle": 60.0, "outer_angle": 70.0},
    "point": {**LIGHTS["point"], "position": [3.5, 0.4, 0.3]},
}


@pytest.mark.parametrize("kind", ["directional", "spot", "point"])
def test_no_acne_on_a_lit_plane_at_grazing_light(gl, kind):
    light = GRAZING[kind]
    shadowed, _ = render(gl, scene(light, cube=False))
    unshadowed, _ = render(gl, scene(light, cube=False, shadows=False))
    ambient, _ = render(gl, scene(None, cube=False))
    lit = (unshadowed - ambient).sum(-1)
    plane = lit > 0.05 * lit.max()
    assert plane.sum() > 2000
    ratio = (shadowed - ambient).sum(-1)[plane] / lit[plane]
    assert ratio.min() > 0.99 and float(np.var(ratio)) < 1e-5


def paths_scene(filter_name: str = "pcf"):
    shadow = {"shadows": True, "shadow_resolution": 256, "shadow_filter": filter_name}
    return scene_from_dict({
        "size": [160, 96], "tonemap": "none",
        "camera": {"position": [0.0, 1.6, 4.2], "target": [0.0, 0.4, 0.0]},
        "shadows": {"atlas_size": 2048},
        "object": [{"mesh": "builtin:plane", "scale": 6.0},
                   {"mesh": "builtin:sphere", "position": [-0.9, 0.6, 0.0], "scale": 0.6},
                   {"mesh": "builtin:cube", "position": [0.9, 0.5, -0.5], "scale": 0.5},
                   {"mesh": "builtin:torus", "position": [0.2, 0.3, 1.2], "scale": 0.4}],
        "light": [AMBIENT,
                  {"type": "directional", "direction": [-0.5, -1.0, -0.3], "intensity": 0.8,
                   **shadow},
                  {"type": "point", "position": [0.5, 1.4, 1.0], "radius": 4.0,
                   "intensity": 4.0, **shadow},
                  {"type": "spot", "position": [-1.0, 2.0, 1.0], "direction": [0.4, -1.0, -0.3],
                   "radius": 5.0, "intensity": 6.0, "inner_angle": 15.0, "outer_angle": 30.0,
                   **shadow}]})


def psnr(a, b, peak):
    mse = float(np.mean((a - b) ** 2))
    return float("inf") if mse == 0.0 else 10.0 * np.log10(peak * peak / mse)


@pytest.mark.parametrize("filter_name", ["pcf", "soft"])
def test_every_light_path_and_both_pipelines_give_one_shadowed_image(gl, filter_name):
    if not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    the_scene = paths_scene(filter_name)
    reference, _ = render(gl, the_scene, "deferred", "volumes")
    unshadowed_scene = paths_scene(filter_name)
    for light in unshadowed_scene.lights[1:]:
        light.params = light.params.model_copy(update={"shadows": False})
    unshadowed, _ = render(gl, unshadowed_scene, "deferred", "volumes")
    peak = float(reference.max())
    assert psnr(reference, unshadowed, peak) < 30.0  # the shadows are there
    for pipeline, path in [("deferred", "tiled"), ("deferred", "clustered"),
                           ("forward", "naive"), ("forward", "tiled")]:
        image, _ = render(gl, the_scene, pipeline, path)
        assert psnr(image, reference, peak) >= 40.0, (pipeline, path)


def test_cascades_show_no_seam(gl):
    """A plane seen at a low angle through 3 cascades, striped by the shadows of a row of
    posts: across a cascade's border the shadow fraction changes no more from one pixel row
    to the next than within a cascade."""
    posts = [{"mesh": "builtin:cube", "position": [x, 0.5, z], "scale": [0.05, 0.7, 0.05]}
             for x in (-1.0, 0.0, 1.0) for z in np.arange(-14.0, 3.0, 1.0)]
    light = {"type": "directional", "direction": [-1.0, -0.6, 0.0], "intensity": 2.0,
             "cascades": 3, "shadow_distance": 20.0, "shadow_resolution": 512,
             "cascade_lambda": 0.6}
    camera = {"position": [0.0, 1.5, 4.0], "target": [0.0, 0.0, -4.0], "near": 0.5,
              "far": 40.0, "fov": 50.0}

    def make(shadows):
        return scene_from_dict({"size": [W, H], "tonemap": "none", "camera": camera,
                                "object": [{"mesh": "builtin:plane", "scale": 40.0,
                                            "params": PLAIN}, *posts],
                                "light": [AMBIENT, {**light, "shadows": shadows}]})
    shadowed, _ = render(gl, make(True))
    unshadowed, _ = render(gl, make(False))
    ambient, _ = render(gl, scene_from_dict({
        "size": [W, H], "tonemap": "none", "camera": camera,
        "object": [{"mesh": "builtin:plane", "scale": 40.0, "params": PLAIN}, *posts],
        "light": [AMBIENT]}))
    lit = (unshadowed - ambient).sum(-1)
    fraction = np.where(lit > 1e-3, (shadowed - ambient).sum(-1) / np.maximum(lit, 1e-6), 1.0)
    # the view depth of each pixel row of the plane (rows top-down), from the camera's pitch
    eye, target = np.array(camera["position"]), np.array(camera["target"])
    forward = (target - eye) / np.linalg.norm(target - eye)
    tan = np.tan(np.radians(camera["fov"]) / 2.0)
    rows = np.arange(H)
    y = (1.0 - (rows + 0.5) / H * 2.0) * tan
    up = np.cross(np.cross(forward, [0, 1, 0]), forward)
    up /= np.linalg.norm(up)
    direction = forward[None] + y[:, None] * up[None]
    t = eye[1] / -direction[:, 1]
    depth = np.where(direction[:, 1] < 0, t, np.inf)  # view depth = t (forward has unit z)
    splits = practical_splits(camera["near"], 20.0, 3, 0.6)
    step = np.abs(np.diff(fraction[:, 20:-20], axis=0)).mean(axis=1)  # between rows r, r+1
    at_border = np.zeros(H - 1, bool)
    for split in splits[:-1]:
        crossing = np.nonzero((depth[:-1] - split) * (depth[1:] - split) <= 0)[0]
        at_border[crossing] = True
        at_border[np.clip(crossing - 1, 0, H - 2)] = True
        at_border[np.clip(crossing + 1, 0, H - 2)] = True
    visible = np.isfinite(depth[:-1]) & np.isfinite(depth[1:]) & (depth[1:] < 19.0)
    assert at_border[visible].any()
    assert step[at_border & visible].max() <= step[~at_border & visible].max()


def test_shadow_holds_still_under_sub_pixel_camera_moves(gl):
    """The camera moved sideways a third of a pixel at a time, looking straight down: the
    plane's image moves with it, and frames a whole pixel apart are the same image moved by a
    column. The shadowed frames differ from that no more than the unshadowed ones do (the
    cascades' texel grids stay put in the world; a grid sliding with the camera would change
    the filtered edges)."""
    light = {**LIGHTS["directional"], "cascades": 3, "shadow_resolution": 512}
    pixel = 2.0 * CAMERA["position"][1] * np.tan(np.radians(CAMERA["fov"]) / 2.0) / H
    _, on_cube = plane_points()
    frames: dict[bool, list[np.ndarray]] = {True: [], False: []}
    for k in range(6):
        shift = k * pixel / 3.0
        camera = {**CAMERA, "position": [shift, 5.0, 0.0], "target": [shift, 0.0, 0.0]}
        for shadows in (True, False):
            frames[shadows].append(render(gl, scene_from_dict({
                "size": [W, H], "tonemap": "none", "camera": camera,
                "object": [{"mesh": "builtin:plane", "scale": 8.0, "params": PLAIN},
                           {"mesh": "builtin:cube", "position": list(CUBE_CENTRE),
                            "scale": CUBE_HALF / 0.75, "params": PLAIN}],
                "light": [AMBIENT, {**light, "shadows": shadows}]}))[0])
    # the plane's pixels away from the cube in both frames (its silhouette, lit as the plane
    # is, falls on pixel centres differently a third of a pixel on)
    near_cube = on_cube.copy()
    for axis in (0, 1):
        for step in (-2, -1, 1, 2):
            near_cube |= np.roll(on_cube, step, axis=axis)
    region = ~(near_cube[:, :-1] | near_cube[:, 1:])
    peak = max(float(image.sum(-1).max()) for image in frames[False])
    for k in range(3):
        changed = {shadows: np.abs(images[k + 3][:, :-1] - images[k][:, 1:]).sum(-1)[region]
                   for shadows, images in frames.items()}
        # (without the texel snapping: 0.43 of a peak of about 1)
        assert changed[True].max() <= 1.25 * changed[False].max() + 0.01 * peak, \
            (changed[True].max(), changed[False].max())


def test_lights_over_the_budget_are_unshadowed_with_one_warning(gl):
    spots = [{**LIGHTS["spot"], "position": [x, 3.0, 0.6], "shadows": True}
             for x in (-1.0, 0.0, 1.0)]
    the_scene = scene_from_dict({"size": [W, H], "tonemap": "none", "camera": CAMERA,
                                 "shadows": {"max_shadowed_lights": 2, "atlas_size": 1024},
                                 "object": [{"mesh": "builtin:plane", "scale": 8.0}],
                                 "light": [AMBIENT, *spots]})
    with Renderer(the_scene, gl=gl) as renderer, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        renderer.render()
        renderer.render()
        atlas = renderer.blackboard[SHADOW_ATLAS]
        assert sorted(atlas.slots.values()) == [1, 2]
        assert id(the_scene.lights[3]) not in atlas.slots
    budget = [w for w in caught if "shadow budget" in str(w.message)]
    assert len(budget) == 1 and "\n" not in str(budget[0].message)
    assert "light 3" in str(budget[0].message)


@pytest.mark.parametrize("point_first", [True, False])
def test_a_light_whose_maps_do_not_fit_leaves_its_squares_to_the_others(point_first):
    """A 256^2 atlas holds four 128^2 squares: a point light's six do not fit, a spot light's
    one does, listed before or after it (the point light's first four squares were kept,
    and the spot light was refused as not fitting)."""
    from deferred.lighting.shadows.plan import plan_atlas

    the_scene = scene_from_dict({"light": [
        {"type": "point", "position": [0.0, 2.0, 0.0], "shadows": True,
         "shadow_resolution": 128},
        {"type": "spot", "position": [0.0, 2.0, 0.0], "shadows": True,
         "shadow_resolution": 128}]})
    point, spot = the_scene.lights
    plan, left_out = plan_atlas([point, spot] if point_first else [spot, point], 256, 16)
    assert list(plan) == [id(spot)] and len(plan[id(spot)][1]) == 1
    assert len(left_out) == 1 and left_out[0][0] == (0 if point_first else 1)  # the point light
    assert left_out[0][1] == "6 map(s) of 128^2 each do not fit the 256^2 atlas"


@pytest.mark.parametrize(("text", "expected"), [
    ('[[light]]\ntype = "directional"\nshadows = true\nshadow_resolution = 1000\n',
     "light[0].shadow_resolution: must be a power of two"),
    ('[[light]]\ntype = "directional"\nshadows = true\ncascades = 5\n', "light[0].cascades"),
    ('[[light]]\ntype = "spot"\nshadows = true\nshadow_filter = "blur"\n',
     "light[0].shadow_filter: expected one of 'pcf', 'soft'"),
    ('[[light]]\ntype = "point"\nshadows = true\nnormal_bias = -1.0\n', "light[0].normal_bias"),
    ('[shadows]\natlas_size = 3000\n', "shadows.atlas_size: must be a power of two"),
    ('[shadows]\nmax_shadowed_lights = 0\n', "shadows.max_shadowed_lights"),
    ('[shadows]\nopacity_scale = 0.3\n', "shadows.opacity_scale: must be 1, 0.5"),
    ('[shadows]\nallocation = "screen"\n',
     "shadows.allocation: expected one of 'fixed', 'coverage'"),
])
def test_bad_shadow_parameters_are_one_line_errors(tmp_path, text, expected):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=re.escape(expected)):
        from deferred.scene.loader import load_scene
        load_scene(path)
    done = subprocess.run([sys.executable, "-m", "deferred", "render", str(path), "-o",
                           str(tmp_path / "out.png")], capture_output=True, text=True)
    assert done.returncode == 2
    assert len(done.stderr.strip().splitlines()) == 1 and expected.split(":")[0] in done.stderr
    assert not (tmp_path / "out.png").exists()


def test_records_that_overflow_the_gl_uniform_blocks_are_one_line(gl):
    class SmallBlocks:  # a GL with the smallest uniform blocks the GL 3.3 spec allows
        info = {"GL_MAX_UNIFORM_BLOCK_SIZE": 16384}

    check_records_fit(SmallBlocks(), 25, "scene.toml: shadows")  # 25 x 640 bytes fit
    with pytest.raises(InputError) as error:
        check_records_fit(SmallBlocks(), 26, "scene.toml: shadows")
    assert str(error.value).count("\n") == 0
    assert "max_shadowed_lights = 26" in str(error.value) and "at most 25" in str(error.value)
    check_records_fit(gl.ctx, 64, "scene.toml: shadows")  # the largest budget fits here


@pytest.mark.slow
def test_shadow_views_and_the_dump_show_the_atlas(tmp_path):
    from deferred.io.images import read_image

    path = tmp_path / "scene.toml"
    path.write_text(
        'size = [96, 64]\n[shadows]\natlas_size = 1024\n'
        '[[object]]\nmesh = "builtin:plane"\nscale = 4.0\n'
        '[[object]]\nmesh = "builtin:cube"\nposition = [0.0, 0.8, 0.0]\nscale = 0.4\n'
        '[[light]]\ntype = "directional"\nshadows = true\nshadow_resolution = 256\n'
        'cascades = 2\n')

    def deferred(*args):
        return subprocess.run([sys.executable, "-m", "deferred", *map(str, args)],
                              capture_output=True, text=True)
    assert deferred("render", path, "--view", "shadow_atlas", "-o",
                    tmp_path / "atlas.exr").returncode == 0
    atlas = read_image(tmp_path / "atlas.exr")
    assert atlas.shape[:2] == (1024, 1024)
    drawn = atlas[..., 0] < 1.0
    # two cascades of 256^2 in a corner of the atlas (rows top-down: its bottom), casters drawn
    assert drawn[-512:, :512].any() and not drawn[:512].any()
    assert deferred("render", path, "--view", "shadow.cascades", "-o",
                    tmp_path / "cascades.exr").returncode == 0
    cascades = read_image(tmp_path / "cascades.exr")[..., 0]
    assert set(np.unique(cascades)) <= {0.0, 1.0, 2.0} and (cascades == 1.0).any()
    assert deferred("dump", path, "-o", tmp_path / "dump").returncode == 0
    assert (tmp_path / "dump" / "shadow_atlas.exr").is_file()
    spot = path.read_text().replace('type = "directional"', 'type = "spot"\n'
                                     'position = [0.0, 3.0, 0.0]').replace("cascades = 2\n", "")
    path.write_text(spot)  # shadows, but no directional light's cascades
    done = deferred("render", path, "--view", "shadow.cascades", "-o", tmp_path / "c.png")
    assert done.returncode == 2 and "no directional light of this scene casts shadows" in \
        done.stderr and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert not (tmp_path / "c.png").exists()
    path.write_text(path.read_text().replace("shadows = true", "shadows = false"))
    done = deferred("render", path, "--view", "shadow_atlas", "-o", tmp_path / "none.png")
    assert done.returncode == 2 and "no light of this scene casts shadows" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


# self-shadowing (deep opacity maps) off: these tests compare shadowed and unshadowed scenes,
# and the fur's own shadow is tests/deferred/lighting/test_opacity_shadows.py's
FUR = {"revie_fur": {"fur_length": 0.5, "shells": 12, "stipple": False,
                     "self_shadow_density": 0.0},
       "shell_fur": {"fur_length": 0.5, "shells": 12, "self_shadow_density": 0.0}}
FUR_LIGHT = np.array([0.6, -1.0, 0.0])  # from the left, down


def fur_scene(material: str, shadows: bool, *, caster_above: bool = False,
              standard: bool = False, density: float = 0.0):
    ball = {"mesh": "builtin:sphere", "position": [0.0, 0.9, 0.0], "scale": 0.4}
    ball.update({"params": PLAIN} if standard else {
        "material": material, "params": {**FUR[material], "self_shadow_density": density}})
    objects = [{"mesh": "builtin:plane", "scale": 8.0, "params": PLAIN}, ball]
    if caster_above:
        # a slab up toward the light (out of the camera's view) whose shadow falls on the
        # ball's left half: the points x in [-0.45, 0] near the top, 1.7 units up the light
        objects.append({"mesh": "builtin:cube", "position": [-1.28, 2.9, 0.0],
                        "scale": [0.3, 0.03, 1.0], "params": PLAIN})
    light = {"type": "directional", "direction": list(FUR_LIGHT), "intensity": 2.0,
             "cascades": 1, "shadow_distance": 8.0, "shadow_resolution": 1024,
             "shadows": shadows}
    return scene_from_dict({"size": [W, H], "tonemap": "none", "camera": CAMERA,
                            "object": objects, "light": [AMBIENT, light]})


@pytest.mark.slow
@pytest.mark.parametrize("density", [0.0, 0.5])
@pytest.mark.parametrize("material", ["revie_fur", "shell_fur"])
def test_fur_casts_a_shadow_from_its_shells(gl, material, density):
    """The fur ball's shadow on the floor is the sphere's grown by the fur (its shells cast,
    not just its skin): a ring just outside the bare sphere's shadow is shaded. Without
    self-shadowing (density 0) the shells cast in the depth map, dithered; with it only the
    skin does, and the floor beyond the fur keeps exp(-k x the fur's optical depth) from the
    deep opacity maps (lighting/shadows.glsl, opacity_beyond)."""
    points, _ = plane_points()
    centre = -0.9 * FUR_LIGHT[0] / FUR_LIGHT[1]  # where the light's ray through the centre lands
    stretch = np.linalg.norm(FUR_LIGHT) / abs(FUR_LIGHT[1])  # the shadow's ellipse along x
    rho = np.hypot((points[..., 0] - centre) / stretch, points[..., 2])
    far_side = points[..., 0] > 0.8  # not hidden by the fur ball (0.6 wide) from above

    def fraction(**kw):
        shadowed, _ = render(gl, fur_scene(material, True, density=density, **kw))
        unshadowed, _ = render(gl, fur_scene(material, False, density=density, **kw))
        ambient, _ = render(gl, scene_from_dict({
            "size": [W, H], "tonemap": "none", "camera": CAMERA,
            "object": [{"mesh": "builtin:plane", "scale": 8.0, "params": PLAIN}],
            "light": [AMBIENT]}))
        lit = (unshadowed - ambient).sum(-1)
        return (shadowed - ambient).sum(-1) / np.maximum(lit, 1e-6)
    fur = fraction()
    skin = fraction(standard=True)
    ring = far_side & (rho > 0.42) & (rho < 0.5)  # the fur reaches 0.4 + 0.2
    inside = far_side & (rho < 0.33)
    outside = far_side & (rho > 0.75)
    assert ring.sum() > 20 and inside.sum() > 20
    assert skin[ring].mean() > 0.95  # the bare sphere leaves the ring lit
    assert fur[ring].mean() < 0.8  # the fur shades it
    # softly: the shadow lightens outward through the fur's reach (sparser toward the tips)
    bands = [fur[far_side & (rho > a) & (rho < a + 0.04)].mean() for a in (0.42, 0.46, 0.5)]
    print(material, density, "ring", fur[ring].mean(), "bands", bands)
    assert bands[0] < bands[1] < bands[2] < 1.0
    assert fur[inside].max() < 0.05 and fur[outside].min() > 0.98


@pytest.mark.slow
@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
@pytest.mark.parametrize("material", ["revie_fur", "shell_fur"])
def test_fur_receives_shadows(gl, material, pipeline):
    """A slab's shadow over the left half of a fur ball darkens the fur there (shells, fins
    and the root shell read the shadow), in both pipelines; the right half stays lit."""
    shadowed, _ = render(gl, fur_scene(material, True, caster_above=True), pipeline)
    unshadowed, _ = render(gl, fur_scene(material, False, caster_above=True), pipeline)
    points, _ = plane_points()
    # the ball's top seen from above (its pixels within 0.3 of the middle at its top's height)
    x, z = points[..., 0] * (5.0 - 1.3) / 5.0, points[..., 2] * (5.0 - 1.3) / 5.0
    on_ball = np.hypot(x, z) < 0.3
    left, right = on_ball & (x < -0.15), on_ball & (x > 0.15)
    shaded, plain = shadowed.sum(-1), unshadowed.sum(-1)
    assert shaded[left].mean() < 0.6 * plain[left].mean()
    assert shaded[right].mean() > 0.95 * plain[right].mean()


def test_turning_shadows_on_between_frames_rebuilds_the_renderer(gl):
    the_scene = scene(LIGHTS["spot"], shadows=False)
    with Renderer(the_scene, gl=gl) as renderer:
        before = renderer.render(hdr=True).hdr
        assert renderer.shadow_atlas is None
        light = the_scene.lights[1]
        light.params = light.params.model_copy(update={"shadows": True})
        after = renderer.render(hdr=True).hdr
        assert renderer.shadow_atlas is not None and renderer.shadow_atlas.slots
        assert after[..., :3].sum() < 0.97 * before[..., :3].sum()  # the cube's shadow


def test_a_light_out_of_view_draws_no_maps(gl):
    behind = {**LIGHTS["spot"], "position": [0.0, 9.0, 0.0], "radius": 2.0}  # above the camera
    the_scene = scene_from_dict({"size": [W, H], "tonemap": "none", "camera": CAMERA,
                                 "object": [{"mesh": "builtin:plane", "scale": 8.0}],
                                 "light": [AMBIENT, {**LIGHTS["spot"], "shadows": True},
                                           {**behind, "shadows": True}]})
    with Renderer(the_scene, gl=gl) as renderer:
        renderer.render()
        atlas = renderer.shadow_atlas
        assert [tile.light for tile in atlas.tiles] == [the_scene.lights[1]]
        assert id(the_scene.lights[2]) not in atlas.slots


@pytest.mark.parametrize("spot_first", [True, False])
def test_each_light_is_tested_for_view_against_the_camera(gl, spot_first):
    """A narrow spot light and a point light off to the side, both in view: each gets its maps
    whichever is listed first (the point light was tested against the spot light's frustum
    when listed after it), and the two orders give the same image."""
    spot = {"type": "spot", "position": [0.0, 2.0, 0.0], "direction": [0.0, -1.0, 0.0],
            "radius": 3.0, "outer_angle": 15.0, "inner_angle": 10.0, "shadows": True,
            "shadow_resolution": 128}
    point = {"type": "point", "position": [1.9, -0.25, 0.6], "radius": 0.8, "intensity": 4.0,
             "shadows": True, "shadow_resolution": 64}

    def lit(order):
        the_scene = scene_from_dict({
            "size": [64, 36], "tonemap": "none", "shadows": {"atlas_size": 512},
            "camera": {"position": [0.0, 0.5, 3.0], "target": [0.0, 0.0, 0.0], "fov": 45.0},
            "object": [{"mesh": "builtin:plane", "scale": 6.0, "position": [0.0, -0.7, 0.0]},
                       {"mesh": "builtin:sphere", "scale": 0.5},
                       {"mesh": "builtin:cube", "position": [1.8, -0.5, 0.6], "scale": 0.1}],
            "light": [*order, {"type": "ambient", "color": [0.05, 0.05, 0.05]}]})
        with Renderer(the_scene, gl=gl) as renderer:
            image = renderer.render(hdr=True).hdr
            slots = renderer.shadow_atlas.slots
            assert all(id(light) in slots for light in the_scene.lights[:2])
        return image

    first = lit([spot, point] if spot_first else [point, spot])
    other = lit([point, spot] if spot_first else [spot, point])
    np.testing.assert_allclose(first, other, atol=1e-5)


def test_the_soft_filter_widens_the_penumbra(gl):
    """The same shadow edge through pcf and through the soft filter 6 texels wide: the
    transition (lit fraction between 0.1 and 0.9) spans about 2 texels with pcf and several
    times that with the soft filter, centred on the analytic edge either way."""
    points, on_cube = plane_points()
    distance = analytic_shadow("directional", points)
    ambient, _ = render(gl, scene(None))
    widths = {}
    for name, extra in (("pcf", {}), ("soft", {"shadow_filter": "soft",
                                               "shadow_softness": 6.0})):
        light = {**LIGHTS["directional"], **extra}
        shadowed, tiles = render(gl, scene(light))
        unshadowed, _ = render(gl, scene(light, shadows=False))
        lit = (unshadowed - ambient).sum(-1)
        fraction = (shadowed - ambient).sum(-1) / np.maximum(lit, 1e-6)
        texel = texel_size("directional", tiles, points)
        between = ~on_cube & (fraction > 0.1) & (fraction < 0.9)
        widths[name] = float(np.percentile(np.abs(distance[between] / texel[between]), 90))
        # the half-lit line on the analytic edge
        assert abs(float(np.median(distance[between] / texel[between]))) < 1.5
    assert widths["pcf"] < 3.0 and widths["soft"] > 2.0 * widths["pcf"], widths
