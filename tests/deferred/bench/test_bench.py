"""deferred bench: sweep structure, scene variants, outputs, bad input. Never timings."""

import csv
import json
from collections import Counter

import numpy as np
import pytest
from locations import ROOT

from deferred.bench.harness import Sweep, run_bench
from deferred.bench.report import COLUMNS
from deferred.bench.scenes import (
    extra_point_lights,
    set_self_shadow_density,
    shell_objects,
    with_extra_lights,
    with_shells,
)
from deferred.cli import main
from deferred.errors import InputError
from deferred.io.images import read_image
from deferred.render.pipeline import PIPELINES
from deferred.scene.loader import load_scene, scene_from_dict

LIGHTS_SCENE = ROOT / "benchmarks" / "lights.toml"
FAST = ["--size", "64x36", "--runs", "2", "--warmup", "1"]


def run(capsys, *args):
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def standard_scene():
    return scene_from_dict({
        "size": [64, 36], "light_path": "volumes",
        "camera": {"position": [0.0, 1.5, 3.0], "target": [0.0, 0.0, 0.0]},
        "object": [{"mesh": "builtin:plane", "scale": 2.0},
                   {"mesh": "builtin:sphere", "position": [0.0, 0.5, 0.0], "scale": 0.5}],
        "light": [{"type": "ambient"}],
    })


@pytest.mark.slow
def test_cli_sweep_writes_json_csv_plot(tmp_path, capsys):
    out = {s: tmp_path / f"bench.{s}" for s in ("json", "csv", "png")}
    code, stdout, err = run(capsys, "bench", *FAST, "--lights", "3,0", "--shells", "0,4",
                            "--light-paths", "volumes,tiled,naive",
                            "--json", str(out["json"]), "--csv", str(out["csv"]),
                            "--plot", str(out["png"]))
    assert code == 0, err
    assert "median ms" in stdout and "median ms" not in err  # the results on stdout
    assert f"plot: {out['png'].resolve()}" in err.splitlines()  # where to look
    assert ", 2 runs (" in stdout  # --runs 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bench.csv", "bench.json",
                                                          "bench.png"]

    report = json.loads(out["json"].read_text())
    assert set(report) == {"renderer", "results"}
    for key in ("vendor", "renderer", "version"):
        assert report["renderer"][key]
    assert report["renderer"]["gbuffer_bytes_per_pixel"] == 20
    layout = report["renderer"]["gbuffer_layout"]
    assert list(layout) == ["albedo_specular", "normal_exponent_id", "linear_depth", "depth"]
    assert sum(entry["bytes_per_pixel"] for entry in layout.values()) == 20
    results = report["results"]
    combos = Counter((r["pipeline"], r["light_path"], r["lights"], r["shells"])
                     for r in results)
    paths = [("deferred", "volumes"), ("deferred", "tiled"), ("forward", "tiled"),
             ("forward", "naive")]
    assert set(combos) == {(*p, lights, shells) for p in paths for lights in (0, 3)
                           for shells in (0, 4)}
    assert set(combos.values()) == {1}
    assert "shells: deferred" in stdout  # the crossover lines

    demo = load_scene(None)
    for r in results:
        assert list(r) == list(COLUMNS)
        # two runs (rounds), each 1-4 timed frames (back to back for 100 ms, the first dropped)
        assert (r["width"], r["height"]) == (64, 36) and r["runs"] == 2
        assert 2 <= r["frames"] <= 8
        assert len(r["times_ms"]) == r["frames"] and all(t > 0.0 for t in r["times_ms"])
        assert r["min_ms"] <= r["median_ms"] <= r["max_ms"]
        assert r["min_ms"] <= r["mean_ms"] <= r["max_ms"]
        assert r["min_ms"] == min(r["times_ms"]) and r["max_ms"] == max(r["times_ms"])
        assert r["stddev_ms"] >= 0.0
        variant = with_extra_lights(with_shells(demo, r["shells"]), r["lights"], 64 / 36)
        names = [p.name for p in PIPELINES[r["pipeline"]](r["light_path"]).passes(variant)]
        assert list(r["passes_ms"]) == names
        assert all(t > 0.0 for t in r["passes_ms"].values())
        shell_pass = "torus.shells" if r["pipeline"] == "deferred" else "torus.forward_shells"
        assert (shell_pass in r["passes_ms"]) == (r["shells"] > 0)
        # the framework's CPU time: per frame, and per draw call
        assert r["cpu_ms"] > 0.0 and r["draw_calls"] > 0
        assert r["cpu_us_per_draw"] == pytest.approx(1000.0 * r["cpu_ms"] / r["draw_calls"])
        assert r["gpu_passes_ms"] is None or set(r["gpu_passes_ms"]) == set(names)

    with out["csv"].open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == list(COLUMNS)
    assert len(rows) == len(results)
    for row, r in zip(rows, results, strict=True):
        assert (row["pipeline"], int(row["lights"]), int(row["shells"])) == \
            (r["pipeline"], r["lights"], r["shells"])
        assert float(row["median_ms"]) == r["median_ms"]
        assert json.loads(row["times_ms"]) == r["times_ms"]
        assert json.loads(row["passes_ms"]) == r["passes_ms"]

    plot = read_image(out["png"])
    assert plot.shape[0] > 100 and plot.shape[1] > 2 * plot.shape[0]  # one panel per shells
    assert plot[..., :3].std() > 0.05


