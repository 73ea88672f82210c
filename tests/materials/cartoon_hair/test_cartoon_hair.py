"""cartoon_hair (Costigan, "Cartoon Hair Simulation"): strands on the head's scalp simulated,
swept into tubes and toon shaded in both pipelines, with strand ids in the G-buffer that the
edges effect outlines overlapping strands by (4.3.7)."""

from __future__ import annotations

import numpy as np
import pytest
from locations import ROOT

from deferred.cli import main
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict


def head_scene(params: dict | None = None, effects=None, size=(128, 128), events=()) -> object:
    return scene_from_dict({
        "event": [{"time": t, "object": "head", "params": p} for t, p in events],
        "size": list(size), "tonemap": "none", "background": [0.9, 0.9, 0.9],
        "camera": {"position": [0.0, 0.05, 0.55], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"name": "head", "mesh": "builtin:head?segments=48&rings=32",
                    "material": "cartoon_hair",
                    "params": {"strands": 60, "style": "spiky", **(params or {})}}],
        "light": [{"type": "directional", "direction": [-0.5, -0.6, -0.6]}],
        "effect": effects or []})


def capture(gl, scene, pipeline="deferred", time=0.0):
    with Renderer(scene, pipeline, gl=gl) as renderer:
        result = renderer.render(time=time, hdr=True)
        targets = {name: renderer.targets.read(name)[::-1] for name in renderer.targets.specs}
        return result, targets


def test_the_hair_is_drawn_over_the_head_with_strand_ids(gl):
    result, targets = capture(gl, head_scene())
    ids = targets["strand_id"][..., 0]
    hair = ids > 0.5
    assert 0.1 < hair.mean() < 0.7
    assert len(np.unique(ids[hair])) > 20  # many strands seen
    assert np.all(ids[hair] == np.round(ids[hair]))  # whole indices, 1 + the strand's
    assert ids[hair].max() <= 60
    # the hair is on top: most hair pixels lie in the upper half of the frame
    rows = np.nonzero(hair)[0]
    assert np.mean(rows < 64) > 0.6
    assert np.isfinite(result.hdr).all()


def test_forward_and_deferred_agree_without_outlines(gl):
    from conftest import psnr

    scene = head_scene()
    deferred, _ = capture(gl, scene, "deferred")
    forward, _ = capture(gl, scene, "forward")
    assert psnr(deferred.hdr[..., :3], forward.hdr[..., :3]) > 35.0


