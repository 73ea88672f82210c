"""Buffer dumps: EXR round trip, stipple captures, pixel history, --compare, --view, the CLI."""

import json
import os

import numpy as np
import OpenImageIO as oiio
import pytest
from locations import FIXTURES

from deferred.cli import main
from deferred.core.passes import FullscreenPass, Phase
from deferred.debug.capture import GBUFFER_CHANNELS, capture_frame
from deferred.debug.compare import compare_dumps
from deferred.debug.dump import contact_tiles, write_dump
from deferred.debug.pixel_history import pixel_history
from deferred.debug.views import view
from deferred.gbuffer.layout import decode
from deferred.interfaces import registry
from deferred.io.images import read_channels, read_image, write_image
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SIZE = (160, 120)


def small_scene(ball_color=(0.8, 0.3, 0.2), lights=None, objects=None):
    """A floor filling the lower part of the frame and a ball in front of it."""
    return scene_from_dict({
        "size": list(SIZE), "light_path": "volumes",  # a pass per light type
        "camera": {"position": [0.0, 1.2, 3.0], "target": [0.0, 0.4, 0.0]},
        "object": objects or [
            {"name": "floor", "mesh": "builtin:plane", "scale": 4.0,
             "params": {"color": [0.4, 0.4, 0.4]}},
            {"name": "ball", "mesh": "builtin:sphere", "position": [0.0, 0.5, 0.0],
             "scale": 0.5, "params": {"color": list(ball_color), "specular_exponent": 48.0}},
        ],
        "light": lights or [
            {"type": "ambient", "color": [0.2, 0.2, 0.25]},
            {"type": "directional", "direction": [-0.4, -1.0, -0.5], "intensity": 0.8},
            {"type": "point", "position": [1.0, 1.0, 1.0], "intensity": 3.0, "radius": 4.0},
        ]})


@pytest.fixture
def renderer(gl):
    made = []

    def make(scene, pipeline="deferred"):
        r = Renderer(scene, pipeline, gl=gl)
        made.append(r)
        return r

    yield make
    for r in made:
        r.release()


def reference_buffers(renderer):
    """What each pass wrote, read straight from GL after it ran (top row first, float32)."""
    after = {}

    def keep(render_pass, frame):
        after[render_pass.name] = {t: frame.targets.read(t)[::-1].copy()
                                   for t in render_pass.writes}

    renderer.render(on_pass=keep)
    return after


def as_half(values):
    return np.asarray(values, np.float32).astype(np.float16).astype(np.float32)