def test_json_dash_goes_to_stdout(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, stdout, err = run(capsys, "bench", str(LIGHTS_SCENE), *FAST, "--lights", "2",
                            "--pipelines", "forward", "--light-paths", "naive", "--json", "-")
    assert code == 0, err
    report = json.loads(stdout)
    assert [(r["pipeline"], r["light_path"], r["lights"], r["shells"])
            for r in report["results"]] == [("forward", "naive", 2, 0)]
    assert "median ms" in err  # the table goes to stderr, out of the JSON's way
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_scene_without_shells_sweeps_one_value(gl, capsys):
    scene = standard_scene()
    assert shell_objects(scene) == []
    report = run_bench(scene, Sweep(lights=[0, 2], shells=[0, 16, 64], runs=1, warmup=0,
                                    light_paths=["volumes", "naive"], round_ms=0.0), gl=gl)
    assert [(r.pipeline, r.lights, r.shells) for r in report.results] == [
        ("deferred", 0, 0), ("forward", 0, 0), ("deferred", 2, 0), ("forward", 2, 0)]
    assert all(r.runs == 1 and r.stddev_ms == 0.0 for r in report.results)

    code, _, err = run(capsys, "bench", str(LIGHTS_SCENE), *FAST, "--lights", "0",
                       "--pipelines", "deferred", "--shells", "0,16")
    assert code == 0, err
    assert "no object has a 'shells' parameter; shell sweep skipped (shells 0)" in err


@pytest.mark.parametrize("count", [0, 1, 40])
def test_extra_lights_are_added_to_a_copy(render, count):
    scene = standard_scene()
    before = list(scene.lights)
    variant = with_extra_lights(scene, count, 64 / 36)
    assert scene.lights == before  # the loaded scene is never changed
    assert len(variant.lights) == len(before) + count
    assert variant.lights[:len(before)] == before
    assert all(light.name == "point" for light in variant.lights[len(before):])
    _, renderer = render(variant, size=(64, 36), readback=False)
    assert renderer.light_buffer.count == len(before) + count
    passes = [p.name for p in renderer.passes]
    assert ("lighting.point" in passes) == (count > 0)


def test_extra_lights_deterministic_nested_and_on_screen():
    scene = standard_scene()
    aspect = 16 / 9
    many = extra_point_lights(scene, 64, aspect)
    again = extra_point_lights(scene, 64, aspect)
    few = extra_point_lights(scene, 8, aspect)
    assert [lt.params for lt in many] == [lt.params for lt in again]
    assert [lt.params for lt in few] == [lt.params for lt in many[:8]]  # counts nest
    assert len({lt.params.position for lt in many}) == 64
    view = scene.camera.view()
    projection = scene.camera.projection(aspect)
    for light in many:
        clip = projection @ view @ np.append(light.params.position, 1.0)
        assert clip[3] > 0.0 and np.all(np.abs(clip[:2] / clip[3]) <= 1.0)
        assert 0.0 < light.params.radius < 5.0


@pytest.mark.slow
@pytest.mark.parametrize("shells", [0, 3, 9])
def test_shells_applied_to_fur_objects_only(render, shells):
    demo = load_scene(None)
    fur = {obj.label: obj.material.params.shells for obj in shell_objects(demo)}
    assert set(fur) == {"torus", "ball"}
    variant = with_shells(demo, shells)
    assert {obj.label: obj.material.params.shells for obj in shell_objects(demo)} == fur
    floor = next(obj for obj in variant.objects if obj.label == "floor")
    assert floor.material is demo.objects[0].material  # no shells: untouched
    for pipeline, suffix in (("deferred", "shells"), ("forward", "forward_shells")):
        result, _ = render(variant, pipeline, size=(32, 18), readback=False)
        for label in fur:
            assert result.draws_by_pass.get(f"{label}.{suffix}", 0) == shells


def test_shells_out_of_the_materials_range_is_bad_input():
    with pytest.raises(InputError, match=r"^--shells: .*256.* for torus \(revie_fur\), got 999"):
        with_shells(load_scene(None), 999)


def test_self_shadow_density_set_on_every_fur_and_nothing_else():
    scene = load_scene(ROOT / "examples" / "shadows_demo.toml")
    before = {obj.label: obj.material.params for obj in scene.objects}
    set_self_shadow_density(scene, 0.0)
    furs = [obj for obj in scene.objects if "self_shadow_density" in type(obj.params).model_fields]
    assert sorted(obj.material.name for obj in furs) == ["revie_fur", "revie_fur"]
    assert all(obj.params.self_shadow_density == 0.0 for obj in furs)
    assert all(obj.material.params == before[obj.label]
               for obj in scene.objects if obj not in furs)
    with pytest.raises(InputError, match=r"self_shadow_density: Input should be greater"):
        set_self_shadow_density(scene, -1.0)


@pytest.mark.parametrize("args, fragment", [
    (["--lights", "1,x"], "--lights: expected comma-separated whole numbers"),
    (["--lights", ""], "--lights: expected comma-separated whole numbers"),
    (["--lights", "4,-1"], "--lights: counts must be 0 or more, got -1"),
    (["--lights", "20000"], "--lights: at most 16384 lights"),
    (["--shells", "-2"], "--shells: counts must be 0 or more"),
    (["--shells", "0,999"], "--shells: Input should be less than or equal to 256"),
    (["--light-paths", "fast"], "--light-paths: unknown light path 'fast'"),
    (["--light-paths", "clustered", "--pipelines", "forward"],
     "--light-paths: no light path of the pipelines chosen"),
    (["--light-paths", "volumes,naive", "--pipelines", "forward"],
     "--light-paths: volumes is no light path of forward (add its pipeline to --pipelines)"),
    (["--runs", "0"], "Invalid value for '--runs'"),
    (["--warmup", "-1"], "Invalid value for '--warmup'"),
    (["--pipelines", "deferred,raytrace"], "--pipelines: unknown pipeline 'raytrace'"),
    (["--pipelines", ","], "--pipelines: expected pipeline names"),
    (["--size", "0x10"], "--size: size 0x10 is impossible"),
    (["--size", "wide"], "--size: expected WIDTHxHEIGHT"),
    (["--json", "out.txt"], "--json: output must end in .json"),
    (["--csv", "out.json"], "--csv: output must end in .csv"),
    (["--plot", "out.jpg"], "--plot: output must end in .png"),
    (["--csv", "missing/out.csv"], "--csv: output folder does not exist: missing"),
    (["--json", "folder.json"], "--json: output is a folder, not a file"),
    (["missing.toml"], "missing.toml: scene file not found"),
])
def test_bad_input_exits_2_with_one_line_and_no_files(tmp_path, capsys, monkeypatch, args,
                                                      fragment):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "folder.json").mkdir()
    # Outputs to prove none is written, and a tiny sweep so a check that fails to stop the
    # command costs a second, not a default sweep.
    others = {"--json": "r.json", "--csv": "r.csv", "--plot": "r.png", "--size": "16x9",
              "--runs": "1", "--warmup": "0", "--lights": "0", "--shells": "0"}
    extra = [x for key, value in others.items() if key not in args for x in (key, value)]
    code, stdout, err = run(capsys, "bench", *args, *extra)
    assert code == 2
    assert fragment in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert stdout == ""
    assert [p.name for p in tmp_path.iterdir()] == ["folder.json"]
    assert list((tmp_path / "folder.json").iterdir()) == []


