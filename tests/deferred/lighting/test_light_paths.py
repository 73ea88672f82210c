"""Light paths: tiled and clustered deferred lighting and Forward+ give the image of the volumes
and naive paths; the light lists hold every light that reaches a pixel; lights off screen are
culled on the CPU; a context without compute shaders runs volumes and naive."""

from types import SimpleNamespace

import numpy as np
import pytest

from deferred.bench.scenes import with_extra_lights
from deferred.errors import InputError
from deferred.gl.context import Features, GLContext
from deferred.lighting.buffer import visible_spheres
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene, scene_from_dict

ALL_TYPES = [
    {"type": "ambient", "color": [0.2, 0.22, 0.25], "ground": [0.1, 0.08, 0.06]},
    {"type": "directional", "direction": [-0.5, -1.0, -0.3], "intensity": 0.8},
    {"type": "point", "position": [0.5, 1.0, 1.0], "radius": 3.0, "intensity": 4.0},
    {"type": "spot", "position": [-1.0, 2.0, 1.0], "direction": [0.4, -1.0, -0.3],
     "radius": 5.0, "intensity": 6.0, "inner_angle": 15.0, "outer_angle": 30.0},
]


def scene_with(lights_extra: int):
    scene = scene_from_dict({
        "size": [160, 96], "tonemap": "none",
        "camera": {"position": [0.0, 1.6, 4.2], "target": [0.0, 0.4, 0.0]},
        "object": [{"mesh": "builtin:plane", "scale": 6.0},
                   {"mesh": "builtin:sphere", "position": [-0.9, 0.6, 0.0], "scale": 0.6},
                   {"mesh": "builtin:cube", "position": [0.9, 0.5, -0.5], "scale": 0.5},
                   {"mesh": "builtin:torus", "position": [0.2, 0.3, 1.2], "scale": 0.4}],
        "light": ALL_TYPES})
    return with_extra_lights(scene, lights_extra, 160 / 96)


def render(gl, scene, pipeline, light_path):
    if not gl.features.compute_shaders and light_path in ("tiled", "clustered"):
        pytest.skip("the driver has no compute shaders")
    with Renderer(scene, pipeline, gl=gl, light_path=light_path) as renderer:
        result = renderer.render()
        return result, renderer.light_path


def psnr(a, b, peak):
    mse = float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))
    return float("inf") if mse == 0.0 else 10.0 * np.log10(peak * peak / mse)


@pytest.mark.parametrize("extra", [0, 16, 200])
@pytest.mark.parametrize("path", ["tiled", "clustered"])
def test_deferred_paths_give_the_volumes_image(gl, extra, path):
    scene = scene_with(extra)
    reference, _ = render(gl, scene, "deferred", "volumes")
    result, used = render(gl, scene, "deferred", path)
    assert used == path
    peak = float(reference.hdr[..., :3].max())
    assert psnr(result.hdr[..., :3], reference.hdr[..., :3], peak) >= 40.0
    assert "lighting.point" in reference.draws_by_pass
    assert f"lighting.{path}" in result.draws_by_pass and \
        "lighting.point" not in result.draws_by_pass  # one pass for every light


@pytest.mark.parametrize("extra", [0, 16, 200])
def test_forward_plus_gives_the_naive_image(gl, extra):
    scene = scene_with(extra)
    reference, _ = render(gl, scene, "forward", "naive")
    result, used = render(gl, scene, "forward", "tiled")
    assert used == "tiled" and "forward.cull_tiles" in result.draws_by_pass
    peak = float(reference.hdr[..., :3].max())
    assert psnr(result.hdr[..., :3], reference.hdr[..., :3], peak) >= 40.0


@pytest.mark.slow
def test_forward_plus_lights_fur_shells_in_front_of_the_opaque_depth(gl):
    demo = with_extra_lights(load_scene(None), 24, 16 / 9)
    images = []
    for path in ("naive", "tiled"):
        with Renderer(demo, "forward", (160, 90), gl=gl, light_path=path) as renderer:
            images.append(renderer.render().image[..., :3])
    assert psnr(images[0], images[1], 255.0) >= 40.0


