"""Benchmarks: the same scene through each pipeline over a sweep of light and shell counts.

README.md, "Benchmarks", and benchmarks/README.md. Every (pipeline, light path, lights, shells)
point of a sweep gets its own renderer on one shared GL context: ``warmup`` untimed frames
(shaders compile there), then
``runs`` rounds, each of frames timed by wall clock around ``render()`` plus ``ctx.finish()``
(back to back for ``round_ms``, the first dropped: a 20 ms frame is timed four times a round, a
3 s one once), one frame timing each pass the same way (kept apart so the per-pass
``finish()`` calls do not inflate the totals), one frame of CPU time, and one with GL timer
queries where the driver answers them. The points of one shell count are timed together,
their rounds interleaved (:func:`run_bench`), so that ratios between them survive the
machine's drift.

The light sweep adds ``L`` point lights to the scene's own, placed by a seeded generator inside
the objects' world bounds where the camera sees them, each with a radius covering a fixed share
of the view at its depth, so every light touches the screen whatever the scene's scale. The
lights of a smaller count are the first lights of a larger one. The shell sweep sets ``shells``
on every object whose material has that parameter (``revie_fur``); without one the scene runs
with its own shells (its largest count is the rows' ``shells``).

Every light path of each pipeline runs (``light_path``: ``volumes``, ``tiled``, ``clustered``
for deferred, ``naive`` and ``tiled`` (Forward+) for forward), unless ``--light-paths`` picks.
Besides wall-clock times, each row holds the framework's own CPU time per frame and per draw
call (the rendering thread's CPU time over ``render()``, less its time inside the drawing GL
calls, where llvmpipe does vertex work on the calling thread: :func:`time_cpu`), and per-pass GL
timer-query times where the driver answers them (``gpu_passes_ms``; llvmpipe does not).

JSON: ``{"renderer": {...}, "results": [{"pipeline", "light_path", "lights", "shells", "width",
"height", "runs", "frames", "median_ms", "mean_ms", "min_ms", "max_ms", "stddev_ms", "times_ms",
"passes_ms", "cpu_ms", "draw_calls", "cpu_us_per_draw", "gpu_passes_ms"}]}``. ``lights`` counts
the extra lights; ``renderer`` also records the G-buffer layout and bytes per pixel, the CPU
count and the scene. CSV: the same columns, the lists and mappings as JSON text.
"""

from __future__ import annotations

import random
import statistics
import time
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from deferred.bench.budget import ROUND_FRAMES, interleaved_groups
from deferred.bench.report import BenchReport, BenchResult, renderer_info
from deferred.bench.scenes import MAX_LIGHTS, LightSweep, shell_objects, with_shells
from deferred.bench.timing import (
    cpu_frame,
    gpu_frame,
    medians,
    pass_frame,
    time_frame,
    timer_queries,
    timer_queries_work,
)
from deferred.errors import InputError
from deferred.gl.context import GLContext, create_context
from deferred.io.extras import PLOT, require_extra
from deferred.io.images import amount
from deferred.io.memory import BUDGET_VARIABLE, memory_budget
from deferred.io.paths import check_output_path
from deferred.names import LIGHT_PATHS, LightPath, Pipeline
from deferred.render.pipeline import PIPELINES
from deferred.render.renderer import Renderer
from deferred.scene.scene import Scene

DEFAULT_LIGHTS = (1, 16, 64, 256, 1024)
ROUND_ORDER_SEED = 0  # run_bench: the order of the points in each round
OUTPUT_SUFFIXES = {"--json": ".json", "--csv": ".csv", "--plot": ".png"}


# -- options -------------------------------------------------------------------------------------

def parse_counts(text: str, where: str) -> list[int]:
    """``"1,16,64"`` -> ``[1, 16, 64]``: non-negative integers, sorted, duplicates dropped."""
    parts = [p.strip() for p in text.split(",")]
    try:
        counts = [int(p) for p in parts]
    except ValueError:
        raise InputError(f"expected comma-separated whole numbers such as 1,16,64, got '{text}'",
                         where) from None
    negative = [c for c in counts if c < 0]
    if negative:
        raise InputError(f"counts must be 0 or more, got {negative[0]}", where)
    return sorted(set(counts))


def parse_light_paths(text: str, where: str = "--light-paths") -> list[str] | None:
    """``"all"`` (None: every path of each pipeline) or path names, checked."""
    if text.strip() == "all":
        return None
    names = [p.strip() for p in text.split(",") if p.strip()]
    known = [path.value for path in LightPath]
    for name in names:
        if name not in known:
            raise InputError(f"unknown light path '{name}' (choose from all, "
                             f"{', '.join(known)})", where)
    if not names:
        raise InputError(f"expected light paths such as tiled,volumes, got '{text}'", where)
    return list(dict.fromkeys(names))