def test_builtin_overdraw_scene_has_objects_at_several_depths(render):
    scene = load_scene("builtin:overdraw")
    depths = {round(float(obj.model[2, 3]), 1) for obj in scene.objects[1:]}
    assert len(scene.objects) > 30 and len(depths) >= 5
    result, _ = render(scene, "forward", size=(96, 54), light_path="naive")
    assert result.draws_by_pass["floor.forward"] == 1 and np.isfinite(result.hdr).all()
    with pytest.raises(InputError, match="no built-in scene 'nope'"):
        load_scene("builtin:nope")


def test_speedups_compare_the_fastest_deferred_path_at_the_most_lights():
    from deferred.bench.report import BenchReport, BenchResult, speedups

    def row(pipeline, path, lights, ms, shells=0):
        return BenchResult(pipeline, lights, shells, 64, 36, [ms], light_path=path)

    report = BenchReport({}, [
        row("deferred", "volumes", 16, 9.0), row("deferred", "tiled", 16, 5.0),
        row("forward", "naive", 16, 20.0), row("forward", "tiled", 16, 4.0),
        row("deferred", "volumes", 1024, 300.0), row("deferred", "tiled", 1024, 50.0),
        row("deferred", "clustered", 1024, 80.0), row("forward", "naive", 1024, 2600.0),
        row("forward", "tiled", 1024, 130.0),
        row("deferred", "volumes", 4, 10.0, shells=16), row("forward", "naive", 4, 8.0, 16)])
    assert speedups(report) == [
        "0 shells, 1024 extra lights: deferred (tiled) 50.0 ms: 52.0x naive forward "
        "(2600.0 ms), 2.60x the fastest forward path (tiled, 130.0 ms)",
        "16 shells, 4 extra lights: deferred (volumes) 10.0 ms: 0.8x naive forward (8.0 ms), "
        "0.80x the fastest forward path (naive, 8.0 ms)"]