def listed_frame(gl, path: str, extra: int, size: tuple[int, int] | None = None
                 ) -> SimpleNamespace:
    """One frame of scene_with(extra) through a list path, read back: the lists (``entries``,
    ``counts``), the light records, and each covered pixel's view-space point (``xs``, ``ys``,
    ``z``, ``points``) with the volume lights whose sphere reaches it (``reach``)."""
    if not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    with Renderer(scene_with(extra), "deferred", size, gl=gl, light_path=path) as renderer:
        renderer.render()
        lists = renderer.light_lists
        grid = lists.grid
        data = np.frombuffer(lists.buffer.read(), dtype=np.uint32)
        records = np.frombuffer(renderer.light_buffer.texture.read(), dtype=np.float32)
        records = records.reshape(-1, 4, 4)[:renderer.light_buffer.count]
        slots = lists.shading_slots()
        frame_entries = lists.entries()  # from the shading's copy
        depth = renderer.targets.read("linear_depth")[..., 0]
        inverse = renderer.last_frame.inverse_projection
        global_count = renderer.light_buffer.global_count
        camera = renderer.scene.camera
    height, width = depth.shape
    ys, xs = np.nonzero(depth > 0.0)
    ndc = np.stack([(xs + 0.5) / width * 2 - 1, (ys + 0.5) / height * 2 - 1,
                    np.ones(len(xs)), np.ones(len(xs))], -1)
    rays = ndc @ inverse.T
    rays = rays[:, :3] / rays[:, 3:]
    z = depth[ys, xs]
    points = rays * (z / -rays[:, 2])[:, None]
    spheres = records[global_count:, 1]
    reach = np.linalg.norm(points[:, None, :] - spheres[None, :, :3], axis=-1) <= \
        spheres[None, :, 3] * 0.999
    counts = data[:grid.count]
    entries = frame_entries
    return SimpleNamespace(grid=grid, capacity=lists.capacity, counts=counts, entries=entries,
                           data=data, slots=slots,
                           records=records, global_count=global_count, camera=camera,
                           xs=xs, ys=ys, z=z, points=points, reach=reach)


