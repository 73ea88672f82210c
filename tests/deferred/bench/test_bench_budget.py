"""deferred bench weighed before it runs (deferred.bench.budget): interleaved renderers kept
within the memory budget by timing fewer at once, a sweep past the time budget refused in a
second naming --runs, every light count's lights made once."""

from __future__ import annotations

import time

import pytest

from deferred.bench.budget import interleaved_groups, point_bytes, predict_sweep
from deferred.bench.harness import Sweep, run_bench, sweep_points
from deferred.bench.scenes import LightSweep, with_extra_lights
from deferred.cli import main
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict


def small_scene():
    return scene_from_dict({
        "size": [32, 24], "camera": {"position": [0.0, 1.5, 3.0], "target": [0.0, 0.0, 0.0]},
        "object": [{"mesh": "builtin:plane", "scale": 2.0}],
        "light": [{"type": "ambient"}],
    })


def test_a_light_sweep_gives_each_count_the_lights_with_extra_lights_would():
    scene = small_scene()
    sweep = LightSweep(scene, 40, 4 / 3)
    for count in (0, 7, 40):
        made = with_extra_lights(scene, count, 4 / 3)
        assert [light.params for light in sweep.at(count).lights] == \
            [light.params for light in made.lights]
    assert len(scene.lights) == 1  # the scene itself unchanged


def test_points_are_grouped_to_fit_the_memory_budget(monkeypatch):
    scene = small_scene()
    points = sweep_points(Sweep(lights=[0, 1, 2, 3], light_paths=["tiled"]))
    one = point_bytes(scene, "deferred", "tiled", (32, 24))
    assert one > 16 << 20  # the programs and driver state a renderer holds are counted
    groups, held = interleaved_groups(points, scene, (32, 24))
    assert groups == [points] and held >= len(points) * one // 2
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", str(int(2.5 * one)))
    groups, _ = interleaved_groups(points, scene, (32, 24))
    assert len(groups) > 1 and all(len(group) <= 2 for group in groups)
    assert [point for group in groups for point in group] == points


def test_an_interleaved_sweep_past_the_budget_keeps_fewer_renderers_alive(gl, monkeypatch):
    scene = small_scene()
    one = point_bytes(scene, "deferred", "tiled", (32, 24))
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", str(int(2.5 * one)))
    alive, most = set(), [0]
    made, release = Renderer.__init__, Renderer.release

    def counted_init(self, *args, **kwargs):
        made(self, *args, **kwargs)
        alive.add(id(self))
        most[0] = max(most[0], len(alive))

    def counted_release(self):
        alive.discard(id(self))
        return release(self)

    monkeypatch.setattr(Renderer, "__init__", counted_init)
    monkeypatch.setattr(Renderer, "release", counted_release)
    notes = []
    sweep = Sweep(lights=[0, 1, 2], light_paths=["tiled"], runs=1, warmup=0, round_ms=0.0)
    report = run_bench(scene, sweep, gl=gl, note=notes.append)
    assert len(report.results) == 6 and not alive
    assert most[0] <= 2
    assert len(notes) == 1 and "DEFERRED_TARGET_MEMORY" in notes[0] and "groups" in notes[0]


def test_the_sweeps_time_grows_with_its_points_and_runs():
    scene = small_scene()
    points = sweep_points(Sweep(lights=[0, 64], light_paths=["tiled"]))
    short = predict_sweep(scene, points, 1, (32, 24), runs=2, warmup=1, round_ms=100.0)
    long = predict_sweep(scene, points, 1, (32, 24), runs=20, warmup=1, round_ms=100.0)
    assert 0.0 < short.seconds < long.seconds
    assert predict_sweep(scene, points, 2, (32, 24), 2, 1, 100.0).seconds == \
        pytest.approx(2 * short.seconds)


def test_thousands_of_light_counts_are_refused_in_seconds_naming_runs(tmp_path, capsys,
                                                                      monkeypatch):
    monkeypatch.chdir(tmp_path)
    counts = ",".join(str(n) for n in range(2000))
    start = time.perf_counter()
    code = main(["bench", "--lights", counts, "--size", "64x64"])
    elapsed = time.perf_counter() - start
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --runs: bench predicted to take")
    assert "DEFERRED_TARGET_TIME" in lines[0]
    assert elapsed < 20.0
    assert list(tmp_path.iterdir()) == []