def _noisy(pipeline, path, lights, median, spread, shells=0):
    """A point whose three frames have ``median`` and standard deviation ``spread``."""
    from deferred.bench.report import BenchResult

    return BenchResult(pipeline, lights, shells, 64, 36,
                       [median - spread, median, median + spread], light_path=path, rounds=2)


def test_a_difference_within_the_spread_is_a_tie_with_its_numbers():
    """The issue's case: 11.8 ms with a standard deviation of 6.96 ms against 10.0 ms is no
    win: speedups, crossovers and growth say tie and give the numbers."""
    from deferred.bench.report import BenchReport, crossovers, growth, noise, speedups, tied

    report = BenchReport({}, [
        _noisy("deferred", "tiled", 1, 11.8, 6.96), _noisy("forward", "naive", 1, 10.0, 0.5),
        _noisy("deferred", "tiled", 64, 20.0, 1.0), _noisy("forward", "naive", 64, 90.0, 2.0)])
    low = [r for r in report.results if r.lights == 1]
    assert tied(*low) and not tied(*[r for r in report.results if r.lights == 64])
    (at_most,) = speedups(BenchReport({}, low))
    assert at_most == ("0 shells, 1 extra lights: deferred (tiled) 11.8 ± 7.0 ms: a tie with "
                       "naive forward (10.0 ± 0.5 ms: the difference, 1.8 ms, is within the "
                       "spread, 7.0 ms), a tie with the fastest forward path (naive, 10.0 ± "
                       "0.5 ms: the difference, 1.8 ms, is within the spread, 7.0 ms)")
    assert "x naive forward" not in at_most  # no ratio declares a winner
    lines = crossovers(report)
    assert lines[0] == ("0 shells: deferred (tiled) beats naive forward from 64 extra lights "
                        "on; a tie within the noise at 1 (11.8 ± 7.0 ms against 10.0 ± 0.5 ms) "
                        "extra lights")
    assert growth(report) == ["0 shells, deferred (tiled) against its frame at 1 extra lights "
                              "(11.8 ± 7.0 ms): 64: 1.69x"]
    (said,) = noise(report)
    assert said.startswith("noise: a point's frames vary by 0.50-6.96 ms (standard deviation) "
                           "(2-59% of its median)"), said
    assert "tie" in said


