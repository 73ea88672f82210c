"""``deferred bench --sweep lights=1,64,256 shells=16,64 size=640x360,1280x720``: every point of
the grid (a light count, a shell count, a size) timed as a task of its own, in every pipeline
and light path asked for, here or on workers (``--workers N``, ``--ray [ADDRESS]``:
:mod:`deferred.farm.tasks` says how timings stay apart), the scene sent to them by content;
the points' reports merged into one, in the grid's order."""

from __future__ import annotations

import itertools
import re
import socket
from collections.abc import Callable, Sequence
from dataclasses import replace

from deferred.bench.harness import Sweep, check_sweep, parse_counts, run_bench
from deferred.bench.report import BenchReport
from deferred.errors import InputError
from deferred.farm.bundle import SceneBundle, UnpackedScene
from deferred.scene.size import parse_size

GRID_KEYS = ("lights", "shells", "size")
GRID_ENTRY = re.compile(r"^(lights|shells|size)=(.*)$")


def is_grid_entry(text: str) -> bool:
    """Whether a command-line word is ``KEY=VALUES`` of a grid (``lights=1,64``)."""
    return GRID_ENTRY.match(text) is not None


def parse_grid(entries: Sequence[str], where: str = "--sweep") -> dict[str, list]:
    """``["lights=1,64", "size=640x360,1280x720"]`` -> {"lights": [1, 64], "size": [(640,
    360), (1280, 720)]}; ``InputError`` naming the entry."""
    grid: dict[str, list] = {}
    for entry in entries:
        match = GRID_ENTRY.match(entry)
        if match is None:
            raise InputError(f"expected KEY=VALUE,... with KEY one of {', '.join(GRID_KEYS)}, "
                             f"got {entry!r}", where)
        key, values = match.groups()
        if key in grid:
            raise InputError(f"{key} given twice", where)
        if key == "size":
            grid[key] = [parse_size(value, f"{where} size") for value in values.split(",")]
        else:
            grid[key] = parse_counts(values, f"{where} {key}")
    return grid


def grid_sweeps(base: Sweep, grid: dict[str, list]) -> list[Sweep]:
    """One sweep per point of the grid (a key left out keeps ``base``'s values)."""
    lights = [[count] for count in grid["lights"]] if "lights" in grid else [base.lights]
    shells = [[count] for count in grid["shells"]] if "shells" in grid else [base.shells]
    sizes = grid.get("size", [base.size])
    return [replace(base, lights=point_lights, shells=point_shells, size=size)
            for size, point_shells, point_lights in itertools.product(sizes, shells, lights)]


def check_grid(scene, sweeps: list[Sweep]) -> None:
    for sweep in sweeps:
        check_sweep(scene, sweep)


def time_point(bundle: SceneBundle, sweep: Sweep) -> BenchReport:
    """One grid point timed where this runs (a worker): the scene loaded from its bytes."""
    from deferred.scene.loader import load_scene

    unpacked = UnpackedScene(bundle)
    try:
        report = run_bench(load_scene(unpacked.path), sweep)
        report.renderer["host"] = socket.gethostname()
        return report
    finally:
        unpacked.remove()


def run_grid(bundle: SceneBundle, sweeps: list[Sweep], workers: int | None, ray: str | None,
             on_done: Callable[[int, int], None]) -> BenchReport:
    """Every point's report, merged: the results in the grid's order, the renderer's
    description from the first point with how the points were placed."""
    from deferred.farm.tasks import placement, run_tasks

    reports = run_tasks(time_point, [(bundle, sweep) for sweep in sweeps], workers, ray,
                        on_done)
    renderer = {**reports[0].renderer, "sweep_points": len(sweeps),
                "sweep_placement": placement(workers, ray)}
    hosts = sorted({str(report.renderer.get("host", "")) for report in reports} - {""})
    if hosts:
        renderer["sweep_hosts"] = hosts
    return BenchReport(renderer, [result for report in reports for result in report.results])
