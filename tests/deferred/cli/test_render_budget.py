"""deferred render weighed before it runs (issue #38, items 4 and 8): work past the time budget
refused in a second, in one line naming the key and the budget, before the meshes it would
make; a warning past a minute; memory the budget did not see (hair tubes, a strand file
parsed, collision spheres) counted before it is taken."""

from __future__ import annotations

import json
import time

import pytest

from deferred.cli import main
from deferred.scene import loader

FUR_5M = """size = [64, 64]
[[object]]
mesh = "builtin:sphere?segments=2236&rings=1118"
material = "shell_fur"
[[light]]
type = "directional"
"""
HAIR_MAX = """size = [64, 64]
[[object]]
name = "head"
mesh = "builtin:head"
material = "cartoon_hair"
[object.params]
strands = 20000
segments = 32
hair_samples = 64
sides = 16
{extra}
[[light]]
type = "directional"
"""
SMALL = """size = [40, 30]
[[object]]
mesh = "builtin:sphere?segments=12&rings=6"
[[light]]
type = "directional"
"""


def refused(tmp_path, capsys, monkeypatch, args, text=None, limit=20.0):
    """Run ``deferred`` with ``args`` (``s.toml`` holding ``text``): the one error line."""
    monkeypatch.chdir(tmp_path)
    if text is not None:
        (tmp_path / "s.toml").write_text(text)
    before = sorted(p.name for p in tmp_path.iterdir())
    start = time.perf_counter()
    code = main(args)
    elapsed = time.perf_counter() - start
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert elapsed < limit, elapsed
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written
    return lines[0]


def test_hours_of_samples_are_refused_in_a_second_naming_samples(tmp_path, capsys,
                                                                monkeypatch):
    line = refused(tmp_path, capsys, monkeypatch,
                   ["render", "-o", "out.png", "--samples", "1024", "--size", "4096x4096"])
    assert line.startswith("error: --samples: render predicted to take "), line
    for fragment in ("1,024 samples", "the budget is 1 h", "DEFERRED_TARGET_TIME"):
        assert fragment in line, line


def test_the_budget_variable_lets_it_through_to_the_next_check(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("DEFERRED_TARGET_TIME", "1e9")
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", "100000000")  # stops it before any frame
    line = refused(tmp_path, capsys, monkeypatch,
                   ["render", "-o", "out.png", "--samples", "1024", "--size", "4096x4096"])
    assert "DEFERRED_TARGET_MEMORY" in line and "DEFERRED_TARGET_TIME" not in line


def test_a_5m_triangle_fur_is_refused_before_its_mesh_is_made(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(loader, "load_mesh", lambda *a, **k: pytest.fail("mesh made"))
    line = refused(tmp_path, capsys, monkeypatch, ["render", "s.toml", "-o", "out.png"], FUR_5M,
                   limit=10.0)
    assert "4,999,696 strands" in line and "strand steps" in line, line


def test_a_tight_budget_refuses_a_small_render_naming_the_scenes_size(tmp_path, capsys,
                                                                     monkeypatch):
    monkeypatch.setenv("DEFERRED_TARGET_TIME", "0.01")
    line = refused(tmp_path, capsys, monkeypatch, ["render", "s.toml", "-o", "out.png"], SMALL)
    assert line.startswith("error: s.toml: size: render predicted to take"), line


def test_past_a_minute_a_warning_says_the_prediction(tmp_path, capsys, monkeypatch):
    import deferred.io.cost as cost

    monkeypatch.setattr(cost, "WARN_SECONDS", 0.0)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(SMALL)
    assert main(["render", "s.toml", "-o", "out.png", "--samples", "2"]) == 0
    err = capsys.readouterr().err
    assert "warning: render predicted to take about" in err and "2 samples" in err, err
    assert (tmp_path / "out.png").exists()


def test_hair_at_its_maxima_is_refused_under_a_small_memory_budget(tmp_path, capsys,
                                                                  monkeypatch):
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", "300000000")
    line = refused(tmp_path, capsys, monkeypatch, ["render", "s.toml", "-o", "out.png"],
                   HAIR_MAX.format(extra="silhouettes = true"))
    assert "hair tubes of head" in line and "DEFERRED_TARGET_MEMORY" in line, line


def test_more_collision_spheres_than_the_limit_are_refused(tmp_path, capsys, monkeypatch):
    spheres = "collision_spheres = [" + ", ".join(["[0, 0, 0, 0.1]"] * 257) + "]"
    line = refused(tmp_path, capsys, monkeypatch, ["render", "s.toml", "-o", "out.png"],
                   HAIR_MAX.format(extra=spheres))
    assert "object[0].params.collision_spheres" in line and "256" in line, line


def test_a_strand_file_past_the_memory_budget_is_refused_before_it_is_parsed(
        tmp_path, capsys, monkeypatch):
    from deferred.materials.techniques import hair_strands

    strands = [[[0.0, 0.1 + 0.01 * k, 0.001 * n] for k in range(8)] for n in range(2000)]
    (tmp_path / "hair.json").write_text(json.dumps({"strands": strands}))
    monkeypatch.setattr(hair_strands.json, "loads", lambda *a: pytest.fail("parsed"))
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", "2000000")
    line = refused(tmp_path, capsys, monkeypatch, ["render", "s.toml", "-o", "out.png"],
                   HAIR_MAX.format(extra='strands_file = "hair.json"'))
    assert "strands_file" in line and "parsing the" in line and "hair.json" in line, line


def test_samples_count_as_steps_of_the_progress(tmp_path, capsys, monkeypatch):
    from deferred.io.progress import Progress

    counted, advanced = [], []
    count, advance = Progress.count, Progress.advance
    monkeypatch.setattr(Progress, "count", lambda self, total, unit, text="": (
        counted.append((total, unit, text)), count(self, total, unit, text))[1])
    monkeypatch.setattr(Progress, "advance", lambda self, done=None, text=None, seconds_left=None:
                        (advanced.append((done, seconds_left)),
                         advance(self, done, text, seconds_left))[1])
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(SMALL)
    assert main(["render", "s.toml", "-o", "out.png", "--samples", "6"]) == 0
    assert capsys.readouterr().err.startswith("wrote out.png")
    assert counted == [(6, "samples", "rendering out.png (the first frame: compiling shaders)")]
    # the time left from the prediction before a sample is measured, then from the samples
    assert [done for done, _ in advanced] == list(range(7))
    assert advanced[0][1] > 0.0 and advanced[-1][1] == 0.0
    assert all(left is not None and left >= 0.0 for _, left in advanced)


def test_the_step_clock_predicts_then_measures_without_the_first_step():
    from deferred.cli.budget import StepClock

    now = [0.0]
    clock = StepClock(10, predicted=2.0, clock=lambda: now[0])
    now[0] = 5.0  # the first step compiles: not a measure of the others
    assert clock.done(1) == pytest.approx(9 * 2.0)
    now[0] = 6.0
    assert clock.done(2) == pytest.approx(8 * 1.0)
    now[0] = 9.0
    assert clock.done(3) == pytest.approx(7 * 2.0)  # the median of 1 s and 3 s


def test_the_arrays_averaging_samples_are_counted_against_the_memory_budget(
        tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", "12000000")  # 256x256: 14.7 MB of arrays
    line = refused(tmp_path, capsys, monkeypatch, ["render", "s.toml", "-o", "out.png",
                                                   "--size", "256x256", "--samples", "4"], SMALL)
    assert line.startswith("error: --samples: averaging 4 samples of 256x256 needs"), line
    assert main(["render", "s.toml", "-o", "out.png", "--size", "256x256"]) == 0  # one holds none
