"""Issue #40: ``deferred bench --sweep``: every grid point a task (here, on pinned local workers,
on a local Ray instance), one merged report in the grid's order; a bad grid is one line."""

from __future__ import annotations

import json

import pytest
from command_line import assert_one_line_error, run

from deferred.bench.grid import grid_sweeps, parse_grid
from deferred.bench.harness import Sweep

FAST = ["--runs", "1", "--warmup", "0", "--pipelines", "deferred", "--light-paths", "tiled"]


def test_the_grid_is_every_combination_in_order():
    grid = parse_grid(["lights=1,64", "size=640x360,1280x720", "shells=16"])
    assert grid == {"lights": [1, 64], "size": [(640, 360), (1280, 720)], "shells": [16]}
    points = [(s.size, list(s.shells), list(s.lights))
              for s in grid_sweeps(Sweep(runs=3), grid)]
    assert points == [((640, 360), [16], [1]), ((640, 360), [16], [64]),
                      ((1280, 720), [16], [1]), ((1280, 720), [16], [64])]
    assert all(s.runs == 3 for s in grid_sweeps(Sweep(runs=3), grid))


def test_a_bad_grid_is_one_line(tmp_path, capsys):
    code, _, err = run(capsys, "bench", "--sweep", "lights=1,x", *FAST)
    assert_one_line_error(code, err, "--sweep lights")
    code, _, err = run(capsys, "bench", "--sweep", "lights=1", "size=10", *FAST)
    assert_one_line_error(code, err, "--sweep size")
    code, _, err = run(capsys, "bench", "--workers", "2", *FAST)
    assert_one_line_error(code, err, "--workers: times the points of a --sweep grid")


@pytest.mark.slow
@pytest.mark.parametrize("where", ["workers", "ray"])
def test_sweep_points_are_tasks_merged_into_one_report(tmp_path, capsys, request, where):
    if where == "ray":
        pytest.importorskip("ray")
        request.getfixturevalue("local_ray")
        placed = ["--ray"]
    else:
        placed = ["--workers", "2"]
    out = tmp_path / "bench.json"
    code, stdout, err = run(capsys, "bench", "--sweep", "lights=0,2", "size=32x18,48x24",
                            *FAST, *placed, "--json", out, "--csv", tmp_path / "bench.csv")
    assert code == 0, err
    report = json.loads(out.read_text())
    points = [(r["width"], r["height"], r["lights"]) for r in report["results"]]
    assert points == [(32, 18, 0), (32, 18, 2), (48, 24, 0), (48, 24, 2)]
    assert report["renderer"]["sweep_points"] == 4
    placement = report["renderer"]["sweep_placement"]
    assert ("one task at a time on each node" in placement) == (where == "ray")
    assert ("pinned to" in placement) == (where == "workers")
    assert "48x24" in stdout  # the table's size column
    assert len((tmp_path / "bench.csv").read_text().splitlines()) == 5