def pipeline_paths(pipeline: str, light_paths: Sequence[str] | None) -> list[str]:
    """The light paths a sweep runs for ``pipeline``: every one of its own, or those named that
    it has."""
    own = LIGHT_PATHS[Pipeline(pipeline)]
    return list(own) if light_paths is None else [p for p in own if p in light_paths]


def parse_pipelines(text: str, where: str = "--pipelines") -> list[str]:
    names = [p.strip() for p in text.split(",") if p.strip()]
    if not names:
        raise InputError(f"expected pipeline names such as deferred,forward, got '{text}'", where)
    for name in names:
        if name not in PIPELINES:
            raise InputError(f"unknown pipeline '{name}' (choose from "
                             f"{', '.join(PIPELINES)})", where)
    return list(dict.fromkeys(names))


def check_output(path: str | Path, where: str) -> Path:
    """An output file named by ``where`` (``--json``...) with that option's suffix; a plot
    needs the ``plot`` extra (matplotlib)."""
    checked = check_output_path(path, where, (OUTPUT_SUFFIXES[where],), patterns=False)
    if where == "--plot":
        require_extra(PLOT, ("matplotlib",), "a plot", where)
    return checked




@dataclass(frozen=True)
class Sweep:
    lights: Sequence[int] = DEFAULT_LIGHTS
    shells: Sequence[int] | None = None  # None: the scene's own shells, as they are
    pipelines: Sequence[str] = tuple(Pipeline)
    light_paths: Sequence[str] | None = None  # None: every path of each pipeline
    size: tuple[int, int] | None = None  # None: the scene's size
    runs: int = 10
    warmup: int = 2
    interleave: bool = True  # the points of a shell count timed together (run_bench)
    # a point's timed frames in a round: back to back until they make this (ROUND_FRAMES at
    # most, the first dropped where there are more); 0: one a round
    round_ms: float = 100.0


def own_shells(scene: Scene) -> int:
    """The scene's own shell count: its objects' largest (0 where none has shells)."""
    return max((int(obj.material.params.shells) for obj in shell_objects(scene)), default=0)


def sweep_shells(scene: Scene, shells: Sequence[int] | None) -> list[int]:
    """The shell counts a sweep really runs: the scene's own where none are given, one value
    (0) when no object has shells."""
    if shells is None:
        return [own_shells(scene)]
    return list(shells) if shell_objects(scene) else [0]


def _shelled(scene: Scene, sweep: Sweep, shells: int) -> Scene:
    """The scene at one of the sweep's shell counts (as it is without a shell sweep)."""
    if sweep.shells is None or not shell_objects(scene):
        return scene
    return with_shells(scene, shells)


@dataclass
class _TimedPoint:
    """A sweep point being timed: its renderer and the samples gathered so far."""

    lights: int
    pipeline: str
    light_path: str
    renderer: Any
    queries: dict[str, Any] | None = None  # timer queries, where the driver answers them
    times_ms: list[float] = field(default_factory=list)
    passes_ms: dict[str, list[float]] = field(default_factory=dict)
    cpu_ms: list[float] = field(default_factory=list)
    gpu_ms: dict[str, list[float]] = field(default_factory=dict)
    draw_calls: int = 0
    rounds: int = 0

    def time_round(self, round_ms: float) -> None:
        """Timed frames back to back until they make ``round_ms`` (at most ROUND_FRAMES; the
        first dropped where there are more, since it pays for the frame of another point just
        before it), one frame with every pass fenced, one of CPU time, and one with timer
        queries where the driver answers them."""
        frames = [time_frame(self.renderer)]
        while len(frames) < ROUND_FRAMES and sum(frames) < round_ms:
            frames.append(time_frame(self.renderer))
        self.times_ms += frames[1:] if len(frames) > 1 else frames
        self.rounds += 1
        for name, values in pass_frame(self.renderer).items():
            self.passes_ms.setdefault(name, []).extend(values)
        cpu, self.draw_calls = cpu_frame(self.renderer)
        self.cpu_ms.append(cpu)
        if self.queries is not None:
            for name, ms in gpu_frame(self.renderer, self.queries).items():
                self.gpu_ms.setdefault(name, []).append(ms)

    def result(self, shells: int) -> BenchResult:
        return BenchResult(self.pipeline, self.lights, shells, *self.renderer.size,
                           self.times_ms, medians(self.passes_ms), self.light_path,
                           statistics.median(self.cpu_ms), self.draw_calls,
                           medians(self.gpu_ms) if self.queries is not None else None,
                           self.rounds)