def near_sides(ids: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """Pixels with a 4-neighbour of another (non-zero) id that lies farther away."""
    near_side = np.zeros(ids.shape, bool)
    for axis, shift in ((0, 1), (0, -1), (1, 1), (1, -1)):
        other_id, other_depth = np.roll(ids, shift, axis), np.roll(depth, shift, axis)
        near_side |= (ids > 0.5) & (other_id > 0.5) & (np.abs(other_id - ids) > 0.5) & \
            (other_depth > depth)
    near_side[[0, -1], :] = near_side[:, [0, -1]] = False
    return near_side


def test_overlapping_clumps_of_one_colour_are_outlined_not_strands(gl):
    """Where two clumps meet (4-neighbours of different clump ids, one nearer), the nearer
    side is an edge: the surface id alone (one material) would draw nothing there. Strands of
    one clump crossing each other are not outlined (4.3.7: Costigan outlines the hair and its
    clumps, not every strand), unless one lies well in front of the other (a depth break)."""
    _, targets = capture(gl, head_scene(effects=[{"type": "edges", "width": 1}]))
    strands, clumps = targets["strand_id"][..., 0], targets["strand_id"][..., 1]
    depth = targets["linear_depth"][..., 0]
    edges = targets["edges_raw"][..., 0] > 0.5
    between_clumps = near_sides(clumps, depth)
    assert between_clumps.sum() > 100
    assert edges[between_clumps].all()
    within_clumps = near_sides(strands, depth) & ~between_clumps
    assert within_clumps.sum() > 50
    assert edges[within_clumps].mean() < 0.5
    # a clump is several strands, whole numbers like the strands' ids
    hair = strands > 0.5
    assert len(np.unique(clumps[hair])) < 0.5 * len(np.unique(strands[hair]))
    assert np.all(clumps[hair] == np.round(clumps[hair])) and np.all(clumps[~hair] == 0.0)


def test_a_frame_depends_only_on_its_time(gl):
    """The simulation steps from t = 0: the hair at t = 0.5 is the same whether frames before
    it were rendered or not, and differs from t = 0 (the strands fall and swing)."""
    scene = head_scene({"bend_stiffness": 0.3, "torsion_stiffness": 0.3})
    with Renderer(scene, gl=gl) as renderer:
        first = renderer.render(time=0.0).image
        for t in (0.1, 0.2, 0.3):
            renderer.render(time=t)
        stepped = renderer.render(time=0.5).image
    with Renderer(scene, gl=gl) as renderer:
        direct = renderer.render(time=0.5).image
    np.testing.assert_array_equal(stepped, direct)
    assert not np.array_equal(first, direct)


@pytest.mark.parametrize("params, message", [
    ({"strands_file": "missing.json"}, "object[0].params.strands_file: strand file not found"),
    ({"keyframes": ["a.json"]}, "key_times needs a time for each keyframe"),
    ({"sides": 2}, "object[0].params.sides"),
    ({"taper": [0.0, 0.0]}, "object[0].params.taper"),
    ({"settle": 30.0, "time_step": 0.001}, "settle / time_step is 30,000 steps; the most is"),
])
def test_bad_parameters_are_one_line_errors(tmp_path, capsys, params, message):
    import json

    (tmp_path / "s.toml").write_text(
        "[[object]]\nmesh = \"builtin:head\"\nmaterial = \"cartoon_hair\"\n[object.params]\n" +
        "".join(f"{key} = {json.dumps(value)}\n" for key, value in params.items()))
    code = main(["render", str(tmp_path / "s.toml"), "-o", str(tmp_path / "out.png")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and message in err, err
    assert not (tmp_path / "out.png").exists()


def test_the_hair_follows_the_head_along_its_track(gl):
    """The strands' roots are pinned to the object's transform at each step (its tracks move
    it): a head moved to the right by a track carries its hair with it."""
    scene = head_scene({"edge_stiffness": 1.0, "bend_stiffness": 1.0, "torsion_stiffness": 1.0})
    scene.add_track(scene.objects[0], [{"time": 0.0, "position": [0.0, 0.0, 0.0]},
                                       {"time": 0.5, "position": [0.08, 0.0, 0.0]}])
    hair_x, head_x = [], []
    for time in (0.0, 1.0):
        _, targets = capture(gl, scene, time=time)
        ids = targets["strand_id"][..., 0]
        covered = targets["linear_depth"][..., 0] > 0.0
        hair_x.append(np.nonzero(ids > 0.5)[1].mean())
        # the head's own pixels, in the rows under the hair (its face and chin)
        head = covered & (ids < 0.5)
        head[:64] = False
        head_x.append(np.nonzero(head)[1].mean())
    head_shift, hair_shift = head_x[1] - head_x[0], hair_x[1] - hair_x[0]
    assert head_shift > 15.0  # the track moved the head right
    # the hair went with it (less where strands swing out of the frame's right edge)
    assert 0.4 * head_shift < hair_shift < 1.3 * head_shift


@pytest.mark.parametrize("mode", ["surface", "screen"])
def test_hatching_inks_the_hair_by_its_lit_tone(gl, mode):
    """Hatching (4.3.8) multiplies the lit hair by the tonal art map's ink for its tone: the
    head is untouched, the hair only darkens, and its darker bands take more ink than its lit
    ones; forward and deferred agree."""
    from conftest import psnr

    plain, targets = capture(gl, head_scene(size=(192, 192)))
    hatched, _ = capture(gl, head_scene({"hatching": mode}, size=(192, 192)))
    hair = targets["strand_id"][..., 0] > 0.5
    base, inked = plain.hdr[..., :3], hatched.hdr[..., :3]
    np.testing.assert_array_equal(inked[~hair], base[~hair])
    assert np.all(inked[hair] <= base[hair] + 1e-6)
    darkening = 1.0 - inked[hair].mean(axis=-1) / np.maximum(base[hair].mean(axis=-1), 1e-6)
    assert (darkening > 0.05).mean() > 0.05  # strokes on the hair
    brightness = base[hair].mean(axis=-1)
    # the ramp's bands: its darkest against its lightest
    dark, light = brightness <= brightness.min() + 1e-3, brightness >= brightness.max() - 1e-3
    assert darkening[dark].mean() > 2.0 * darkening[light].mean()
    forward, _ = capture(gl, head_scene({"hatching": mode}, size=(192, 192)), "forward")
    assert psnr(hatched.hdr[..., :3], forward.hdr[..., :3]) > 30.0


def test_the_hair_starts_over_when_its_head_gets_a_track(gl):
    """A track added after some frames changes the head's whole motion: the hair is simulated
    again from t = 0 and draws what a fresh renderer draws (its roots jumped in one step), at
    a frame time between simulation steps too."""
    scene = head_scene({"bend_stiffness": 0.5, "torsion_stiffness": 0.5})
    with Renderer(scene, gl=gl) as renderer:
        renderer.render(time=0.5)
        scene.add_track(scene.objects[0], [{"time": 0.0, "rotation": [0.0, 0.0, 0.0]},
                                           {"time": 0.5, "rotation": [0.0, 40.0, 0.0]}],
                        interpolation="smooth")
        late = renderer.render(time=0.55).image
    with Renderer(scene, gl=gl) as fresh:
        np.testing.assert_array_equal(late, fresh.render(time=0.55).image)


def test_two_heads_have_their_own_strand_ids(gl):
    """Each hair object takes its own range of strand ids, so strands of two heads are told
    apart (outlines, silhouette visibility): both heads share indices 1..N otherwise."""
    scene = scene_from_dict({
        "size": [160, 96], "camera": {"position": [0.0, 0.05, 0.8], "target": [0, 0, 0]},
        "object": [{"name": name, "mesh": "builtin:head?segments=32&rings=24",
                    "material": "cartoon_hair", "position": [x, 0.0, 0.0],
                    "params": {"strands": 30}}
                   for name, x in (("left", -0.13), ("right", 0.13))],
        "light": [{"type": "directional"}]})
    _, targets = capture(gl, scene)
    ids = np.unique(targets["strand_id"][..., 0])
    ids = ids[ids > 0.5]
    first, second = ids[ids <= 30], ids[ids > 32768]
    assert len(first) > 5 and len(second) > 5 and len(first) + len(second) == len(ids)
    assert second.max() <= 32768 + 30


EXAMPLES = sorted((ROOT / "examples" / "cartoon_hair").glob("*.toml"))


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_the_cartoon_hair_examples_render(gl, path):
    from deferred.scene.loader import load_scene

    assert len(EXAMPLES) >= 4
    with Renderer(load_scene(path), size=(64, 64), gl=gl) as renderer:
        result = renderer.render(time=0.5, hdr=True)
        ids = renderer.targets.read("strand_id")[..., 0]
    assert np.isfinite(result.hdr).all() and (ids > 0.5).mean() > 0.05


def test_a_time_too_far_for_the_simulation_is_refused_before_a_frame(tmp_path, capsys):
    """The hair steps from t = 0: a frame at 10,000 s (600,000 steps) is refused in one line
    naming --time before anything is drawn, instead of running for hours."""
    (tmp_path / "s.toml").write_text(
        "[[object]]\nmesh = \"builtin:head\"\nmaterial = \"cartoon_hair\"\n")
    code = main(["render", str(tmp_path / "s.toml"), "-o", str(tmp_path / "out.png"),
                 "--time", "10000"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: --time: t = 10000 s needs 600,000 simulation "
                                        "steps"), err
    assert not (tmp_path / "out.png").exists()


def test_the_gpu_and_numpy_tubes_draw_the_same_hair(gl):
    """The tubes built by compute shaders (GpuTubes) and by numpy (a GL 3.3 context) are the
    same mesh to float rounding: the same image, strand ids and depth, both pipelines, with
    silhouette strokes drawn from the same buffer."""
    from conftest import psnr

    from deferred.gl.context import Features, GLContext

    gl33 = GLContext(gl.ctx, Features(storage_buffers=False, compute_shaders=False))
    scene = head_scene({"bend_stiffness": 0.3, "torsion_stiffness": 0.3, "silhouettes": True})
    for pipeline in ("deferred", "forward"):
        gpu, gpu_targets = capture(gl, scene, pipeline, time=0.3)
        cpu, cpu_targets = capture(gl33, scene, pipeline, time=0.3)
        assert psnr(gpu.hdr[..., :3], cpu.hdr[..., :3]) > 60.0, pipeline
        if pipeline == "deferred":
            ids, other = gpu_targets["strand_id"][..., 0], cpu_targets["strand_id"][..., 0]
            assert (ids != other).mean() < 0.002
            assert (ids > 0.5).mean() > 0.1


def test_dynamics_parameters_follow_the_timeline(gl):
    """gravity, wind and the stiffnesses may change at an event: the hair before it is the
    hair without the event, after it the simulation has run with the new values since the
    event's time; seeking in any order gives each time's own frame (the simulation replays
    from t = 0 with the parameters of each step)."""
    base = {"bend_stiffness": 0.4, "torsion_stiffness": 0.4}
    change = {"wind": [3.0, 0.0, 0.0], "gravity": [0.0, -2.0, 0.0], "bend_stiffness": 0.1}
    timeline = head_scene(base, events=[(0.25, change)])
    plain = head_scene(base)
    frames = {}
    for t in (0.2, 0.5):
        with Renderer(timeline, gl=gl) as renderer:
            frames[t] = renderer.render(time=t).image
    with Renderer(plain, gl=gl) as renderer:
        np.testing.assert_array_equal(frames[0.2], renderer.render(time=0.2).image)
        assert np.abs(frames[0.5].astype(int) - renderer.render(time=0.5).image).mean() > 2.0
    with Renderer(timeline, gl=gl) as renderer:  # out of order, and the same times again
        for t in (0.5, 0.2, 0.5, 0.35, 0.2):
            image = renderer.render(time=t).image
            if t in frames:
                np.testing.assert_array_equal(image, frames[t])


def test_a_python_change_to_the_dynamics_starts_the_hair_over(gl):
    """set_params on a parameter the simulation reads every step (not timeline_fixed) changes
    the hair's history: the next frame is a fresh renderer's, not one stepped on from the
    old values."""
    scene = head_scene({"bend_stiffness": 0.4, "torsion_stiffness": 0.4})
    with Renderer(scene, gl=gl) as renderer:
        renderer.render(time=0.3)
        scene.objects[0].set_params(wind=[0.0, 0.0, 4.0])
        late = renderer.render(time=0.4).image
    with Renderer(scene, gl=gl) as fresh:
        np.testing.assert_array_equal(late, fresh.render(time=0.4).image)


def test_what_builds_the_hair_cannot_follow_a_timeline():
    from deferred.errors import InputError

    for key, value in (("strands", 30), ("sides", 4), ("settle", 1.0), ("time_step", 0.01)):
        with pytest.raises(InputError, match=f"cartoon_hair reads {key} once, at t = 0"):
            head_scene(events=[(0.5, {key: value})])


def test_settle_counts_toward_the_bound_on_steps(tmp_path, capsys):
    (tmp_path / "s.toml").write_text(
        "[[object]]\nmesh = \"builtin:head\"\nmaterial = \"cartoon_hair\"\n"
        "[object.params]\nsettle = 60.0\ntime_step = 0.004\n")
    code = main(["render", str(tmp_path / "s.toml"), "-o", str(tmp_path / "out.png"),
                 "--time", "30"])
    err = capsys.readouterr().err
    assert code == 2 and "needs 22,500 simulation steps of 0.004 s (with settle)" in err, err
    assert not (tmp_path / "out.png").exists()


def random_walk_strands(count: int = 400, points: int = 9, seed: int = 7) -> np.ndarray:
    """Guide strands the material did not grow: random walks from roots on the upper part of
    a unit sphere, drooping, kept outside it."""
    rng = np.random.default_rng(seed)
    roots = rng.normal(size=(3 * count, 3))
    roots /= np.linalg.norm(roots, axis=1, keepdims=True)
    roots = roots[roots[:, 1] > -0.2][:count]
    strands = []
    for root in roots:
        point, direction = root.copy(), root + 0.3 * rng.normal(size=3)
        strand = [point]
        step = 0.9 / (points - 1) * rng.uniform(0.8, 1.2)
        for _ in range(points - 1):
            direction = direction / np.linalg.norm(direction) + [0.0, -0.35, 0.0] + \
                0.25 * rng.normal(size=3)
            point = strand[-1] + step * direction / np.linalg.norm(direction)
            point = point * max(1.0, 1.02 / np.linalg.norm(point))
            strand.append(point)
        strands.append(strand)
    return np.asarray(strands)


def write_obj_strands(path, strands: np.ndarray) -> None:
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in strands.reshape(-1, 3)]
    points = strands.shape[1]
    for s in range(len(strands)):
        lines.append("l " + " ".join(str(s * points + k + 1) for k in range(points)))
    path.write_text("\n".join(lines) + "\n")


STROKE_COLOR = [0.31, 0.25, 0.38]  # cartoon_hair's default stroke_color, sRGB


def outline_ink(plain: np.ndarray, outlined: np.ndarray, lines) -> np.ndarray:
    """Pixels the outlines ink: moved visibly (more than 10 levels) and more than halfway from
    their colour without outlines toward a line's colour (sRGB): a line's faint fringe and a
    stroke faded toward the roots (Fig. 4.19) under half opacity are not ink."""
    a, b = plain[..., :3] / 255.0, outlined[..., :3] / 255.0
    moved = np.linalg.norm(b - a, axis=-1)
    ink = np.zeros(moved.shape, bool)
    for line in lines:
        toward = np.linalg.norm(np.asarray(line) - a, axis=-1)
        ink |= (moved > 10.0 / 255.0) & (moved > 0.5 * toward)
    return ink


def sphere_hair_scene(path, params: dict | None = None, effects=(), size=(320, 320)):
    return scene_from_dict({
        "size": list(size), "tonemap": "none", "background": [0.93, 0.93, 0.96],
        "camera": {"position": [0.0, 0.2, 2.2], "target": [0.0, -0.05, 0.0], "fov": 40.0},
        "object": [{"name": "ball", "mesh": "builtin:sphere", "material": "cartoon_hair",
                    "scale": 0.5,
                    "params": {"strands_file": str(path), "radius": 0.04,
                               "color": [0.85, 0.55, 0.25],
                               "collision_spheres": [[0.0, 0.0, 0.0, 1.0]], **(params or {})}}],
        "light": [{"type": "directional", "direction": [-0.5, -0.6, -0.6]}],
        "effect": list(effects)})


def test_hair_from_a_file_on_another_mesh_is_outlined_not_buried(gl, tmp_path):
    """400 guide strands the material did not grow (random walks, an OBJ file) on a sphere,
    with the edges effect and the silhouette strokes at their defaults: at most 40% of the
    hair's pixels are outline ink, and at least half of the hair's silhouette against the
    background is outlined (Costigan 4.3.7: the hair's outline and its clumps', not every
    strand buried in ink)."""
    path = tmp_path / "walk.obj"
    write_obj_strands(path, random_walk_strands())
    plain, targets = capture(gl, sphere_hair_scene(path))
    outlined, _ = capture(gl, sphere_hair_scene(path, {"silhouettes": True},
                                                [{"type": "edges"}]))
    hair = targets["strand_id"][..., 0] > 0.5
    background = targets["linear_depth"][..., 0] <= 0.0
    assert hair.mean() > 0.3
    ink = outline_ink(plain.image, outlined.image, ([0.0, 0.0, 0.0], STROKE_COLOR))
    rim = np.zeros_like(hair)
    for axis, shift in ((0, 1), (0, -1), (1, 1), (1, -1)):
        rim |= hair & np.roll(background, shift, axis)
    assert rim.sum() > 500
    assert ink[hair].mean() <= 0.4, ink[hair].mean()
    assert ink[rim].mean() >= 0.5, ink[rim].mean()


def test_the_moving_head_example_is_not_buried_in_ink():
    """examples/cartoon_hair/moving_head.toml at t = 0.5 s (the edges effect on combed hair):
    under a quarter of the covered pixels are near black."""
    from deferred.scene.loader import load_scene

    with Renderer(load_scene(ROOT / "examples" / "cartoon_hair" / "moving_head.toml")) as r:
        image = r.render(time=0.5).image[..., :3] / 255.0
        covered = r.targets.read("linear_depth")[::-1][..., 0] > 0.0
    luminance = image @ [0.2126, 0.7152, 0.0722]
    assert covered.mean() > 0.2
    assert (luminance[covered] < 0.1).mean() < 0.25


@pytest.mark.parametrize("params", [{"specular_intensity": 0.6, "specular_exponent": 60.0},
                                    {"ramp_metric": "specular", "ramp_shininess": 15.0}],
                         ids=["band", "ramp"])
def test_the_hair_shines_along_its_strands_and_the_skin_apart(gl, params):
    """Figs. 4.9-4.10 on the hair: the band (and the ramp's specular metric) follow the strand
    tangent (sin(T, H)), a band across the strands: at least a tenth of the hair's pixels
    change against the unlit Fig. 4.7; the band leaves the skin alone, whose own highlight
    (skin_specular_intensity) changes only the head."""
    plain, targets = capture(gl, head_scene(size=(192, 192)))
    shiny, _ = capture(gl, head_scene(params, size=(192, 192)))
    hair = targets["strand_id"][..., 0] > 0.5
    changed = np.abs(shiny.hdr[..., :3] - plain.hdr[..., :3]).max(axis=-1) > 1e-3
    assert changed[hair].mean() >= 0.1, changed[hair].mean()
    if "specular_intensity" in params:
        assert not changed[~hair].any()
        skin, _ = capture(gl, head_scene({"skin_specular_intensity": 0.6}, size=(192, 192)))
        skin_changed = np.abs(skin.hdr[..., :3] - plain.hdr[..., :3]).max(axis=-1) > 1e-3
        assert skin_changed.sum() > 20 and not skin_changed[hair].any()


def hatching_ink(plain: np.ndarray, hatched: np.ndarray, strength: float = 0.8) -> np.ndarray:
    """The hatching's ink: it multiplies the lit hair by 1 - strength x ink."""
    a, b = plain[..., :3].mean(axis=-1), hatched[..., :3].mean(axis=-1)
    return np.clip(1.0 - b / np.maximum(a, 1e-6), 0.0, 1.0) / strength


STROKE_CONTRAST = 0.2  # RMS ink step between neighbouring pixels: smeared bands gave 0.10-0.15


@pytest.mark.slow
@pytest.mark.parametrize("size", [320, 1280])
@pytest.mark.parametrize("mode", ["screen", "surface"])
def test_hatching_reads_as_pen_strokes(gl, mode, size):
    """Hatching (4.3.8) as pen strokes at 320 and 1280 px: the tonal art map's strokes,
    hatching_width pixels wide, read from one level and thresholded crisp, so the ink steps
    from pixel to pixel (the RMS difference of neighbouring pixels' ink over hair of one flat
    tone, both axes) by more than STROKE_CONTRAST; the trilinear blend of the thesis' 6-pixel
    strokes gave 0.10-0.15 (soft bands)."""
    params = {"color": [0.95, 0.72, 0.38], "radius": 0.02, "strands": 150}
    scene = head_scene(params, size=(size, size))
    plain, targets = capture(gl, scene)
    extra = {"hatching_scale": 1.0} if mode == "surface" else {}
    hatched, _ = capture(gl, head_scene({**params, "hatching": mode, **extra}, size=(size, size)))
    strands = targets["strand_id"][..., 0]
    image = plain.image[..., :3].astype(int)
    flat = strands > 0.5
    for axis, shift in ((0, 1), (0, -1), (1, 1), (1, -1)):  # one strand, one tone around
        flat &= (np.roll(strands, shift, axis) == strands) & \
            (np.abs(np.roll(image, shift, axis) - image).max(axis=-1) == 0)
    ink = hatching_ink(plain.image, hatched.image)
    steps = ((ink - np.roll(ink, 1, 1)) ** 2 + (ink - np.roll(ink, 1, 0)) ** 2) / 2.0
    assert flat.sum() > 0.1 * size * size
    assert 0.1 < ink[flat].mean() < 0.6  # hatched, neither blank nor black
    assert np.sqrt(steps[flat].mean()) > STROKE_CONTRAST


def test_surface_hatching_has_no_beat_of_its_tiles(gl, tmp_path):
    """No moire: one straight tube seen side on, its map repeated 40 times along it (a tile
    6.5 pixels long, its strokes far finer than pixels along the strand). Sampled by one
    isotropic level, the minified tiles showed as a chevron of blots a tile apart (a power of
    0.86 at the tiles' frequency in the column-averaged ink, of 0.91 in all); read
    anisotropically, and flat past what the taps resolve, the ink has under 0.01 there
    (0.002) and is nearly uniform."""
    import json

    (tmp_path / "side.json").write_text(json.dumps(
        {"strands": [[[x, 3.0, 0.0] for x in np.linspace(-1.0, 1.0, 12)]]}))

    def scene(params):
        return scene_from_dict({
            "size": [320, 160], "tonemap": "none", "background": [1.0, 1.0, 1.0],
            "camera": {"position": [0.0, 3.0, 20.0], "target": [0.0, 3.0, 0.0], "fov": 3.5},
            "object": [{"name": "s", "mesh": "builtin:sphere", "material": "cartoon_hair",
                        "params": {"strands_file": str(tmp_path / "side.json"), "radius": 0.1,
                                   "taper": [0.0, 0.0, 1.0], "gravity": [0.0, 0.0, 0.0],
                                   "collision_spheres": [], "ramp": [[0.0, "#9a9a9a"]],
                                   "hair_samples": 12, "sides": 16, "color": [1.0, 1.0, 1.0],
                                   **params}}],
            "light": [{"type": "directional", "direction": [0.0, -1.0, 0.0]}]})

    plain, targets = capture(gl, scene({}))
    hatched, _ = capture(gl, scene({"hatching": "surface", "hatching_scale": 40.0}))
    hair = targets["strand_id"][..., 0] > 0.5
    rows = np.nonzero(hair.sum(axis=1) > 150)[0]
    columns = np.nonzero(hair[rows].all(axis=0))[0]
    assert len(rows) > 15 and len(columns) > 200
    ink = hatching_ink(plain.image, hatched.image)[np.ix_(rows, columns)]
    means = ink.mean(axis=0)
    power = np.abs(np.fft.rfft(means - means.mean())) ** 2 / len(means)
    frequency = np.fft.rfftfreq(len(means))
    length = 2.0 / (40.0 * np.tan(np.radians(1.75))) * 160  # the strand's pixels
    tile = np.abs(frequency - 40.0 / length).argmin()
    assert 0.05 < ink.mean() < 0.4  # the tone's mean ink
    assert power[tile - 1:tile + 2].sum() < 0.01
    assert ink.std() < 0.08