def test_gbuffer_exr_round_trip(tmp_path, renderer):
    r = renderer(small_scene())
    capture = capture_frame(r)
    write_dump(capture, tmp_path)
    t = r.targets
    g = decode(t.read("albedo_specular")[::-1], t.read("normal_exponent_id")[::-1],
               t.read("linear_depth")[::-1])

    image = oiio.ImageInput.open(str(tmp_path / "gbuffer.exr"))
    spec = image.spec()
    raw = image.read_image(format=oiio.FLOAT)
    image.close()
    assert sorted(spec.channelnames) == sorted(GBUFFER_CHANNELS)
    assert spec.channelnames[spec.z_channel] == "Z"  # the EXR's depth channel
    assert spec.format == oiio.FLOAT
    assert raw.shape == (SIZE[1], SIZE[0], len(GBUFFER_CHANNELS))

    pixels, names, attributes = read_channels(tmp_path / "gbuffer.exr")
    assert names == list(GBUFFER_CHANNELS)  # written order survives EXR's sorting
    assert attributes["z_channel"] == names.index("Z")
    c = {name: pixels[..., k] for k, name in enumerate(names)}
    covered = g["material_id"] > 0
    np.testing.assert_array_equal(np.stack([c["albedo.R"], c["albedo.G"], c["albedo.B"]], -1),
                                  g["albedo"])
    np.testing.assert_array_equal(c["specular.intensity"], g["specular_intensity"])
    np.testing.assert_array_equal(c["specular.exponent"], g["specular_exponent"])
    np.testing.assert_array_equal(c["Z"], g["linear_depth"])
    np.testing.assert_array_equal(c["material.id"], g["material_id"])
    np.testing.assert_array_equal(c["shading.model"], g["shading_model"])
    normal = np.stack([c["N.X"], c["N.Y"], c["N.Z"]], -1)
    np.testing.assert_allclose(normal[covered], g["normal"][covered], atol=1e-6)
    assert np.all(normal[~covered] == 0.0)
    # top-down: sky above, floor at the bottom, nearest at the bottom row
    assert np.all(c["Z"][0] == 0.0) and np.all(c["Z"][-1] > 0.0)
    assert c["Z"][-1].mean() < c["Z"][SIZE[1] // 2][covered[SIZE[1] // 2]].mean()


def test_pass_files_hold_what_each_pass_wrote(tmp_path, renderer):
    r = renderer(small_scene())
    capture = capture_frame(r)
    manifest = write_dump(capture, tmp_path)
    reference = reference_buffers(r)  # a second frame: rendering is deterministic
    assert [p["name"] for p in manifest["passes"]] == [p.name for p in r.passes]
    for entry in manifest["passes"]:
        path = tmp_path / entry["file"]
        assert path.name.startswith(f"{entry['index']:02d}_")
        pixels, names, _ = read_channels(path)
        specs = {t: r.targets.specs[t] for t in entry["outputs"]}
        half = all(s.dtype in ("f1", "f2") and not s.depth for s in specs.values())
        expected_names = []
        for target, spec in specs.items():
            suffixes = "Z" if spec.depth else "RGBA"[: spec.components]
            expected_names += [f"{target}.{s}" for s in suffixes]
        assert names == expected_names == entry["channels"]
        k = 0
        for target, values in reference[entry["name"]].items():
            stored = pixels[..., k: k + values.shape[2]]
            np.testing.assert_array_equal(stored, as_half(values) if half else values,
                                          err_msg=f"{entry['name']}: {target}")
            if r.targets.specs[target].dtype == "f1":  # 8-bit codes come back exactly
                np.testing.assert_array_equal(np.rint(stored * 255), np.rint(values * 255))
            k += values.shape[2]
    light, names, _ = read_channels(tmp_path / "light.exr")
    assert names == ["R", "G", "B"]
    np.testing.assert_array_equal(light, r.targets.read("light_accumulation")[::-1][..., :3])
    final, names, attributes = read_channels(tmp_path / "final.exr")
    assert names == ["R", "G", "B", "A"] and attributes["alpha_channel"] == 3
    np.testing.assert_array_equal(final, r.targets.read("composite")[::-1])
    png = read_image(tmp_path / "final.png")
    np.testing.assert_array_equal(np.rint(png * 255).astype(np.uint8), capture.image)


def test_manifest_describes_the_frame(tmp_path, renderer, gl):
    r = renderer(small_scene())
    manifest = write_dump(capture_frame(r), tmp_path)
    on_disk = json.loads((tmp_path / "manifest.json").read_text())
    assert on_disk == json.loads(json.dumps(manifest))
    assert manifest["gl"]["renderer"] == gl.info["renderer"]
    assert manifest["scene"] == "<dict>" and manifest["size"] == list(SIZE)
    assert manifest["gbuffer"]["bytes_per_pixel"] == 20
    assert manifest["gbuffer"]["channels"] == list(GBUFFER_CHANNELS)
    assert manifest["gbuffer"]["targets"]["normal_exponent_id"]["format"] == "RGBA16F"
    for entry, render_pass in zip(manifest["passes"], r.passes, strict=True):
        assert entry["phase"] == render_pass.phase.value
        assert entry["inputs"] == list(render_pass.reads)
        assert entry["outputs"] == list(render_pass.writes)
        assert set(entry["formats"]) == set(render_pass.reads) | set(render_pass.writes)
        assert entry["time_ms"] > 0.0
    light = next(p for p in manifest["passes"] if p["name"] == "lighting.point")
    assert light["formats"]["light_accumulation"] == "RGBA16F"
    assert light["formats"]["linear_depth"] == "R32F"
    assert manifest["frame_ms"] == pytest.approx(sum(p["time_ms"] for p in manifest["passes"]),
                                                 abs=1e-2)
    assert "pixel_history" not in manifest
    for name in manifest["files"].values():
        assert (tmp_path / name).is_file()
    assert not [p for p in tmp_path.rglob(".*")]  # no temporaries left behind
    assert (tmp_path / "final.png").stat().st_mode & 0o777 == 0o666 & ~_umask()


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_capture_api_gives_named_arrays_per_pass(renderer):
    r = renderer(small_scene())
    capture = capture_frame(r, passes=["ball.*", "lighting.point"])
    assert [p.name for p in capture.passes if p.captured] == ["ball.gbuffer", "lighting.point"]
    ball = capture["ball.gbuffer"]
    assert set(ball.arrays) == {"albedo_specular", "normal_exponent_id", "linear_depth",
                                "depth"}
    channels = ball.channels()
    assert list(channels)[:4] == [f"albedo_specular.{c}" for c in "RGBA"]
    assert channels["depth.Z"].shape == (SIZE[1], SIZE[0])
    red = np.isclose(channels["albedo_specular.R"], 0.8, atol=1 / 255)
    assert 0.05 < red.mean() < 0.5
    assert not capture["lighting.directional"].raw
    with pytest.raises(KeyError):  # the pass before it was not captured
        capture.before("lighting.point")
    full = capture_frame(r)
    point = full["lighting.point"].arrays["light_accumulation"]
    before = full.before("lighting.point")["light_accumulation"]
    assert np.all(point >= before) and np.any(point > before)  # a light only adds


def stipple_property(capture, name):
    """Pixels the stipple pass changed (any channel of any target it wrote)."""
    before = capture.before(name)
    after = capture[name].arrays
    changed = np.zeros(capture.size[::-1], bool)
    for target, values in after.items():
        changed |= np.any(values != before[target], axis=-1)
    ys, xs = np.nonzero(changed)
    return changed, set(zip((ys % 2).tolist(), (xs % 2).tolist(), strict=True))


def test_stipple_capture_differs_in_one_parity_class(renderer):
    from stipple_material import StippleMaterial

    registry.materials.register(StippleMaterial)
    try:
        scene = small_scene(objects=[
            {"name": "floor", "mesh": "builtin:plane", "scale": 4.0},
            {"name": "ball", "mesh": "builtin:sphere", "material": "test_stipple",
             "position": [0.0, 0.5, 0.0], "scale": 0.6}])
        capture = capture_frame(renderer(scene))
    finally:
        registry.materials.unregister(StippleMaterial.name)
    stipple = capture["ball.stipple"]
    assert stipple.phase == "stipple"
    changed, classes = stipple_property(capture, "ball.stipple")
    # GL (odd x, even y) is top-down (odd x, odd y) in a frame 120 rows high
    assert classes == {(1, 1)}
    # where the ball covers a whole 2x2 tile, exactly one of its four pixels changed
    ball = capture["ball.gbuffer"].arrays["linear_depth"][..., 0] != \
        capture.before("ball.gbuffer")["linear_depth"][..., 0]
    tiles = ball.reshape(SIZE[1] // 2, 2, SIZE[0] // 2, 2).all(axis=(1, 3))
    per_tile = changed.reshape(SIZE[1] // 2, 2, SIZE[0] // 2, 2).sum(axis=(1, 3))
    assert tiles.sum() > 200
    assert np.all(per_tile[tiles] == 1)
    assert not changed[~ball].any()


@pytest.mark.slow
@pytest.mark.skipif("revie_fur" not in registry.materials,
                    reason="the revie_fur material is not registered (being written)")
def test_revie_fur_stipple_capture_differs_in_one_pixel_per_tile(tmp_path, renderer):
    scene = small_scene(objects=[
        {"name": "floor", "mesh": "builtin:plane", "scale": 4.0},
        {"name": "fur", "mesh": "builtin:sphere", "material": "revie_fur",
         "position": [0.0, 0.5, 0.0], "scale": 0.5, "params": {"shells": 4}}])
    capture = capture_frame(renderer(scene))
    stipple = capture["fur.stipple"]
    assert stipple.phase == "stipple"
    changed, _ = stipple_property(capture, "fur.stipple")
    # one pixel of a 2x2 tile, which one varying from tile to tile (stipple.glsl)
    tiles = changed.reshape(SIZE[1] // 2, 2, SIZE[0] // 2, 2).sum(axis=(1, 3))
    assert changed.sum() > 100 and tiles.max() == 1
    manifest = write_dump(capture, tmp_path)
    files = {p["name"]: p["file"] for p in manifest["passes"]}
    assert (tmp_path / files["fur.stipple"]).is_file()
    assert (tmp_path / files["fur.stipple_obliteration"]).is_file()


@pytest.mark.slow
def test_compare_same_scene_is_zero_and_a_change_stays_on_the_object(tmp_path, renderer):
    first, same, changed = tmp_path / "a", tmp_path / "b", tmp_path / "c"
    write_dump(capture_frame(renderer(small_scene())), first)
    write_dump(capture_frame(renderer(small_scene())), same)
    r = renderer(small_scene(ball_color=(0.2, 0.3, 0.8)))
    capture = capture_frame(r)
    write_dump(capture, changed)

    results = compare_dumps(first, same, tmp_path / "same-diff")
    assert len(results) == 3 + len(r.passes)  # gbuffer, light, final + passes
    assert all(d.problem is None and d.max == 0.0 and d.pixels == 0 for d in results)
    assert sorted(p.name for p in (tmp_path / "same-diff").rglob("*")) == ["compare.json"]

    out = tmp_path / "diff"
    results = {d.buffer: d for d in compare_dumps(first, changed, out)}
    ball = capture["ball.gbuffer"].arrays["linear_depth"][..., 0] != \
        capture.before("ball.gbuffer")["linear_depth"][..., 0]
    for key in ("gbuffer.exr", "final.exr", "light.exr", "passes/ball.gbuffer",
                "passes/post.tonemap"):
        diff = results[key]
        assert diff.problem is None and diff.max > 0.0, key
        assert 0 < diff.pixels <= ball.sum(), key
        image, _, _ = read_channels(out / diff.image)
        assert not image[~ball].any(), f"{key} differs off the ball"
        assert (out / diff.image.replace(".exr", ".png")).is_file()
    for key in ("passes/gbuffer.clear", "passes/floor.gbuffer"):
        assert results[key].max == 0.0 and results[key].image is None
    assert results["gbuffer.exr"].per_channel_max["Z"] == 0.0
    assert results["gbuffer.exr"].per_channel_max["albedo.B"] == pytest.approx(0.6, abs=0.01)
    saved = json.loads((out / "compare.json").read_text())
    assert {b["buffer"] for b in saved["buffers"]} == set(results)


def test_pixel_history_lists_the_passes_that_wrote_a_pixel(renderer):
    lights = [{"type": "ambient", "color": [0.2, 0.2, 0.2]},
              {"type": "point", "position": [0.5, 1.0, 1.5], "intensity": 2.0, "radius": 6.0},
              {"type": "point", "position": [-0.5, 1.0, 1.5], "intensity": 2.0,
               "radius": 6.0}]
    # the ball is drawn before the floor: the floor's fragments behind it fail the depth test
    scene = small_scene(lights=lights, objects=[
        {"name": "ball", "mesh": "builtin:sphere", "position": [0.0, 0.5, 0.0], "scale": 0.5,
         "params": {"color": [0.8, 0.2, 0.2]}},
        {"name": "floor", "mesh": "builtin:plane", "scale": 4.0}])
    r = renderer(scene)
    capture = capture_frame(r)
    ball = capture["ball.gbuffer"].arrays["albedo_specular"][..., 0] > 0.5
    ys, xs = np.nonzero(ball)
    x, y = int(np.median(xs)), int(np.median(ys))  # the middle of the ball
    assert ball[y, x]
    events = {e.name: e for e in pixel_history(r, x, y)}
    wrote = [name for name, e in events.items() if e.wrote]
    assert wrote == ["gbuffer.clear", "ball.gbuffer", "lighting.background", "lighting.ambient",
                     "lighting.point", "material.composite_copy", "post.tonemap"]
    assert events["floor.gbuffer"].fragments == 0
    assert events["ball.gbuffer"].fragments == 1
    assert events["lighting.point"].fragments == 2  # one per light
    assert events["gbuffer.clear"].fragments is None
    albedo = events["ball.gbuffer"].after["albedo_specular"]
    assert np.rint(np.array(albedo[:3]) * 255).tolist() == \
        np.rint(np.array([0.8, 0.2, 0.2]) * 255).tolist()
    assert set(events["gbuffer.clear"].cleared_to) == set(events["gbuffer.clear"].after)
    assert events["gbuffer.clear"].cleared_to["depth"] == [1.0]
    assert events["post.tonemap"].first_writes == ("final",)
    assert events["lighting.point"].first_writes == ()  # the background pass wrote it first
    lit = events["lighting.point"]
    assert all(a > b for a, b in zip(lit.after["light_accumulation"][:3],
                                     lit.before["light_accumulation"][:3], strict=True))
    for target in ("light_accumulation", "composite", "final"):
        last = [e for e in events.values() if target in e.after][-1]
        np.testing.assert_array_equal(last.after[target], capture.target(target)[y, x])
    # the probes leave the frame as it was
    assert np.array_equal(r.render().image, capture.image)

    sky = pixel_history(r, 0, 0)
    assert [e.name for e in sky if e.wrote] == ["gbuffer.clear", "lighting.background",
                                                "material.composite_copy", "post.tonemap"]


@pytest.mark.parametrize("light_path, passes", [
    ("volumes", ("lighting.background", "lighting.ambient", "lighting.directional")),
    ("tiled", ("lighting.tiled",)), ("clustered", ("lighting.clustered",))])
def test_full_screen_lighting_runs_on_surfaces_only(gl, light_path, passes):
    """The full-screen lighting passes draw on the far plane with the depth test "greater":
    no fragment on the background (llvmpipe skips such blocks; an `if` would not), one on a
    surface, and the background pixel still holds the scene's background (its pass clears the
    light accumulation to it)."""
    scene = small_scene()
    scene.background = (0.25, 0.5, 0.75)
    r = Renderer(scene, "deferred", gl=gl, light_path=light_path)
    try:
        capture = capture_frame(r)
        depth = capture.target("depth")[..., 0]
        sky_y, sky_x = (int(v[0]) for v in np.nonzero(depth >= 1.0))
        floor_y, floor_x = (int(v[-1]) for v in np.nonzero(depth < 1.0))
        sky = {e.name: e for e in pixel_history(r, sky_x, sky_y)}
        floor = {e.name: e for e in pixel_history(r, floor_x, floor_y)}
        for name in passes:
            assert sky[name].fragments == 0 and floor[name].fragments == 1, name
        assert sky[passes[0]].cleared and sky[passes[0]].wrote
        background = np.array(capture.target("light_accumulation")[sky_y, sky_x], np.float32)
        np.testing.assert_allclose(background, [0.25, 0.5, 0.75, 0.0], atol=1e-3)
        assert capture.target("light_accumulation")[floor_y, floor_x][3] == 1.0  # coverage
    finally:
        r.release()


@pytest.mark.parametrize("light_path", ["volumes", "tiled", "clustered"])
def test_depth_without_a_surface_holds_the_background(gl, light_path):
    """A pixel whose depth was written with no G-buffer surface (a depth-only pass over the
    sky) passes the lighting's depth test; the shaders then write the background there, as
    the clear does on the rest of the sky."""

    from deferred.gbuffer.layout import DEPTH

    scene = small_scene()
    scene.background = (0.25, 0.5, 0.75)
    r = Renderer(scene, "deferred", gl=gl, light_path=light_path)
    try:
        r.shaders.add_root(FIXTURES / "depth_only")
        depth_only = FullscreenPass("test.depth_only", Phase.GEOMETRY, "depth_only.frag", {},
                                    (), depth=DEPTH, depth_test=True, depth_func="always",
                                    depth_write=True)  # GL writes depth only when testing it
        r.insert_pass(depth_only, after="gbuffer.clear")
        capture = capture_frame(r)
        depth = capture.target("depth")[..., 0]
        width = depth.shape[1]
        light = np.asarray(capture.target("light_accumulation"), np.float32)
        ids = capture.target("normal_exponent_id")[..., 3]
        sky_left = (ids <= 0.0) & (np.arange(width) < width // 2)[None, :]
        sky_right = (ids <= 0.0) & (np.arange(width) >= width // 2)[None, :]
        assert sky_left.any() and sky_right.any()
        assert np.all(depth[sky_left] < 1.0) and np.all(depth[sky_right] >= 1.0)
        for sky in (sky_left, sky_right):
            np.testing.assert_allclose(light[sky], np.broadcast_to([0.25, 0.5, 0.75, 0.0],
                                                                   light[sky].shape), atol=1e-3)
        assert np.all(light[ids > 0.0][:, 3] == 1.0)
    finally:
        r.release()


def test_contact_sheet_has_every_buffer_in_pass_order(tmp_path, renderer):
    r = renderer(small_scene())
    capture = capture_frame(r)
    tiles = contact_tiles(capture)
    titles = [t.title for t in tiles]
    pass_titles = [f"{p.index:02d} {p.name}" for p in capture.passes]
    seen = list(dict.fromkeys(t for t in titles if t != "frame"))
    assert seen == pass_titles
    for p in capture.passes:
        subtitles = [t.subtitle for t in tiles if t.title == f"{p.index:02d} {p.name}"]
        assert list(dict.fromkeys(s.split(":")[0] for s in subtitles)) == list(p.writes)
    frame = [t.subtitle for t in tiles if t.title == "frame"]
    assert frame == ["albedo", "normal", "depth", "specular", "material", "light", "composite",
                     "final.png"]
    # false colour: normals as N * 0.5 + 0.5, background black
    normal = next(t.rgb for t in tiles if t.subtitle == "normal")
    g = capture.gbuffer()
    ids = g["material.id"] > 0
    n = np.stack([g["N.X"], g["N.Y"], g["N.Z"]], -1)
    assert np.all(normal[~ids] == 0.0)
    np.testing.assert_allclose(normal[ids], np.clip(n[ids] * 0.5 + 0.5, 0, 1), atol=1e-6)
    write_dump(capture, tmp_path)
    sheet = read_image(tmp_path / "contact.png")
    assert sheet.shape[1] == 6 + 6 * (SIZE[0] + 6)
    label_strip = sheet[6:38, 6: 6 + SIZE[0], :3]
    assert label_strip.max() > 0.5  # the label text is there


def test_view_buffers(renderer):
    r = renderer(small_scene())
    capture = capture_frame(r, passes=["lighting.background"])
    g = capture.gbuffer()
    normal = view(capture, "normal")
    assert normal.channels == ("N.X", "N.Y", "N.Z")
    np.testing.assert_array_equal(normal.pixels[..., 2], g["N.Z"])
    assert view(capture, "depth").channels == ("Z",)
    assert view(capture, "material").pixels.max() == registry.materials.get("standard").type_id
    light = view(capture, "lighting.background")
    assert light.channels == tuple(f"light_accumulation.{c}" for c in "RGBA")
    assert light.pixels[..., 3].max() == 1.0  # coverage alpha; no light added yet
    assert view(capture, "light").pixels.max() > light.pixels[..., :3].max()


# -- command line ------------------------------------------------------------------------------
def run(capsys, *args):
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.mark.slow
def test_cli_dump_writes_the_folder(tmp_path, capsys):
    out = tmp_path / "dump"
    code, stdout, err = run(capsys, "dump", "-o", out, "--size", "96x64")
    assert code == 0, err
    assert stdout == ""
    manifest = json.loads((out / "manifest.json").read_text())
    lists = {"light_lists.exr"} if "light_lists" in manifest["files"] else set()  # tiled paths
    assert {p.name for p in out.iterdir()} == {"gbuffer.exr", "light.exr", "final.exr",
                                               "final.png", "contact.png", "manifest.json",
                                               "index.html", "passes", *lists}
    assert manifest["scene"] == "builtin:demo.toml" and manifest["size"] == [96, 64]
    # a file for every pass that writes a target (light culling fills a buffer, no target)
    assert len(list((out / "passes").glob("*.exr"))) == \
        sum(1 for p in manifest["passes"] if p["outputs"])
    # again into the same folder, fewer passes: no stale pass file is left to mislead, and
    # files the dump did not make are left alone
    (out / "passes" / "notes.exr").write_bytes(b"mine")
    code, _, err = run(capsys, "dump", "-o", out, "--size", "96x64", "--passes",
                       "lighting.*,post.tonemap")
    assert code == 0, err
    names = sorted(p.name for p in (out / "passes").iterdir())
    assert names.pop() == "notes.exr"
    names = [n.split("_", 1)[1] for n in names]
    assert names[-1] == "post.tonemap.exr" and len(names) >= 2 and all(
        n.startswith("lighting.") for n in names[:-1])


def test_cli_dump_pixel_prints_history(tmp_path, capsys):
    scene = tmp_path / "scene.toml"
    scene.write_text('size = [64, 48]\n[[object]]\nmesh = "builtin:sphere"\n'
                     '[[light]]\ntype = "ambient"\n')
    code, stdout, err = run(capsys, "dump", scene, "-o", tmp_path / "d", "--pixel", "32,24")
    assert code == 0, err
    lines = stdout.splitlines()
    assert lines[0].startswith("pixel 32,24 (top-down) of 64x48:")
    assert any(line.startswith("01 sphere0.gbuffer (geometry): 1 fragment") for line in lines)
    # the clear's "before" is what it clears to, not the previous frame's value; a pass's own
    # first write of a target (the tone map's final) is its result, never "(unchanged)"
    clear = lines[lines.index("00 gbuffer.clear (geometry): clear") + 1:][:4]
    assert all(" cleared to (" in line for line in clear), clear
    assert "cleared to (0, 0, 0, 0) -> (0, 0, 0, 0)" in clear[0], clear
    final = [line for line in lines if line.strip().startswith("final ")]
    assert final and all("(first write this frame) -> (" in line and "unchanged" not in line
                         for line in final), final
    manifest = json.loads((tmp_path / "d" / "manifest.json").read_text())
    history = manifest["pixel_history"]
    assert history["pixel"] == [32, 24]
    assert [e["pass"] for e in history["passes"]][:2] == ["gbuffer.clear", "sphere0.gbuffer"]
    assert manifest["scene"] == str(scene.resolve())


def test_cli_forward_dump_has_no_gbuffer(tmp_path, capsys):
    code, _, err = run(capsys, "dump", "-o", tmp_path, "--size", "64x36", "--pipeline",
                       "forward")
    assert code == 0, err
    assert not (tmp_path / "gbuffer.exr").exists() and not (tmp_path / "light.exr").exists()
    assert (tmp_path / "final.exr").is_file()


@pytest.mark.slow
def test_cli_compare(tmp_path, capsys):
    for name in ("a", "b"):
        assert run(capsys, "dump", "-o", tmp_path / name, "--size", "64x36")[0] == 0
    code, stdout, err = run(capsys, "dump", "--compare", tmp_path / "a", tmp_path / "b")
    assert code == 0, err  # the same: exit 0, as diff
    assert "final.exr" in stdout and "passes/post.tonemap" in stdout
    assert "0 of" in err
    assert (tmp_path / "b-diff" / "compare.json").is_file()


@pytest.mark.slow
def test_cli_compare_output_is_whole_and_never_a_folder_of_other_files(tmp_path, capsys):
    for name in ("a", "b"):
        assert run(capsys, "dump", "-o", tmp_path / name, "--size", "64x36")[0] == 0
    out = tmp_path / "diff"
    out.mkdir()
    (out / "final.png").write_bytes(b"an earlier difference image")
    (out / "passes").mkdir()
    (out / "passes" / "post.tonemap.exr").write_bytes(b"another")
    (out / "notes.txt").write_text("mine")  # the user's, kept as a dump keeps them
    (out / "compare.json").write_text("{}")  # an earlier comparison: its own files replaced
    code, _, err = run(capsys, "dump", "--compare", tmp_path / "a", tmp_path / "b", "-o", out)
    assert code == 0, err
    # equal dumps: no images; the earlier ones gone, the notes kept
    assert sorted(p.name for p in out.iterdir()) == ["compare.json", "notes.txt"]
    assert (out / "notes.txt").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "b", "diff"]  # no staging left
    notes = tmp_path / "notes"
    notes.mkdir()
    (notes / "todo.txt").write_text("mine")
    code, _, err = run(capsys, "dump", "--compare", tmp_path / "a", tmp_path / "b", "-o", notes)
    assert code == 2 and "is a folder of other files" in err and str(notes) in err
    assert sorted(p.name for p in notes.iterdir()) == ["todo.txt"]


SCENE_TOML = """size = [64, 36]
light_path = "volumes"
[[object]]
name = "ball"
mesh = "builtin:sphere"
[[light]]
type = "ambient"
"""


@pytest.mark.parametrize("args, fragment", [
    (["dump"], "-o: a dump needs an output folder"),
    (["dump", "-o", "d", "--passes", "nope"], "--passes: no pass matches 'nope'"),
    (["dump", "-o", "d", "--size", "64x36", "--pixel", "64,0"],
     "--pixel: 64,0 is outside the 64x36 image"),
    (["dump", "-o", "d", "--pixel", "x"], "--pixel: expected X,Y"),
    (["dump", "--compare", "a", "b"], "a: not a folder"),
    (["dump", "scene.toml", "--compare", "a", "b"], "--compare: compares two dump folders"),
    (["render", "SCENE", "--view", "nope", "-o", "v.png"], "--view: unknown view 'nope'"),
    (["render", "SCENE", "--view", "ball.gbuffer", "-o", "v.png"],
     "--view: pass 'ball.gbuffer' writes 4 targets; choose one of ball.gbuffer:albedo_specular"),
    (["render", "SCENE", "--view", "ball.gbuffer:light_accumulation", "-o", "v.png"],
     "--view: pass 'ball.gbuffer' does not write 'light_accumulation'"),
    (["render", "SCENE", "--view", "albedo", "--pipeline", "forward", "-o", "v.png"],
     "--view: view 'albedo' shows albedo_specular, normal_exponent_id, linear_depth, which no "
     "pass of this pipeline writes"),
])
def test_bad_input_exits_2_with_one_line_and_no_files(tmp_path, capsys, monkeypatch, args,
                                                      fragment):
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE_TOML)
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    code, _, err = run(capsys, *[scene if a == "SCENE" else a for a in args])
    assert code == 2
    assert fragment in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert list(work.iterdir()) == []


@pytest.mark.slow
def test_cli_render_view(tmp_path, capsys):
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE_TOML)
    code, stdout, err = run(capsys, "render", scene, "--view", "help")
    assert code == 0, err
    names = [line.split()[0] for line in stdout.splitlines()]
    assert names[:8] == ["albedo", "normal", "depth", "specular", "material", "shading", "light",
                         "composite"]
    assert "lighting.ambient" in names and "ball.gbuffer:TARGET" in names

    exr = tmp_path / "normal.exr"
    code, stdout, err = run(capsys, "render", "--view", "normal", "--size", "64x36", "-o", exr)
    assert code == 0 and stdout == "", err
    assert "view normal" in err
    pixels, names, _ = read_channels(exr)
    assert names == ["N.X", "N.Y", "N.Z"]
    length = np.linalg.norm(pixels, axis=-1)
    assert np.allclose(length[length > 0], 1.0, atol=1e-5)

    png = tmp_path / "ids.png"
    assert run(capsys, "render", "--view", "material", "--size", "64x36", "-o", png)[0] == 0
    assert read_image(png).shape == (36, 64, 4)

    lit = tmp_path / "lit.exr"
    code, _, err = run(capsys, "render", "--view", "lighting.spot", "--light-path", "volumes",
                       "--size", "64x36", "-o", lit)
    assert code == 0, err
    pixels, names, _ = read_channels(lit)
    assert names == [f"light_accumulation.{c}" for c in "RGBA"]


def test_write_image_keeps_written_channel_order(tmp_path):
    names = ("b.Y", "a.X", "Z", "A")
    pixels = np.random.default_rng(0).random((4, 5, 4)).astype(np.float32)
    write_image(tmp_path / "x.exr", pixels, channels=names)
    back, read_names, attributes = read_channels(tmp_path / "x.exr")
    assert read_names == list(names)
    np.testing.assert_array_equal(back, pixels)
    assert attributes == {"z_channel": 2, "alpha_channel": 3}


@pytest.mark.slow
def test_cli_compare_never_replaces_a_folder_holding_the_dumps(tmp_path, capsys):
    out = tmp_path / "cmp"
    for name in ("a", "b"):
        assert run(capsys, "dump", "-o", out / name, "--size", "64x36")[0] == 0
    (out / "compare.json").write_text("{}")  # looks like an earlier comparison
    code, _, err = run(capsys, "dump", "--compare", out / "a", out / "b", "-o", out)
    assert code == 2 and "holds the dump" in err, err
    assert (out / "a" / "manifest.json").is_file() and (out / "b" / "manifest.json").is_file()


@pytest.mark.slow
def test_a_dump_of_a_list_path_holds_the_light_lists(tmp_path, renderer, gl):
    if not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    from dataclasses import replace

    from deferred.bench.scenes import with_extra_lights

    scene = with_extra_lights(replace(small_scene(), light_path="tiled"), 40, SIZE[0] / SIZE[1])
    capture = capture_frame(renderer(scene))
    manifest = write_dump(capture, tmp_path / "dump")
    assert manifest["files"]["light_lists"] == "light_lists.exr"
    pixels, channels, _ = read_channels(tmp_path / "dump" / "light_lists.exr")
    assert channels == ["lights.listed"]
    np.testing.assert_array_equal(pixels[..., 0], capture.light_lists)
    assert pixels.max() > 0 and len(np.unique(pixels)) > 3
    assert any(t.subtitle == "light_lists" for t in contact_tiles(capture))
    # the volumes path has no lists: no file, and no tile
    volumes = capture_frame(renderer(small_scene()))
    assert volumes.light_lists is None
    assert "light_lists" not in write_dump(volumes, tmp_path / "other")["files"]


@pytest.mark.slow
def test_a_dump_past_the_memory_budget_is_refused_before_the_frame(tmp_path, capsys, gl,
                                                                    monkeypatch):
    """A dump holds every captured pass's buffers and the files being written, several times
    a render's targets (the demo at 4096x4096 peaked at 12.8 GB): counted before the frame
    and refused past the budget, naming the size; --passes captures less and fits."""
    out = tmp_path / "dump"
    code, _, err = run(capsys, "dump", "-o", out, "--size", "4096x4096")
    assert code == 2 and err.startswith("error: --size: a dump of 4096x4096 holds ") and \
        err.strip().endswith("the budget is 4.0 GiB (DEFERRED_TARGET_MEMORY): a smaller "
                             "--size, or --passes to capture fewer passes"), err
    assert not out.exists()
    # a budget the render's targets and a dump of one pass fit in, and the whole dump does not
    from deferred.debug.dump import dump_memory
    from deferred.scene.loader import load_scene

    with Renderer(load_scene(None), "deferred", (96, 64), gl=gl) as demo:
        whole, one = dump_memory(demo), dump_memory(demo, ["post.tonemap"])
    assert one < whole
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", str((one + whole) // 2))
    code, _, err = run(capsys, "render", "-o", tmp_path / "x.png", "--size", "96x64")
    assert code == 0, err
    code, _, err = run(capsys, "dump", "-o", out, "--size", "96x64")
    assert code == 2 and "a dump of 96x64 holds" in err, err
    assert not out.exists()
    code, _, err = run(capsys, "dump", "-o", out, "--size", "96x64", "--passes", "post.tonemap")
    assert code == 0, err


def test_the_dump_estimate_covers_what_the_capture_holds(renderer):
    """dump_memory counts at least the arrays a capture keeps (each selected pass's targets,
    every target at the end) plus the render targets."""
    from deferred.debug.capture import capture_bytes
    from deferred.debug.dump import dump_memory
    from deferred.gl.target_spec import targets_bytes

    renderer = renderer(small_scene())
    for passes in (None, ["lighting.*"], ["post.tonemap"]):
        capture = capture_frame(renderer, passes)
        held = sum(raw.nbytes for p in capture.passes for raw in p.raw.values()) + \
            sum(raw.nbytes for raw in capture.targets.values())
        assert capture_bytes(renderer, passes) == held
        assert dump_memory(renderer, passes) >= held + targets_bytes(
            renderer.graph.targets.values(), *renderer.size)


@pytest.mark.slow
def test_a_dump_prepares_no_more_files_than_its_writers_take(tmp_path, renderer, monkeypatch):
    """Files wait for a writer with their float buffers in memory: no more than one queued for
    each writer, whatever the number of passes."""
    import threading
    import time

    import deferred.debug.dump as dump

    lock, queued, most = threading.Lock(), [0], [0]
    real_submit = dump.ThreadPoolExecutor.submit

    def submit(pool, fn, *args, **kwargs):
        with lock:
            queued[0] += 1
            most[0] = max(most[0], queued[0])

        def slow(*a, **k):
            time.sleep(0.02)
            try:
                return fn(*a, **k)
            finally:
                with lock:
                    queued[0] -= 1
        return real_submit(pool, slow, *args, **kwargs)

    monkeypatch.setattr(dump.ThreadPoolExecutor, "submit", submit)
    write_dump(capture_frame(renderer(small_scene())), tmp_path / "dump")
    assert len(list((tmp_path / "dump" / "passes").iterdir())) > 2 * dump.WRITERS
    assert most[0] <= 2 * dump.WRITERS + 1