def sweep_points(sweep: Sweep) -> list[tuple[int, str, str]]:
    """The (lights, pipeline, light path) points of one shell count, in the report's order."""
    return [(lights, pipeline, path) for lights in sweep.lights for pipeline in sweep.pipelines
            for path in pipeline_paths(pipeline, sweep.light_paths)]


def sweep_runs(scene: Scene, sweep: Sweep) -> int:
    """The runs of a sweep: a round of each configuration, ``sweep.runs`` each (a
    configuration is a pipeline's light path at a light count and a shell count)."""
    return len(sweep_shells(scene, sweep.shells)) * len(sweep_points(sweep)) * sweep.runs


def describe_sweep(scene: Scene, sweep: Sweep) -> str:
    """The sweep's size in words: ``24 configurations (4 light paths x 3 light counts x 2
    shell counts) x 10 runs, after 2 warm-up frames each``."""
    paths = len({(pipeline, path) for _, pipeline, path in sweep_points(sweep)})
    shells = sweep_shells(scene, sweep.shells)
    configurations = len(sweep_points(sweep)) * len(shells)

    def counted(count: int, what: str) -> str:
        return f"{count} {what}{'s' if count != 1 else ''}"

    shell_part = (counted(len(shells), "shell count") if sweep.shells is not None
                  else f"the scene's {shells[0]} shells")
    return (f"{counted(configurations, 'configuration')} ({counted(paths, 'light path')} x "
            f"{counted(len(sweep.lights), 'light count')} x {shell_part}) x "
            f"{counted(sweep.runs, 'run')}, after {counted(sweep.warmup, 'warm-up frame')} each")


def check_sweep(scene: Scene, sweep: Sweep) -> None:
    """Everything :func:`run_bench` refuses, refused before any GL work (``InputError``)."""
    if sweep.runs < 1:
        raise InputError(f"runs must be 1 or more, got {sweep.runs}", "--runs")
    if sweep.warmup < 0:
        raise InputError(f"warmup must be 0 or more, got {sweep.warmup}", "--warmup")
    if max(sweep.lights, default=0) + len(scene.lights) > MAX_LIGHTS:
        raise InputError(f"at most {MAX_LIGHTS} lights in all, the scene has "
                         f"{len(scene.lights)}", "--lights")
    if not sweep_points(sweep):
        raise InputError("no light path of the pipelines chosen is in --light-paths",
                         "--light-paths")
    ran = {path for pipeline in sweep.pipelines for path in pipeline_paths(pipeline, None)}
    dropped = [path for path in sweep.light_paths or () if path not in ran]
    if dropped:  # a path of a pipeline not chosen would be left out without a word
        raise InputError(f"{', '.join(dropped)} is no light path of "
                         f"{', '.join(sweep.pipelines)} (add its pipeline to --pipelines)",
                         "--light-paths")
    for shells in sweep_shells(scene, sweep.shells):
        _shelled(scene, sweep, shells)  # each material's range of shells


@dataclass(frozen=True)
class SweepProgress:
    """Where a sweep stands when :func:`run_bench` starts a step (a warm-up or a run): what the
    step is, the runs done of all, and the time left, estimated from the warm-ups and runs
    measured so far (None until one of each was)."""

    description: str
    runs_done: int
    runs_total: int
    seconds_left: float | None


class _SweepClock:
    """The time a sweep has left: the warm-ups still to come at the mean of those measured,
    and each point's runs still to come at that point's mean measured run (points are slow and
    fast by factors: one fast point's run says little of a slow one's), a point not yet run
    at the median of the points' means."""

    def __init__(self, warmups: int, points: Sequence[Hashable], runs: int):
        self.warmups_left = warmups
        self.runs = runs
        self.runs_total = len(points) * runs
        self.warmup_s: list[float] = []
        self.run_s: dict[Hashable, list[float]] = {point: [] for point in points}

    def warmed_up(self, seconds: float) -> None:
        self.warmup_s.append(seconds)
        self.warmups_left -= 1

    def ran(self, point: Hashable, seconds: float) -> None:
        self.run_s[point].append(seconds)

    @property
    def runs_done(self) -> int:
        return sum(len(times) for times in self.run_s.values())

    def seconds_left(self) -> float | None:
        means = {point: statistics.fmean(times) for point, times in self.run_s.items() if times}
        if not means or (self.warmups_left and not self.warmup_s):
            return None
        unmeasured = statistics.median(means.values())
        warmup = statistics.fmean(self.warmup_s) if self.warmup_s else 0.0
        return self.warmups_left * warmup + sum(
            (self.runs - len(times)) * means.get(point, unmeasured)
            for point, times in self.run_s.items())

    def at(self, description: str) -> SweepProgress:
        return SweepProgress(description, self.runs_done, self.runs_total, self.seconds_left())