def test_the_table_title_says_the_runs_asked_for_and_the_frames_they_timed():
    """--runs 2 is "2 runs" (each a round of 1-4 frames timed back to back), not the frames
    timed (which had read 3, 8 or 12 runs)."""
    from deferred.bench.report import BenchReport, BenchResult, plot_title

    rows = [BenchResult("deferred", 0, 0, 64, 36, [5.0] * frames, rounds=2, light_path="tiled")
            for frames in (3, 8)]
    title = plot_title(BenchReport({"scene": "s.toml", "renderer": "llvmpipe"}, rows))
    assert title == "s.toml, 64x36, 2 runs (3-8 frames timed a point), llvmpipe"
    assert rows[0].to_dict()["runs"] == 2 and rows[1].to_dict()["frames"] == 8


def test_the_time_left_is_each_points_runs_at_its_own_measured_time():
    """A slow point's runs are not estimated from a fast point's: each point's runs left at
    its own mean run, a point not yet run at the median of the means, warm-ups at theirs."""
    from deferred.bench.harness import _SweepClock

    clock = _SweepClock(2, ["fast", "slow"], runs=3)
    assert clock.seconds_left() is None  # nothing measured
    clock.warmed_up(4.0)
    clock.ran("fast", 0.5)
    # a warm-up left at 4 s, fast's 2 runs at 0.5 s, slow's 3 at the median of the means
    assert clock.seconds_left() == pytest.approx(4.0 + 2 * 0.5 + 3 * 0.5)
    clock.warmed_up(6.0)
    clock.ran("slow", 20.0)
    assert clock.seconds_left() == pytest.approx(2 * 0.5 + 2 * 20.0)
    assert clock.at("round 1").runs_done == 2 and clock.at("round 1").runs_total == 6


def test_growth_compares_the_best_deferred_path_with_its_own_frame_at_the_fewest_lights():
    from deferred.bench.report import BenchReport, BenchResult, growth

    def row(pipeline, path, lights, ms, shells=0):
        return BenchResult(pipeline, lights, shells, 64, 36, [ms], light_path=path)

    report = BenchReport({}, [
        row("deferred", "volumes", 1, 8.0), row("deferred", "tiled", 1, 10.0),
        row("forward", "tiled", 1, 6.0),
        row("deferred", "volumes", 256, 40.0), row("deferred", "tiled", 256, 12.5),
        row("forward", "tiled", 256, 30.0),
        row("deferred", "volumes", 1024, 160.0), row("deferred", "tiled", 1024, 20.0),
        row("deferred", "volumes", 4, 10.0, shells=16)])
    # the tiled path is the fastest at 1024; its 1-light frame, not volumes' faster one, is 1x
    assert growth(report) == [
        "0 shells, deferred (tiled) against its frame at 1 extra lights (10.0 ms): "
        "256: 1.25x, 1024: 2.00x"]


def _record_frames(monkeypatch):
    """Log which renderer each frame and each release belongs to, in order."""
    from deferred.render.renderer import Renderer

    events = []
    render, release = Renderer.render, Renderer.release

    def logged_render(self, *args, **kwargs):
        events.append(("frame", (self.pipeline_name, self.light_path, len(self.scene.lights))))
        return render(self, *args, **kwargs)

    def logged_release(self):
        events.append(("release", (self.pipeline_name, self.light_path,
                                   len(self.scene.lights))))
        return release(self)

    monkeypatch.setattr(Renderer, "render", logged_render)
    monkeypatch.setattr(Renderer, "release", logged_release)
    return events