@pytest.mark.parametrize("size", [None, (157, 93)])  # 160x96; odd: tiles of odd width, height
@pytest.mark.parametrize("split", [2, 1])  # lists of 8x8 quadrants (the default), or 16x16
def test_tile_lists_hold_every_light_that_reaches_a_pixel(gl, size, split, monkeypatch):
    import deferred.lighting.lists as light_lists

    monkeypatch.setattr(light_lists, "LIST_SPLIT", split)
    frame = listed_frame(gl, "tiled", 120, size)
    assert frame.grid.tile == 16 // split
    grid, reach, points, records = frame.grid, frame.reach, frame.points, frame.records
    global_count, counts, entries = frame.global_count, frame.counts, frame.entries
    assert reach.sum() > 1000  # the lights do light the scene
    tile = (frame.ys // grid.tile) * grid.columns + frame.xs // grid.tile
    missing = 0
    for pixel in np.nonzero(reach.any(axis=1))[0]:
        listed = entries[tile[pixel]]
        needed = np.nonzero(reach[pixel])[0] + global_count
        missing += len(set(needed.tolist()) - set(listed.tolist()))
    assert missing == 0
    # and the lists are far shorter than every light
    assert counts.mean() < 0.25 * (len(records) - global_count)
    # and hold only lights whose sphere touches the view-space box of their tile's points
    # (tighter than the tile's frustum between its depth bounds)
    loose = 0
    for list_index in np.unique(tile):
        box = points[tile == list_index]
        pad = 1e-4 * -box[:, 2].min() + 1e-5  # the shader's padding, and float32's bits
        low, high = box.min(0) - pad, box.max(0) + pad
        listed = entries[list_index]
        centres = records[listed.astype(int), 1, :3]
        gap = centres - np.clip(centres, low, high)
        loose += int((np.sum(gap * gap, -1) > records[listed.astype(int), 1, 3] ** 2).sum())
    assert loose == 0


@pytest.mark.parametrize("path", ["tiled", "clustered"])
def test_lists_hold_their_lights_in_light_order_and_clusters_every_light_reaching_a_pixel(
        gl, path):
    """The culling appends each tile's lights in the order of the light buffer, so a frame
    sums its lights in the same order whatever the scheduling (the same image every frame);
    and a pixel's cluster holds every light whose sphere reaches the pixel's point."""
    frame = listed_frame(gl, path, 150)
    grid, entries = frame.grid, frame.entries
    assert frame.counts.max() <= frame.capacity
    assert sum(len(e) for e in entries) > 0
    assert all(np.all(np.diff(e.astype(np.int64)) > 0) for e in entries)  # ascending, once each
    if path == "tiled":
        return  # test_tile_lists_hold_every_light_that_reaches_a_pixel checks the tiles'
    reach, z, ys, xs = frame.reach, frame.z, frame.ys, frame.xs
    assert reach.sum() > 1000
    # the shader's light_list_slice and light_list_of, in numpy
    near, far = frame.camera.near, frame.camera.far
    slices = np.clip(np.floor(np.log(np.maximum(z, near) / near) * grid.slices /
                              np.log(far / near)), 0, grid.slices - 1).astype(int)
    cluster = (slices * grid.rows + ys // grid.tile) * grid.columns + xs // grid.tile
    missing = 0
    for pixel in np.nonzero(reach.any(axis=1))[0]:
        needed = set((np.nonzero(reach[pixel])[0] + frame.global_count).tolist())
        missing += len(needed - set(entries[cluster[pixel]].tolist()))
    assert missing == 0


def test_lights_outside_the_view_are_culled_on_the_cpu(gl):
    from deferred.scene.camera import Camera

    view_projection = Camera(fov=90.0, near=0.1, far=50.0).projection(1.0)
    records = np.zeros((4, 4, 4), np.float32)
    records[:, 1] = [[0.0, 0.0, -5.0, 1.0],   # straight ahead
                     [0.0, 0.0, 5.0, 1.0],    # behind the eye
                     [7.0, 0.0, -5.0, 1.0],   # off to the side
                     [5.5, 0.0, -5.0, 1.0]]   # off to the side, but its sphere reaches in
    assert visible_spheres(records, view_projection).tolist() == [True, False, False, True]
    scene = scene_with(0)
    behind = scene_from_dict({"light": [{"type": "point", "position": [0.0, 1.0, 20.0],
                                         "radius": 2.0}]}).lights
    scene.lights = [*scene.lights, *behind]
    with Renderer(scene, gl=gl) as renderer:
        renderer.render()
        assert renderer.light_buffer.culled == 1
        assert renderer.light_buffer.count == len(ALL_TYPES)


@pytest.mark.parametrize("pipeline,path", [("forward", "naive"), ("forward", "tiled"),
                                           ("deferred", "tiled")])
def test_a_light_type_culled_in_a_later_frame_adds_no_light(gl, pipeline, path):
    # The loops per light type read each type's range of the light buffer from a uniform; a
    # frame in which every light of a type is culled must set its range empty, not keep the
    # last frame's.
    def lights(point_z):
        return scene_from_dict({"light": [
            {"type": "ambient", "color": [0.1, 0.1, 0.1]},
            {"type": "point", "position": [0.0, 1.0, point_z], "radius": 3.0,
             "intensity": 5.0}]}).lights

    scene = scene_with(0)
    scene.lights = lights(1.0)
    with Renderer(scene, pipeline, gl=gl, light_path=path) as renderer:
        lit = renderer.render().hdr
        renderer.scene.lights = lights(40.0)  # behind the eye: culled
        later = renderer.render().hdr
        assert renderer.light_buffer.culled == 1
    scene.lights = lights(40.0)
    with Renderer(scene, pipeline, gl=gl, light_path=path) as renderer:
        fresh = renderer.render().hdr
    assert lit[..., :3].max() > 2.0 * fresh[..., :3].max()  # the point light did reach it
    np.testing.assert_array_equal(later, fresh)


def test_without_compute_shaders_the_gl33_paths_run(gl):
    gl33 = GLContext(gl.ctx, Features(storage_buffers=False, compute_shaders=False))
    scene = scene_with(4)
    with Renderer(scene, gl=gl33) as renderer:
        assert renderer.light_path == "volumes"
    with Renderer(scene, "forward", gl=gl33) as renderer:
        assert renderer.light_path == "naive"
    with pytest.raises(InputError, match="light_path: light path 'tiled' needs compute "
                                         "shaders"):
        Renderer(scene, gl=gl33, light_path="tiled")


def test_unknown_light_path_is_bad_input(gl):
    with pytest.raises(InputError, match="unknown light path 'fast'"):
        Renderer(scene_with(0), gl=gl, light_path="fast")
    with pytest.raises(InputError, match="light_path"):
        scene_from_dict({"light_path": "fast"})


def test_more_lights_than_the_coarse_lists_hold_is_refused_before_a_frame(gl, monkeypatch):
    # the storage buffer: the lists' counts (960 bytes at 160x96), then the tiled culling's
    # coarse lists, every volume light in each at the most (6 coarse lists)
    if not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    import deferred.lighting.lists as light_lists

    scene = scene_with(200)
    monkeypatch.setattr(light_lists, "MAX_LIST_BYTES", 4096)
    with pytest.raises(InputError, match=r": light: \d+ lights: the light lists need \d+ MiB"):
        Renderer(scene, gl=gl, light_path="tiled")
    Renderer(scene_with(40), gl=gl, light_path="tiled").release()  # 3 KB: accepted
    with Renderer(scene, gl=gl, light_path="volumes") as renderer:  # volumes has no lists
        assert renderer.render().hdr[..., :3].max() > 0.0


def test_lists_past_the_limit_refuse_the_frame_in_one_line(gl, monkeypatch):
    # the shading's texture, sized to the frame's capacity: checked each frame
    if not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    import deferred.lighting.lists as light_lists
    from deferred.errors import RenderError

    monkeypatch.setattr(light_lists, "MAX_LIST_BYTES", 64 * 1024)
    with Renderer(scene_with(200), gl=gl, light_path="clustered") as renderer:
        with pytest.raises(RenderError, match=r"^pass lighting.cull_clusters: a tile's frustum "
                                              r"holds \d+ lights: the light lists need"):
            renderer.render()


def test_more_lights_than_the_gl33_light_texture_holds_is_refused(gl, monkeypatch):
    gl33 = GLContext(gl.ctx, Features(storage_buffers=False, compute_shaders=False))
    scene = scene_with(12)
    monkeypatch.setattr(GLContext, "max_texture_size", property(lambda self: 8))
    with pytest.raises(InputError, match=r": light: 16 lights; .* at most 8 rows"):
        Renderer(scene, gl=gl33)


def test_the_shading_lists_texture_is_sized_to_the_frame_and_refused_past_the_rows(gl):
    """The shading reads the lists from a texture of SLOT_TEXELS texels a slot, sized each frame
    to the lists' capacity: past the rows the driver allows, the frame is refused in one line."""
    from deferred.errors import RenderError
    from deferred.lighting.lists import (
        LIST_ROW_BYTES,
        LIST_TEXTURE_WIDTH,
        SLOT_TEXELS,
        LightLists,
        list_grid,
    )

    grid = list_grid(1920, 1080, clustered=False)  # 32400 lists of 8x8 pixels
    lists = LightLists(gl.ctx)
    try:
        lists.prepare(grid, 100, 0.1, 100.0)
        slots = grid.count * 101
        assert lists.texture.width == LIST_TEXTURE_WIDTH
        assert lists.texture.height == -(-SLOT_TEXELS * slots // LIST_TEXTURE_WIDTH)  # 200 rows
        lists.max_texture_size = 256
        with pytest.raises(RenderError, match=rf"^a tile's frustum holds 400 lights: the light "
                                              rf"lists need \d+ MiB .* \(32400 lists\); the "
                                              rf"limit is {256 * LIST_ROW_BYTES >> 20} MiB"):
            lists.prepare(grid, 400, 0.1, 100.0)
    finally:
        lists.release()


@pytest.mark.parametrize("pipeline, path", [("deferred", "tiled"), ("deferred", "clustered"),
                                            ("forward", "tiled")])
def test_a_renderer_reused_with_other_light_counts_draws_what_a_fresh_one_does(gl, pipeline,
                                                                               path):
    """The lists' buffer and texture are kept and grown across frames: fewer lights after more
    (old entries past the new lists), then more again, then none."""
    if not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    counts = (200, 16, 200, 0)
    with Renderer(scene_with(counts[0]), pipeline, gl=gl, light_path=path) as renderer:
        reused = []
        for count in counts:
            renderer.scene.lights = scene_with(count).lights
            reused.append(renderer.render().hdr)
    for count, image in zip(counts, reused, strict=True):
        with Renderer(scene_with(count), pipeline, gl=gl, light_path=path) as renderer:
            np.testing.assert_array_equal(image, renderer.render().hdr)


def test_pixel_to_view_is_the_inverse_projection_at_pixel_centres():
    """The culling's view positions of pixels (one multiply-add) against the lighting's (the
    inverse projection), for a wide and a tall frame."""
    from deferred.lighting.culling import pixel_to_view
    from deferred.scene.camera import Camera

    for width, height, fov in ((640, 360, 50.0), (200, 500, 90.0)):
        projection = Camera(fov=fov, near=0.1, far=80.0).projection(width / height)
        scale_x, scale_y, offset_x, offset_y = pixel_to_view(projection, width, height)
        rng = np.random.default_rng(3)
        pixels = rng.uniform(0.0, 1.0, (50, 2)) * (width, height)
        ndc = np.column_stack([pixels / (width, height) * 2.0 - 1.0, np.ones((50, 2))])
        rays = ndc @ np.linalg.inv(projection).T
        rays = rays[:, :3] / rays[:, 3:]
        expected = rays[:, :2] / -rays[:, 2:]
        got = pixels * (scale_x, scale_y) + (offset_x, offset_y)
        np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("kind", ["point", "spot", "ambient", "directional"])
def test_a_types_records_in_one_go_are_each_lights_record(kind):
    """LightBuffer.pack asks each light type for all its lights' records at once: point and
    spot compute them in numpy (against the record layout of common/lighting.glsl, computed
    here light by light), the others through each light's own record."""
    import math

    from deferred.interfaces.registry import lights as light_registry
    from deferred.scene.camera import Camera

    rng = np.random.default_rng(7)
    cls = light_registry.get(kind)
    made = []
    for _ in range(6):
        values = {"color": rng.uniform(0.0, 1.0, 3).tolist(),
                  "intensity": float(rng.uniform(0.5, 3.0))}
        if kind in ("point", "spot"):
            values |= {"position": rng.uniform(-3.0, 3.0, 3).tolist(),
                       "radius": float(rng.uniform(0.5, 6.0))}
        if kind in ("spot", "directional"):
            values["direction"] = rng.uniform(-1.0, 1.0, 3).tolist()
        made.append(cls.from_dict(values))
    view = Camera(position=(1.0, 2.0, 4.0), target=(0.0, 0.5, 0.0)).view()
    together = cls.records(made, view)
    if kind in ("point", "spot"):
        expected = np.zeros((len(made), 4, 4))
        for k, light in enumerate(made):
            p = light.params
            expected[k, 0, :3] = np.asarray(p.color) * p.intensity
            expected[k, 1, :3] = (view @ np.append(p.position, 1.0))[:3]
            expected[k, 1, 3] = p.radius
            if kind == "spot":
                axis = view[:3, :3] @ np.asarray(p.direction)
                expected[k, 2, :3] = axis / np.linalg.norm(axis)
                expected[k, 2, 3] = math.cos(math.radians(p.outer_angle))
                expected[k, 3, 0] = math.cos(math.radians(p.inner_angle))
    else:
        expected = np.stack([np.asarray(light.record(view), np.float32) for light in made])
    np.testing.assert_allclose(together, expected, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(made[0].record(view), together[0], rtol=1e-6, atol=1e-6)
    assert cls.records([], view).shape == (0, 4, 4)


def test_a_light_type_gone_from_the_scene_adds_no_light(gl):
    # Programs keep the range their light type was given last: a type removed from the scene
    # between frames must get an empty range, as one culled does.
    scene = scene_with(0)
    with Renderer(scene, "forward", gl=gl, light_path="naive") as renderer:
        lit = renderer.render().hdr
        renderer.scene.lights = [light for light in scene.lights
                                 if type(light).__name__ != "SpotLight"]
        later = renderer.render().hdr
    assert len(scene.lights) == len(ALL_TYPES) - 1
    with Renderer(scene, "forward", gl=gl, light_path="naive") as renderer:
        fresh = renderer.render().hdr
    assert not np.array_equal(lit, fresh)  # the spot light did reach it
    np.testing.assert_array_equal(later, fresh)


@pytest.mark.parametrize("pipeline, path", [("deferred", "tiled"), ("forward", "naive")])
def test_a_renderer_follows_a_light_and_the_camera_changed_between_frames(gl, pipeline, path):
    """The light records are packed again only when the lights, their (frozen) parameters or
    the camera change: a frame after each change draws what a fresh renderer does."""
    from dataclasses import replace

    if path == "tiled" and not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    scene = scene_with(40)
    point = next(light for light in scene.lights if type(light).__name__ == "PointLight")
    brighter = point.params.model_copy(update={"intensity": point.params.intensity * 3.0})
    moved = replace(scene.camera, position=(0.6, 1.9, 4.0))
    with Renderer(scene, pipeline, gl=gl, light_path=path) as renderer:
        first = renderer.render().hdr
        assert np.array_equal(renderer.render().hdr, first)  # nothing changed
        point.params = brighter
        after_light = renderer.render().hdr
        renderer.scene.camera = moved
        after_camera = renderer.render().hdr
    assert not np.array_equal(after_light, first)
    with Renderer(scene, pipeline, gl=gl, light_path=path) as renderer:
        np.testing.assert_array_equal(renderer.render().hdr, after_camera)
    scene.camera = replace(moved, position=(0.0, 1.6, 4.2))  # scene_with's camera
    with Renderer(scene, pipeline, gl=gl, light_path=path) as renderer:
        np.testing.assert_array_equal(renderer.render().hdr, after_light)


@pytest.mark.parametrize("path", ["tiled", "clustered"])
def test_the_list_shading_makes_the_composition_where_the_material_phase_has_no_pass(gl, path):
    """The list shading writes the composition buffer too (there is no copy), and with
    Revie's fur the stipple snapshot the material phase takes before its first write to the
    composition (no pass of its own either): the same values as the light accumulation."""
    if not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    with Renderer(scene_with(16), "deferred", gl=gl, light_path=path) as renderer:
        names = [p.name for p in renderer.passes]
        assert "material.composite_copy" not in names
        assert renderer.graph.creators["composite"] == f"lighting.{path}"
        renderer.render()
        np.testing.assert_array_equal(renderer.targets.read("composite"),
                                      renderer.targets.read("light_accumulation"))
    with Renderer(load_scene(), "deferred", (96, 64), gl=gl, light_path=path) as renderer:
        names = [p.name for p in renderer.passes]
        assert "material.composite_copy" not in names
        assert "material.stipple_snapshot" not in names
        shading = renderer.passes[renderer.graph.index(f"lighting.{path}")]
        assert set(shading.creates) == {"light_accumulation", "composite", "composite_snapshot"}
        snapshots = []
        renderer.render(on_pass=lambda p, frame: snapshots.append(
            frame.targets.read("composite_snapshot")) if p is shading else None)
        np.testing.assert_array_equal(snapshots[0], renderer.targets.read("light_accumulation"))
        np.testing.assert_array_equal(snapshots[0], renderer.targets.read("composite_snapshot"))
    with Renderer(load_scene(), "deferred", (96, 64), gl=gl, light_path="volumes") as renderer:
        names = [p.name for p in renderer.passes]
        assert names.index("material.composite_copy") < names.index("material.stipple_snapshot")


def test_several_full_screen_lights_of_a_type_each_light_the_list_and_forward_paths(gl):
    # Their records come from the uniform array (four vec4s a light, the types' ranges into
    # it); the volumes path draws each from the light texture instead: every record must land.
    fill = [{"type": "directional", "direction": d, "intensity": 0.5, "color": c}
            for d, c in [([1.0, -0.4, 0.2], [1.0, 0.4, 0.3]), ([-0.2, -0.5, -1.0], [0.3, 1.0, 0.4]),
                         ([0.0, -1.0, 0.6], [0.3, 0.5, 1.0])]]
    scene = scene_with(8)
    scene.lights = [*scene.lights[:2], *map(scene_light, fill), *scene.lights[2:]]
    reference, _ = render(gl, scene, "deferred", "volumes")
    peak = float(reference.hdr[..., :3].max())
    fewer = scene_with(8)
    assert psnr(render(gl, fewer, "deferred", "volumes")[0].hdr[..., :3],
                reference.hdr[..., :3], peak) < 30.0  # the three lights show
    for pipeline, path in [("deferred", "tiled"), ("forward", "tiled"), ("forward", "naive")]:
        result, _ = render(gl, scene, pipeline, path)
        assert psnr(result.hdr[..., :3], reference.hdr[..., :3], peak) >= 40.0, (pipeline, path)


def scene_light(values: dict):
    from deferred.interfaces.registry import lights

    return lights.get(values["type"]).from_dict({k: v for k, v in values.items() if k != "type"})


def test_more_full_screen_lights_than_a_frame_holds_is_refused_before_a_frame(gl):
    from deferred.lighting.dispatch import FULLSCREEN_LIGHT_CAPACITY

    scene = scene_with(0)
    scene.lights = [*scene.lights, *(scene_light({"type": "directional", "intensity": 0.1})
                                     for _ in range(FULLSCREEN_LIGHT_CAPACITY - 1))]
    with pytest.raises(InputError, match=rf": light: {FULLSCREEN_LIGHT_CAPACITY + 1} full-screen "
                                         rf".* at most {FULLSCREEN_LIGHT_CAPACITY}$"):
        Renderer(scene, gl=gl, light_path="volumes")
    scene.lights = scene.lights[:-1]  # at the capacity: renders
    with Renderer(scene, "forward", gl=gl, light_path="naive") as renderer:
        assert renderer.render().hdr[..., :3].max() > 0.0


@pytest.mark.parametrize("path", ["tiled", "clustered"])
def test_the_shading_copy_of_the_lists_holds_each_listed_lights_sphere_and_index(gl, path):
    # Every light type: the shading reads a reached light's colour, type and (spot) cone from
    # the light buffer at the listed index
    frame = listed_frame(gl, path, 60)
    grid, capacity, records = frame.grid, frame.capacity, frame.records
    spheres, indices = frame.slots
    np.testing.assert_array_equal(spheres[:grid.count, 0].view(np.uint32), frame.counts)
    types = set()
    for list_index, listed in enumerate(frame.entries):
        first = grid.count + list_index * capacity
        index = listed.astype(np.int64)
        np.testing.assert_array_equal(indices[first:first + len(listed)], index)
        held = spheres[first:first + len(listed)]
        np.testing.assert_array_equal(held[:, :3], records[index, 1, :3])  # the centre
        radius = records[index, 1, 3]  # a half float, rounded up: the test stays conservative
        assert np.all(held[:, 3] >= radius) and np.all(held[:, 3] <= radius * (1 + 2.0 ** -10))
        types |= set(records[index, 0, 3].tolist())
    assert types == {3.0, 4.0}  # point and spot lights were listed


def test_a_radius_past_a_half_float_is_refused_on_the_list_paths(gl):
    from deferred.scene.loader import scene_from_dict

    if not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    huge = scene_from_dict({"size": [32, 24], "object": [{"mesh": "builtin:plane"}],
                            "light": [{"type": "point", "position": [0.0, 1.0, 0.0],
                                       "radius": 70000.0}]})
    # refused before a frame, naming the light
    with pytest.raises(InputError, match=r"^<dict>: light\[0\]\.radius: a radius of 70000 is "
                                         r"more than the light lists hold \(65504, a half float\)"):
        Renderer(huge, gl=gl, light_path="tiled")
    with Renderer(huge, gl=gl, light_path="volumes") as renderer:
        assert renderer.render().hdr[..., :3].max() > 0.0
    # and a light given that radius after the renderer was made, at the frame
    small = scene_from_dict({"size": [32, 24], "object": [{"mesh": "builtin:plane"}],
                             "light": [{"type": "point", "position": [0.0, 1.0, 0.0],
                                        "radius": 7.0}]})
    with Renderer(small, gl=gl, light_path="tiled") as renderer:
        small.lights = huge.lights
        with pytest.raises(InputError, match=r"^light: a light's radius of 70000 is more than "
                                             r"the light lists hold \(65504, a half float\)"):
            renderer.render()


def side_plane_counts(spheres, inverse, width, height, tile, slices=None):
    """Lights touching each tile's side planes, tile by tile as tile_frustum.glsl builds them
    (float64), and with ``slices`` (near, far, count) each of the tile's depth slices their
    depth range covers as cull_clusters.comp assigns them: the reference of list_capacity."""
    def slice_of(d, near, far, count):
        return np.clip(np.floor(np.log(np.maximum(d, near) / near) * count / np.log(far / near)),
                       0, count - 1)
    def ray(x, y):
        v = inverse @ np.array([x / width * 2 - 1, y / height * 2 - 1, 1.0, 1.0])
        return v[:3] / v[3]
    counts = []
    for y0 in range(0, height, tile):
        for x0 in range(0, width, tile):
            x1, y1 = min(x0 + tile, width), min(y0 + tile, height)
            r00, r10, r01, r11 = ray(x0, y0), ray(x1, y0), ray(x0, y1), ray(x1, y1)
            centre = r00 + r10 + r01 + r11
            inside = np.ones(len(spheres), bool)
            for a, b in ((r01, r00), (r10, r11), (r00, r10), (r11, r01)):
                n = np.cross(a, b)
                n /= np.linalg.norm(n)
                n = n if n @ centre >= 0 else -n
                inside &= spheres[:, :3] @ n >= -spheres[:, 3]
            if slices is None:
                counts.append(int(inside.sum()))
                continue
            near, far, count = slices
            low, high = -spheres[:, 2] - spheres[:, 3], -spheres[:, 2] + spheres[:, 3]
            inside &= (high >= near) & (low <= far)
            first = slice_of(np.maximum(low, near), near, far, count)
            last = slice_of(high, near, far, count)
            counts += [int((inside & (first <= k) & (k <= last)).sum()) for k in range(count)]
    return np.array(counts)


@pytest.mark.parametrize("pipeline, path", [("deferred", "tiled"), ("deferred", "clustered"),
                                            ("forward", "tiled")])  # Forward+: from the near
@pytest.mark.parametrize("size", [(320, 192), (317, 189)])  # odd: partial tiles
def test_the_lists_capacity_bounds_every_list_and_is_the_side_planes_count(gl, pipeline, path,
                                                                           size):
    from deferred.lighting.lists import coarse_grid, list_capacity

    if not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    scene = scene_with(150)
    with Renderer(scene, pipeline, size, gl=gl, light_path=path) as renderer:
        renderer.render()
        lists = renderer.light_lists
        grid, capacity, coarse_capacity = lists.grid, lists.capacity, lists.coarse_capacity
        raw = np.frombuffer(lists.buffer.read(), dtype=np.uint32)
        spheres = renderer.light_buffer.volume_spheres.astype(np.float64)
        inverse = renderer.last_frame.inverse_projection
        local = renderer.light_buffer.local_count
        camera = renderer.scene.camera
    slices = (camera.near, camera.far, grid.slices) if path == "clustered" else None
    reference = side_plane_counts(spheres, inverse, *size, grid.tile, slices)
    assert capacity == list_capacity(spheres, inverse, *size, grid.tile, slices)
    # the count of the planes, padded a little for the GPU's float32 planes
    assert reference.max() <= capacity <= reference.max() + 2
    assert capacity < 0.5 * local  # far fewer slots than lights: the memory it saves
    assert raw[:grid.count].max() <= capacity  # no list overflowed
    assert raw[:grid.count].max() > 0.5 * capacity  # the bound is near
    if path == "tiled":  # and the coarse lists, after the lists, with their own capacity
        coarse = coarse_grid(grid)
        coarse_reference = side_plane_counts(spheres, inverse, *size, coarse.tile)
        assert coarse_reference.max() <= coarse_capacity <= coarse_reference.max() + 2
        assert coarse_capacity > capacity  # a coarse tile's planes hold more
        base = lists.coarse_base
        assert raw[base:base + coarse.count].max() <= coarse_capacity
        assert raw[base:base + coarse.count].max() > 0.8 * coarse_capacity


def test_more_lights_than_a_listed_lights_index_holds_is_refused(monkeypatch):
    # a listed light's texel holds its index in 16 bits beside its half-float radius
    import deferred.lighting.lists as light_lists

    assert light_lists.MAX_LISTED_LIGHTS <= 1 << 16  # a listed light's index: 16 bits
    monkeypatch.setattr(light_lists, "MAX_LISTED_LIGHTS", 41)
    light_lists.check_light_limits("tiled", (160, 96), 39, 41, max_texture_size=16384)
    with pytest.raises(InputError, match=r"^light: 42 lights; the light lists index at most 41$"):
        light_lists.check_light_limits("clustered", (160, 96), 40, 42, max_texture_size=16384)
    light_lists.check_light_limits("volumes", (160, 96), 40, 42, max_texture_size=16384)


@pytest.mark.parametrize("pipeline, path", [("deferred", "tiled"), ("deferred", "clustered"),
                                            ("forward", "tiled")])
def test_the_light_lists_view_shows_the_length_of_each_pixels_list(gl, pipeline, path):
    from deferred.debug.capture import capture_frame
    from deferred.debug.views import view

    if not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    with Renderer(scene_with(120), pipeline, (157, 93), gl=gl, light_path=path) as renderer:
        capture = capture_frame(renderer)
        lists = renderer.light_lists
        grid = lists.grid
        counts = np.minimum(np.frombuffer(lists.buffer.read(size=4 * grid.count), np.uint32),
                            lists.capacity)
        camera = renderer.scene.camera
    shown = view(capture, "light_lists")
    assert shown.channels == ("lights.listed",) and shown.pixels.shape == (93, 157, 1)
    # each pixel's list as light_list_of finds it (top row first, as the capture keeps it)
    ys, xs = np.mgrid[92:-1:-1, 0:157]
    tile = np.minimum(ys // grid.tile, grid.rows - 1) * grid.columns + \
        np.minimum(xs // grid.tile, grid.columns - 1)
    if pipeline == "deferred":
        depth = capture.target("linear_depth")[..., 0]
        if path == "clustered":
            near, far = camera.near, camera.far
            slices = np.clip(np.floor(np.log(np.maximum(depth, near) / near) * grid.slices /
                                      np.log(far / near)), 0, grid.slices - 1).astype(int)
            tile = slices * grid.rows * grid.columns + tile
        expected = np.where(depth > 0.0, counts[tile], 0)
        assert (depth == 0.0).any() and (expected[depth > 0.0] > 0).all()
    else:  # Forward+: every fragment drawn reads its tile's list
        expected = counts[tile]
    np.testing.assert_array_equal(shown.pixels[..., 0], expected)
    assert len(np.unique(expected)) > 5  # the lists differ over the frame
    lit = shown.pixels[..., 0] > 0
    assert (shown.preview[~lit] == 0.0).all() and (shown.preview[lit].max(axis=-1) > 0.0).all()


def test_the_light_lists_view_needs_a_path_with_lists(gl):
    from deferred.debug.views import resolve_view

    with Renderer(scene_with(4), gl=gl, light_path="volumes") as renderer:
        with pytest.raises(InputError, match=r"^--view: view 'light_lists' shows the light "
                                             r"lists, which only the tiled and clustered"):
            resolve_view("light_lists", renderer.passes)


def mixed_scene(points_culled: bool):
    """scene_with(120) with every other extra light a spot of the same sphere; with
    ``points_culled``, the point lights all behind the camera (culled before upload: the point
    type's range is empty this frame while the spots are listed)."""
    from deferred.lights.point import PointLight
    from deferred.lights.spot import SpotLight

    scene = scene_with(120)
    lights = []
    for index, light in enumerate(scene.lights):
        if light.name != "point":
            lights.append(light)
            continue
        p = light.params
        if index % 2:
            lights.append(SpotLight.from_dict({
                "position": tuple(p.position), "radius": p.radius, "color": tuple(p.color),
                "intensity": p.intensity, "direction": (0.3, -1.0, 0.2), "inner_angle": 25.0,
                "outer_angle": 50.0}))
        elif points_culled:
            lights.append(PointLight.from_dict({"position": (0.0, 1.6, 9.0), "radius": 1.0}))
        else:
            lights.append(light)
    scene.lights = lights
    return scene


@pytest.mark.parametrize("points_culled", [False, True])
@pytest.mark.parametrize("pipeline, path, reference_path", [
    ("deferred", "tiled", "volumes"), ("deferred", "clustered", "volumes"),
    ("forward", "tiled", "naive")])
def test_lists_of_point_and_spot_lights_give_the_reference_image(gl, points_culled, pipeline,
                                                                  path, reference_path):
    """The list loops run a loop per light type over its entries (a list holds its lights in
    light order, the light buffer its types in order): points and spots mixed, and spots alone
    where every point light is culled, give the image of the path with no lists."""
    from deferred.interfaces.registry import lights as light_types

    scene = mixed_scene(points_culled)
    reference, _ = render(gl, scene, pipeline, reference_path)
    result, used = render(gl, scene, pipeline, path)
    assert used == path
    peak = float(reference.hdr[..., :3].max())
    assert psnr(result.hdr[..., :3], reference.hdr[..., :3], peak) >= 40.0
    with Renderer(scene, pipeline, gl=gl, light_path=path) as renderer:
        renderer.render()
        point, spot = (renderer.light_buffer.range(light_types.get(name))[1]
                       for name in ("point", "spot"))
    assert spot == 61 and point == (0 if points_culled else 61)  # with the scene's own two