def run_bench(scene: Scene, sweep: Sweep, gl: GLContext | None = None,
              progress: Callable[[SweepProgress], None] | None = None,
              note: Callable[[str], None] | None = None) -> BenchReport:
    """Render every (pipeline, light path, lights, shells) point of ``sweep`` and time it.

    With ``sweep.interleave`` (the default) the points of one shell count are timed together:
    every point's renderer is built and warmed up, then each of ``runs`` rounds gives every
    point its frames (timed ones back to back for ``sweep.round_ms``, the first of them
    dropped, then one with its passes fenced, one of CPU time, one with timer queries where
    the driver answers them), the points in a shuffled order (seeded: the same orders each
    sweep). A drift in the machine's speed (other load, clocks, llvmpipe's threads) then falls
    on every point alike, and so does whatever one point's frames do to the next one's: in a
    fixed order each point followed the same one every round, and one point's G-buffer passes,
    the same work as another's, ran 40% slower (benchmarks/README.md). Ratios between points
    (a light count against another, a path against another) hold where timing one point after
    another moved them by 40%. The cost: all those renderers are alive at once (about 50-90 MB
    each on the demo, whatever the size), so they are counted against the memory budget
    before any is made, and where they do not fit at once they are timed in groups that do
    (:func:`~deferred.bench.budget.interleaved_groups`; ``note`` is told). Without it, one
    point is built, timed and released after another. ``progress`` is called with a
    :class:`SweepProgress` before each warm-up and each run (a configuration's round).
    """
    check_sweep(scene, sweep)
    points = sweep_points(sweep)
    size = sweep.size or scene.size
    aspect = size[0] / size[1]
    shell_counts = sweep_shells(scene, sweep.shells)
    clock = _SweepClock(len(points) * len(shell_counts),
                        [(shells, *point) for shells in shell_counts for point in points],
                        sweep.runs)

    def report(description: str) -> None:
        if progress is not None:
            progress(clock.at(description))

    owns = gl is None
    gl = gl or create_context()
    results = []
    try:
        timers = timer_queries_work(gl)
        for shells in shell_counts:
            lit = LightSweep(_shelled(scene, sweep, shells), max(sweep.lights, default=0),
                             aspect)
            if sweep.interleave:
                groups, held = interleaved_groups(points, lit.at(max(sweep.lights, default=0)),
                                                 size)
                if len(groups) > 1 and note is not None:
                    note(f"bench: the {len(points)} renderers of a round need about "
                         f"{amount(held)} together, more than the memory budget of "
                         f"{amount(memory_budget())} ({BUDGET_VARIABLE}): timed in "
                         f"{len(groups)} groups of up to {max(map(len, groups))}")
            else:
                groups = [[point] for point in points]
            for group in groups:
                results += _time_group(group, lit, shells, sweep, size, gl, timers, clock,
                                       report)
        info = {**renderer_info(gl, scene), "gl_timer_queries": timers,
                "interleaved": sweep.interleave}
    finally:
        if owns:
            gl.release()
    return BenchReport(info, results)


def _time_group(group: list[tuple[int, str, str]], lit: LightSweep, shells: int, sweep: Sweep,
                size: tuple[int, int], gl: GLContext, timers: bool, clock: _SweepClock,
                report: Callable[[str], None]) -> list[BenchResult]:
    """The points of ``group`` timed together: each built and warmed up, then the rounds,
    the points in a shuffled order each round; every renderer released at the end."""
    order = random.Random(ROUND_ORDER_SEED)  # the same orders in every sweep
    timed: list[_TimedPoint] = []
    try:
        for lights, pipeline, path in group:
            report(f"warm-up: {pipeline} ({path}), {lights} lights, {shells} shells")
            start = time.perf_counter()
            renderer = Renderer(lit.at(lights), pipeline, size, gl=gl, light_path=path)
            timed.append(_TimedPoint(lights, pipeline, path, renderer,
                                     timer_queries(renderer) if timers else None))
            for _ in range(sweep.warmup):
                renderer.render(readback=False)
            clock.warmed_up(time.perf_counter() - start)
        for round_index in range(sweep.runs):
            for k in order.sample(range(len(timed)), len(timed)):
                point = timed[k]
                report(f"round {round_index + 1} of {sweep.runs}: {point.pipeline} "
                       f"({point.light_path}), {point.lights} lights, {shells} shells")
                start = time.perf_counter()
                point.time_round(sweep.round_ms)
                clock.ran((shells, point.lights, point.pipeline, point.light_path),
                          time.perf_counter() - start)
        return [point.result(shells) for point in timed]
    finally:
        for point in timed:
            point.renderer.release()
