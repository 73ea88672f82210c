"""``deferred bench``: a scene timed in each pipeline over a sweep of light and shell counts
(benchmarks/README.md describes the method)."""

from __future__ import annotations

import os
import sys
import time
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

import click
from rich.console import Console

from deferred.cli import options
from deferred.cli.options import check_not_inputs, parse_size_option, stderr
from deferred.errors import InputError, RenderError
from deferred.io.cost import Prediction, WorkWarning, check_time, duration
from deferred.io.extras import require_extra
from deferred.io.progress import Progress
from deferred.scene.loader import load_scene

if TYPE_CHECKING:
    from deferred.bench import BenchReport, Sweep
    from deferred.scene import Scene

OUTPUT_OPTIONS = ("--json", "--csv", "--plot")


@click.command(context_settings={"allow_extra_args": True})
@options.scene_argument
@click.option("--lights", default="1,16,64,256,1024", show_default=True, metavar="N,...",
              help="Extra point lights added to the scene's own, one sweep point each.")
@click.option("--shells", metavar="N,...",
              help="Shell counts for every object whose material has 'shells'. Default: the "
                   "scene's own (0 where no object has shells).")
@options.size_option()
@click.option("--runs", type=click.IntRange(min=1, max=10_000), default=10, show_default=True,
              help="Rounds per point: in each, its frames timed back to back for 100 ms (1 to "
                   "4 counted), then one with each pass timed and one of CPU time.")
@click.option("--warmup", type=click.IntRange(min=0, max=10_000), default=2, show_default=True,
              help="Untimed frames first (shader compilation, first uploads).")
@click.option("--pipelines", default="deferred,forward", show_default=True, metavar="NAME,...")
@click.option("--light-paths", default="all", show_default=True, metavar="PATH,...",
              help="Light paths to time: all (every path of each pipeline), or names: "
                   "volumes, tiled, clustered (deferred), naive, tiled (forward).")
@click.option("--interleave/--no-interleave", default=True, show_default=True,
              help="Time the points of a shell count together, their frames alternating (all "
                   "their renderers alive at once), or one after another (less memory).")
@click.option("--json", "json_path", metavar="FILE.json",
              help="Results as JSON ('-': to stdout, in place of the table).")
@click.option("--csv", "csv_path", metavar="FILE.csv", help="Results as CSV.")
@click.option("--plot", "plot_path", metavar="FILE.png",
              help="ms against light count (needs the plot extra: pip install "
                   "'deferred[plot]').")
@click.option("--sweep", "grid", multiple=True, metavar="KEY=V,... [KEY=V,...]",
              help="Time every point of a grid of lights=N,..., shells=N,... and "
                   "size=WxH,..., each point a task of its own (here, or on --workers/--ray).")
@click.option("--workers", type=click.IntRange(min=1, max=256), metavar="N",
              help="With --sweep: N local worker processes, each pinned to its own cores.")
@click.option("--ray", is_flag=False, flag_value="", default=None, metavar="[ADDRESS]",
              help="With --sweep: the points on a Ray cluster, one at a time on each node "
                   "(needs the ray extra).")
@click.pass_context
def bench(context: click.Context, scene: str | None, lights: str, shells: str | None,
          size: str | None, runs: int, warmup: int,
          pipelines: str, light_paths: str, interleave: bool, json_path: str | None,
          csv_path: str | None, plot_path: str | None, grid: tuple[str, ...],
          workers: int | None, ray: str | None) -> None:
    """Time SCENE (the built-in demo when omitted) in each pipeline over a sweep of light and
    shell counts. The table goes to stdout, progress and the sweep's size and time to stderr;
    benchmarks/README.md describes the method and the results."""
    from deferred import bench as benchmark

    scene, grid = _scene_and_grid(context, scene, grid, workers, ray)
    # Every option is checked before the first frame: bad input never costs a sweep.
    sweep = benchmark.Sweep(lights=benchmark.parse_counts(lights, "--lights"),
                            shells=None if shells is None else
                            benchmark.parse_counts(shells, "--shells"),
                            pipelines=benchmark.parse_pipelines(pipelines),
                            light_paths=benchmark.parse_light_paths(light_paths),
                            size=parse_size_option(size), runs=runs, warmup=warmup,
                            interleave=interleave)
    outputs = _output_files(json_path, csv_path, plot_path)
    loaded = load_scene(scene)
    for where, path in outputs.items():
        check_not_inputs([path], loaded, scene, where)
    if grid:
        report = run_grid(scene, loaded, sweep, grid, workers, ray)
    else:
        benchmark.check_sweep(loaded, sweep)
        if shells is not None and not benchmark.shell_objects(loaded):
            stderr.print(f"{loaded.source}: no object has a 'shells' parameter; shell sweep "
                         "skipped (shells 0)")
        report = run_sweep(loaded, sweep)
    print_results(report, to_stderr=json_path == "-")
    if json_path == "-":
        _json_to_stdout(report)
    writers = {"--json": benchmark.write_json, "--csv": benchmark.write_csv,
               "--plot": benchmark.write_plot}
    for where, path in outputs.items():
        writers[where](report, path)
    if outputs:
        stderr.print(f"wrote {', '.join(str(path) for path in outputs.values())}",
                     markup=False, highlight=False, soft_wrap=True)
    if "--plot" in outputs:  # where to look, as a path a viewer or browser opens
        stderr.print(f"plot: {outputs['--plot'].resolve()}", markup=False, highlight=False,
                     soft_wrap=True)