@pytest.mark.parametrize("interleave", [True, False])
def test_interleaved_points_alternate_their_frames_round_by_round(gl, monkeypatch, interleave):
    scene = standard_scene()
    events = _record_frames(monkeypatch)
    steps = []
    sweep = Sweep(lights=[0, 3], runs=3, warmup=1, light_paths=["tiled"],
                  interleave=interleave, round_ms=0.0)  # one timed frame a round
    report = run_bench(scene, sweep, gl=gl, progress=steps.append)
    from deferred.bench.harness import sweep_runs

    # called before each of the 4 warm-ups and the 12 runs, the runs counted
    assert sweep_runs(scene, sweep) == 12
    assert len(steps) == 4 + 12 and {s.runs_total for s in steps} == {12}
    assert [s.runs_done for s in steps if s.description.startswith("round")] == list(range(12))
    assert steps[0].seconds_left is None  # nothing measured yet
    assert steps[-1].seconds_left is not None and steps[-1].seconds_left >= 0.0
    assert report.renderer["interleaved"] is interleave
    own = len(scene.lights)
    points = [("deferred", "tiled", own), ("forward", "tiled", own),
              ("deferred", "tiled", own + 3), ("forward", "tiled", own + 3)]
    assert [(r.pipeline, r.light_path, r.lights) for r in report.results] == [
        (p, path, n - own) for p, path, n in points]
    assert all(r.runs == 3 and r.draw_calls > 0 and r.passes_ms for r in report.results)
    frames = [point for kind, point in events if kind == "frame"]
    releases = [i for i, (kind, _) in enumerate(events) if kind == "release"]
    # a warm-up, then 3 rounds of 3 kinds of frame (4 where the driver answers timer queries)
    kinds = 4 if report.renderer["gl_timer_queries"] else 3
    assert Counter(frames) == {point: 1 + 3 * kinds for point in points}
    if interleave:
        # every renderer is warmed up first, then each round has each point's frames together,
        # the points in a shuffled order (seeded: the same each sweep); all released at the end
        assert frames[:4] == points
        orders = []
        per_round = 4 * kinds
        for k in range(3):
            round_frames = frames[4 + per_round * k:4 + per_round * (k + 1)]
            order = round_frames[::kinds]
            assert sorted(order) == sorted(points)
            assert round_frames == [p for p in order for _ in range(kinds)]
            orders.append(order)
        assert len({tuple(order) for order in orders}) > 1  # not one fixed order
        assert releases == list(range(len(events) - 4, len(events)))
        again = _record_frames(monkeypatch)
        run_bench(scene, sweep, gl=gl)
        assert [p for kind, p in again if kind == "frame"] == frames
    else:
        # one point's frames, then its release, then the next point's
        per_point = 1 + 3 * kinds
        assert frames == [p for p in points for _ in range(per_point)]
        assert releases == [(per_point + 1) * (i + 1) - 1 for i in range(4)]
    if report.renderer["gl_timer_queries"]:
        assert all(r.gpu_passes_ms and set(r.gpu_passes_ms) == set(r.passes_ms)
                   for r in report.results)


def test_a_round_times_a_cheap_point_back_to_back_and_drops_the_first(gl, monkeypatch):
    """Within a round a point's timed frames run back to back until they make round_ms (at
    most ROUND_FRAMES), and the first, which follows another point's frames, is dropped."""
    from deferred.bench.harness import ROUND_FRAMES

    events = _record_frames(monkeypatch)
    scene = standard_scene()
    report = run_bench(scene, Sweep(lights=[0], runs=2, warmup=0, light_paths=["naive"],
                                    pipelines=["forward"], round_ms=1e9), gl=gl)
    kinds = 4 if report.renderer["gl_timer_queries"] else 3
    (result,) = report.results
    assert result.runs == 2 and result.frames == len(result.times_ms) == 2 * (ROUND_FRAMES - 1)
    frames = [p for kind, p in events if kind == "frame"]
    assert len(frames) == 2 * (ROUND_FRAMES + kinds - 1)