def _scene_and_grid(context: click.Context, scene: str | None, grid: tuple[str, ...],
                    workers: int | None, ray: str | None) -> tuple[str | None, list[str]]:
    """The scene and the grid's entries: ``--sweep lights=1,64 shells=16,64`` leaves the
    entries after the first as words of their own, where click puts the scene."""
    from deferred.bench.grid import is_grid_entry

    words = ([scene] if scene is not None else []) + list(context.args)
    entries = [word for word in words if is_grid_entry(word) and not Path(word).exists()]
    others = [word for word in words if word not in entries]
    if len(others) > 1:
        raise click.UsageError(f"got unexpected extra arguments ({' '.join(others[1:])})")
    if entries and not grid:
        raise click.UsageError(f"{entries[0]} is a grid entry: put it after --sweep")
    if (workers is not None or ray is not None) and not grid:
        raise InputError("times the points of a --sweep grid on workers: add --sweep",
                         "--workers" if workers is not None else "--ray")
    if ray is not None:
        require_extra("ray", ("ray",), "--ray", "--ray")
    return (others[0] if others else None), [*grid, *entries]


def run_grid(scene: str | None, loaded: Scene, sweep: Sweep, entries: list[str],
             workers: int | None, ray: str | None) -> BenchReport:
    """The grid's points as tasks (:mod:`deferred.bench.grid`), the progress on stderr."""
    from deferred.bench import grid as grids
    from deferred.farm.bundle import bundle_scene
    from deferred.farm.tasks import placement

    sweeps = grids.grid_sweeps(sweep, grids.parse_grid(entries))
    grids.check_grid(loaded, sweeps)
    for point in sweeps:
        check_sweep_time(loaded, point)
    stderr.print(f"bench: {len(sweeps)} grid points, {placement(workers, ray)}",
                 markup=False, highlight=False)
    bundle = bundle_scene(scene, loaded)
    with Progress("bench", stderr) as progress:
        progress.count(len(sweeps), "points", "timing the grid")

        def done(count: int, total: int) -> None:
            progress.advance(count, "timing the grid")

        return grids.run_grid(bundle, sweeps, workers, ray, done)


def _output_files(json_path: str | None, csv_path: str | None,
                  plot_path: str | None) -> dict[str, Path]:
    """The files --json, --csv and --plot name, checked (--json - is standard output)."""
    from deferred import bench as benchmark

    outputs = {}
    for where, path in zip(OUTPUT_OPTIONS, (json_path, csv_path, plot_path), strict=True):
        if path is not None and not (where == "--json" and path == "-"):
            outputs[where] = benchmark.check_output(path, where)
    return outputs


def run_sweep(loaded: Scene, sweep: Sweep) -> BenchReport:
    """Time every point of ``sweep``, the progress and the time left on stderr."""
    from deferred import bench as benchmark

    predicted = check_sweep_time(loaded, sweep)
    stderr.print(f"bench: {benchmark.describe_sweep(loaded, sweep)}; time: about "
                 f"{duration(predicted.seconds)} predicted", markup=False, highlight=False)
    with Progress("bench", stderr) as progress:
        progress.count(benchmark.sweep_runs(loaded, sweep), "runs", "starting")
        progress.advance(0, "starting", predicted.seconds)
        started = time.monotonic()
        estimated = []

        def step(at: benchmark.SweepProgress) -> None:
            left = at.seconds_left
            if left is None:  # until a warm-up and a run are measured: the prediction's rest
                left = predicted.seconds - (time.monotonic() - started)
            progress.advance(at.runs_done, at.description, left if left > 0.0 else None)
            if at.seconds_left is not None and not estimated:  # the first measured run
                estimated.append(at.seconds_left)
                progress.note(f"bench: about {duration(at.seconds_left)} left, from the "
                              "warm-ups and the first run measured")

        return benchmark.run_bench(loaded, sweep, progress=step, note=progress.note)


def check_sweep_time(loaded: Scene, sweep: Sweep) -> Prediction:
    """The sweep's predicted time (:func:`deferred.bench.budget.predict_sweep`), refused past
    the time budget naming --runs, and warned of past a minute."""
    from deferred import bench as benchmark
    from deferred.bench.budget import BENCH_REMEDY, predict_sweep

    predicted = predict_sweep(loaded, benchmark.sweep_points(sweep),
                              len(benchmark.sweep_shells(loaded, sweep.shells)),
                              sweep.size or loaded.size, sweep.runs, sweep.warmup,
                              sweep.round_ms)
    said = check_time(predicted, "bench", BENCH_REMEDY)
    if said is not None:
        warnings.warn(said, WorkWarning, stacklevel=2)
    return predicted


def print_results(report: BenchReport, to_stderr: bool) -> None:
    """The table and the comparisons: the results, on stdout unless the JSON is there."""
    from deferred import bench as benchmark

    results = Console(stderr=to_stderr)
    if not results.is_terminal:
        results = Console(stderr=to_stderr, width=160)  # pipes: not 80 columns
    results.print(benchmark.results_table(report))
    for line in [*benchmark.noise(report), *benchmark.crossovers(report),
                 *benchmark.speedups(report), *benchmark.growth(report)]:
        results.print(line, markup=False, highlight=False, soft_wrap=True)


def _json_to_stdout(report: BenchReport) -> None:
    try:  # a full disk or a closed pipe shows here, not as a warning at exit
        click.echo(report.to_json(), nl=False)
        sys.stdout.flush()
    except OSError as exc:
        # what did not fit stays buffered: send it to nowhere, or the flush at exit fails
        # again and prints a traceback
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        raise RenderError(f"cannot write standard output: {exc.strerror or exc}") from exc
