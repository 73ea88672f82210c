"""Benchmarks: the same scene through each pipeline over a sweep of light and shell counts.

DESIGN.md, "Benchmarks". Every (pipeline, light path, lights, shells) point of a sweep gets its
own renderer on one shared GL context: ``warmup`` untimed frames (shaders compile there), then
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
on every object whose material has that parameter (``revie_fur``).

Every light path of each pipeline runs (``light_path``: ``volumes``, ``tiled``, ``clustered``
for deferred, ``naive`` and ``tiled`` (Forward+) for forward), unless ``--light-paths`` picks.
Besides wall-clock times, each row holds the framework's own CPU time per frame and per draw
call (the rendering thread's CPU time over ``render()``, less its time inside the drawing GL
calls, where llvmpipe does vertex work on the calling thread: :func:`time_cpu`), and per-pass GL
timer-query times where the driver answers them (``gpu_passes_ms``; llvmpipe does not).

JSON: ``{"renderer": {...}, "results": [{"pipeline", "light_path", "lights", "shells", "width",
"height", "runs", "median_ms", "mean_ms", "min_ms", "max_ms", "stddev_ms", "times_ms",
"passes_ms", "cpu_ms", "draw_calls", "cpu_us_per_draw", "gpu_passes_ms"}]}``. ``lights`` counts
the extra lights; ``renderer`` also records the G-buffer layout and bytes per pixel, the CPU
count and the scene. CSV: the same columns, the lists and mappings as JSON text.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import random
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import ValidationError

from deferred.errors import InputError
from deferred.gl.context import GLContext, create_context
from deferred.interfaces import registry
from deferred.interfaces.light import Light
from deferred.io.images import write_image, write_text
from deferred.io.paths import check_output_path
from deferred.names import LIGHT_PATHS, LightPath, Pipeline
from deferred.render.pipeline import PIPELINES
from deferred.scene.model import Scene, SceneObject

DEFAULT_LIGHTS = (1, 16, 64, 256, 1024)
DEFAULT_SHELLS = (0, 16, 64)
MAX_LIGHTS = 16384  # the GL 3.3 path keeps one light per row of a texture
LIGHT_SEED = 0
ROUND_ORDER_SEED = 0  # run_bench: the order of the points in each round
ROUND_FRAMES = 5  # the most frames a point renders back to back in a round (Sweep.round_ms)
# A light's radius is this share of the half-height of the view at its depth: on screen each
# sphere spans about 15% of the image height, in any scene at any scale.
LIGHT_VIEW_SHARE = 0.3
LIGHT_INTENSITY = 2.0
SHELLS = "shells"
MIN_SHELLS = "min_shells"
COLUMNS = ("pipeline", "light_path", "lights", "shells", "width", "height", "runs", "median_ms",
           "mean_ms", "min_ms", "max_ms", "stddev_ms", "times_ms", "passes_ms", "cpu_ms",
           "draw_calls", "cpu_us_per_draw", "gpu_passes_ms")
JSON_COLUMNS = ("times_ms", "passes_ms", "gpu_passes_ms")
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
    """An output file named by ``where`` (``--json``...) with that option's suffix."""
    return check_output_path(path, where, (OUTPUT_SUFFIXES[where],), patterns=False)


# -- scene variants ------------------------------------------------------------------------------

def world_bounds(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned world bounds of every object (the camera target +-1 in an empty scene)."""
    if not scene.objects:
        target = np.asarray(scene.camera.target, dtype=np.float64)
        return target - 1.0, target + 1.0
    corners = []
    for obj in scene.objects:
        low, high = obj.mesh.bounds()
        box = np.array([[x, y, z, 1.0] for x in (low[0], high[0]) for y in (low[1], high[1])
                        for z in (low[2], high[2])])
        corners.append((box @ obj.model.T)[:, :3])
    points = np.concatenate(corners)
    return points.min(axis=0), points.max(axis=0)


def extra_point_lights(scene: Scene, count: int, aspect: float,
                       seed: int = LIGHT_SEED) -> list[Light]:
    """``count`` point lights around and above the objects, centres on screen.

    Candidates come from one seeded stream in fixed batches, so the lights of a smaller count are
    a prefix of a larger count's. Where the camera sees too little of the bounds, the remaining
    lights are taken off screen rather than not at all.
    """
    if count == 0:
        return []
    low, high = world_bounds(scene)
    # "Above": a quarter of the objects' height over them (a tenth of their width when flat),
    # not more, or lights would float clear of every surface.
    height = max(float(high[1] - low[1]), 0.1 * float(np.max(high - low)), 1e-3)
    high = high + np.array([0.0, 0.25 * height, 0.0])
    camera = scene.camera
    view = camera.view()
    projection = camera.projection(aspect)
    half_height = math.tan(math.radians(camera.fov) / 2.0)
    rng = np.random.default_rng(seed)
    accepted: list[tuple[np.ndarray, float]] = []
    rejected: list[tuple[np.ndarray, float]] = []
    for _ in range(64):
        points = rng.uniform(low, high, size=(256, 3))
        homogeneous = np.c_[points, np.ones(len(points))]
        eye = homogeneous @ view.T
        clip = eye @ projection.T
        depth = -eye[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            ndc = clip[:, :2] / clip[:, 3:4]
        visible = (depth > camera.near) & np.all(np.abs(ndc) <= 1.0, axis=1)
        for point, distance, seen in zip(points, depth, visible, strict=True):
            radius = LIGHT_VIEW_SHARE * half_height * max(abs(float(distance)), camera.near)
            (accepted if seen else rejected).append((point, radius))
        if len(accepted) >= count:
            break
    chosen = (accepted + rejected)[:count]
    colors = np.random.default_rng(seed + 1).uniform(0.25, 1.0, size=(count, 3))
    point_light = registry.lights.get("point")
    return [point_light.from_dict({"position": tuple(float(v) for v in point),
                                   "radius": radius,
                                   "color": tuple(float(v) for v in color),
                                   "intensity": LIGHT_INTENSITY})
            for (point, radius), color in zip(chosen, colors, strict=True)]


def with_extra_lights(scene: Scene, count: int, aspect: float, seed: int = LIGHT_SEED) -> Scene:
    """A copy of ``scene`` with ``count`` more point lights (the scene itself is unchanged)."""
    return replace(scene, lights=[*scene.lights, *extra_point_lights(scene, count, aspect, seed)])


def has_shells(obj: SceneObject) -> bool:
    return SHELLS in type(obj.material.params).model_fields


def shell_objects(scene: Scene) -> list[SceneObject]:
    """Objects whose material has a ``shells`` parameter."""
    return [obj for obj in scene.objects if has_shells(obj)]


def with_shells(scene: Scene, shells: int, where: str = "--shells") -> Scene:
    """A copy of ``scene`` with ``shells`` on every object whose material has that parameter,
    drawn whatever the distance (``min_shells`` too, where the material has it)."""
    objects = []
    for obj in scene.objects:
        if has_shells(obj):
            material = obj.material
            params = material.params
            try:
                # Validated, not model_copy(update=...): each material's range applies.
                # The sweep fixes the count: a level of detail's minimum (if any) goes with it.
                overrides = {SHELLS: shells}
                if MIN_SHELLS in type(params).model_fields and shells > 0:
                    overrides[MIN_SHELLS] = shells
                new_params = type(params).model_validate({**params.model_dump(), **overrides})
            except ValidationError as exc:
                problem = exc.errors()[0]["msg"]
                raise InputError(f"{problem} for {obj.label} ({material.name}), got {shells}",
                                 where) from None
            # the count holds at every time of the object's timeline, if it has one
            obj = obj.with_material(type(material)(new_params, material.base_dir), overrides)
        objects.append(obj)
    return replace(scene, objects=objects)


# -- timing --------------------------------------------------------------------------------------

def time_frame(renderer) -> float:
    """Milliseconds of one frame: the wall clock around ``render()`` and ``ctx.finish()``, the
    GL queue drained before it starts."""
    ctx = renderer.gl.ctx
    ctx.finish()
    start = time.perf_counter()
    renderer.render(readback=False)
    ctx.finish()
    return (time.perf_counter() - start) * 1000.0


def cpu_frame(renderer) -> tuple[float, int]:
    """Milliseconds of the framework's own CPU work in one frame, and the frame's draw calls:
    the rendering thread's CPU time (``time.thread_time``: waits for the driver and the
    rasteriser's worker threads are not in it) over ``render()``, less its CPU time inside the
    drawing GL calls (draws, dispatches, clears, framebuffer binds, the light lists' copy;
    ``FrameStats.gl_call_seconds``), where llvmpipe runs vertex work and binning on the
    calling thread."""
    renderer.gl.ctx.finish()
    start = time.thread_time()
    result = renderer.render(readback=False, time_gl_calls=True)
    elapsed = time.thread_time() - start
    renderer.gl.ctx.finish()
    return (elapsed - result.gl_call_seconds) * 1000.0, result.draw_calls


def time_cpu(renderer, runs: int) -> tuple[float, int]:
    """Median milliseconds per frame of the framework's own CPU work over ``runs`` frames
    (:func:`cpu_frame`), and the draw calls of a frame."""
    samples = [cpu_frame(renderer) for _ in range(runs)]
    return statistics.median(ms for ms, _ in samples), samples[-1][1]


def timer_queries_work(gl: GLContext) -> bool:
    """Whether the driver answers GL timer queries (Mesa 22.3's llvmpipe does)."""
    ctx = gl.ctx
    query = ctx.query(time=True)
    fbo = ctx.simple_framebuffer((64, 64))
    with query:
        for _ in range(8):
            fbo.clear(0.5, 0.5, 0.5, 1.0)
    ctx.finish()
    elapsed = query.elapsed
    fbo.release()
    return elapsed > 0


def timer_queries(renderer) -> dict[str, Any]:
    """A GL time query per pass of ``renderer``, made once for all its frames (moderngl 5
    cannot release a query)."""
    return {p.name: renderer.gl.ctx.query(time=True) for p in renderer.passes}


def gpu_frame(renderer, queries: dict[str, Any]) -> dict[str, float]:
    """GL timer-query milliseconds of each pass of one frame (drivers that answer them)."""

    def before(render_pass, frame) -> None:
        queries[render_pass.name].__enter__()

    def after(render_pass, frame) -> None:
        queries[render_pass.name].__exit__(None, None, None)

    renderer.render(before_pass=before, on_pass=after, readback=False)
    renderer.gl.ctx.finish()
    return {name: query.elapsed / 1e6 for name, query in queries.items()}


def pass_frame(renderer) -> dict[str, list[float]]:
    """Milliseconds of each pass of one frame, in pass order, by wall clock.

    ``finish()`` before and after every pass: without the fence a pass's work would be billed to
    whichever later pass waited for it. (Timer queries, where a driver answers them, are
    :func:`gpu_frame`'s.)
    """
    ctx = renderer.gl.ctx
    samples: dict[str, list[float]] = {p.name: [] for p in renderer.passes}
    started: dict[str, float] = {}

    def before(render_pass, frame) -> None:
        ctx.finish()
        started[render_pass.name] = time.perf_counter()

    def after(render_pass, frame) -> None:
        ctx.finish()
        samples[render_pass.name].append((time.perf_counter() - started[render_pass.name]) * 1e3)

    renderer.render(before_pass=before, on_pass=after, readback=False)
    return samples


def time_passes(renderer, runs: int) -> dict[str, float]:
    """Median milliseconds of each pass, in pass order, over ``runs`` frames
    (:func:`pass_frame`)."""
    samples: dict[str, list[float]] = {p.name: [] for p in renderer.passes}
    for _ in range(runs):
        for name, values in pass_frame(renderer).items():
            samples[name] += values
    return medians(samples)


def medians(samples: dict[str, list[float]]) -> dict[str, float]:
    return {name: statistics.median(values) for name, values in samples.items() if values}


# -- results -------------------------------------------------------------------------------------

@dataclass
class BenchResult:
    """One (pipeline, light path, lights, shells) point of a sweep; times in milliseconds."""

    pipeline: str
    lights: int
    shells: int
    width: int
    height: int
    times_ms: list[float]
    passes_ms: dict[str, float] = field(default_factory=dict)
    light_path: str = ""
    cpu_ms: float = 0.0
    draw_calls: int = 0
    gpu_passes_ms: dict[str, float] | None = None

    @property
    def cpu_us_per_draw(self) -> float:
        return 1000.0 * self.cpu_ms / max(self.draw_calls, 1)

    @property
    def runs(self) -> int:
        return len(self.times_ms)

    @property
    def median_ms(self) -> float:
        return statistics.median(self.times_ms)

    @property
    def mean_ms(self) -> float:
        return statistics.fmean(self.times_ms)

    @property
    def min_ms(self) -> float:
        return min(self.times_ms)

    @property
    def max_ms(self) -> float:
        return max(self.times_ms)

    @property
    def stddev_ms(self) -> float:
        return statistics.stdev(self.times_ms) if self.runs > 1 else 0.0

    def to_dict(self) -> dict[str, Any]:
        return {"pipeline": self.pipeline, "light_path": self.light_path, "lights": self.lights,
                "shells": self.shells, "width": self.width, "height": self.height,
                "runs": self.runs, "median_ms": self.median_ms, "mean_ms": self.mean_ms,
                "min_ms": self.min_ms, "max_ms": self.max_ms, "stddev_ms": self.stddev_ms,
                "times_ms": list(self.times_ms), "passes_ms": dict(self.passes_ms),
                "cpu_ms": self.cpu_ms, "draw_calls": self.draw_calls,
                "cpu_us_per_draw": self.cpu_us_per_draw, "gpu_passes_ms": self.gpu_passes_ms}


@dataclass
class BenchReport:
    renderer: dict[str, Any]
    results: list[BenchResult]

    def to_dict(self) -> dict[str, Any]:
        return {"renderer": self.renderer, "results": [r.to_dict() for r in self.results]}

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2) + "\n"

    def to_csv(self) -> str:
        out = io.StringIO()
        writer = csv.DictWriter(out, COLUMNS, lineterminator="\n")
        writer.writeheader()
        for result in self.results:
            row = result.to_dict()
            for column in JSON_COLUMNS:
                row[column] = json.dumps(row[column])
            writer.writerow(row)
        return out.getvalue()


@dataclass(frozen=True)
class Sweep:
    lights: Sequence[int] = DEFAULT_LIGHTS
    shells: Sequence[int] = DEFAULT_SHELLS
    pipelines: Sequence[str] = ("deferred", "forward")
    light_paths: Sequence[str] | None = None  # None: every path of each pipeline
    size: tuple[int, int] | None = None  # None: the scene's size
    runs: int = 10
    warmup: int = 2
    interleave: bool = True  # the points of a shell count timed together (run_bench)
    # a point's timed frames in a round: back to back until they make this (ROUND_FRAMES at
    # most, the first dropped where there are more); 0: one a round
    round_ms: float = 100.0


def sweep_shells(scene: Scene, shells: Sequence[int]) -> list[int]:
    """The shell counts a sweep really runs: one value (0) when no object has shells."""
    return list(shells) if shell_objects(scene) else [0]


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

    def time_round(self, round_ms: float) -> None:
        """Timed frames back to back until they make ``round_ms`` (at most ROUND_FRAMES; the
        first dropped where there are more, since it pays for the frame of another point just
        before it), one frame with every pass fenced, one of CPU time, and one with timer
        queries where the driver answers them."""
        frames = [time_frame(self.renderer)]
        while len(frames) < ROUND_FRAMES and sum(frames) < round_ms:
            frames.append(time_frame(self.renderer))
        self.times_ms += frames[1:] if len(frames) > 1 else frames
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
                           medians(self.gpu_ms) if self.queries is not None else None)


def sweep_points(sweep: Sweep) -> list[tuple[int, str, str]]:
    """The (lights, pipeline, light path) points of one shell count, in the report's order."""
    return [(lights, pipeline, path) for lights in sweep.lights for pipeline in sweep.pipelines
            for path in pipeline_paths(pipeline, sweep.light_paths)]


def sweep_steps(scene: Scene, sweep: Sweep) -> int:
    """How many times :func:`run_bench` calls ``progress``: a warm-up per point, a round of
    frames per group of points timed together."""
    points = len(sweep_points(sweep))
    groups = 1 if sweep.interleave else points
    return len(sweep_shells(scene, sweep.shells)) * (points + groups * sweep.runs)


def run_bench(scene: Scene, sweep: Sweep, gl: GLContext | None = None,
              progress: Callable[[str], None] | None = None) -> BenchReport:
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
    each at 1280x720 on lights.toml). Without it, one point is built, timed and released
    after another. ``progress(description)`` is called before each warm-up and each round.
    """
    from deferred.render.renderer import Renderer

    if sweep.runs < 1:
        raise InputError(f"runs must be 1 or more, got {sweep.runs}", "--runs")
    if sweep.warmup < 0:
        raise InputError(f"warmup must be 0 or more, got {sweep.warmup}", "--warmup")
    if max(sweep.lights, default=0) + len(scene.lights) > MAX_LIGHTS:
        raise InputError(f"at most {MAX_LIGHTS} lights in all, the scene has "
                         f"{len(scene.lights)}", "--lights")
    points = sweep_points(sweep)
    if not points:
        raise InputError("no light path of the pipelines chosen is in --light-paths",
                         "--light-paths")
    size = sweep.size or scene.size
    aspect = size[0] / size[1]
    report = progress or (lambda description: None)
    owns = gl is None
    gl = gl or create_context()
    results = []
    try:
        timers = timer_queries_work(gl)
        for shells in sweep_shells(scene, sweep.shells):
            shelled = with_shells(scene, shells) if shell_objects(scene) else scene
            lit = {lights: with_extra_lights(shelled, lights, aspect) for lights in sweep.lights}
            groups = [points] if sweep.interleave else [[point] for point in points]
            for group in groups:
                order = random.Random(ROUND_ORDER_SEED)  # the same orders in every sweep
                timed: list[_TimedPoint] = []
                try:
                    for lights, pipeline, path in group:
                        report(f"warm-up: {pipeline} ({path}), {lights} lights, {shells} shells")
                        renderer = Renderer(lit[lights], pipeline, size, gl=gl, light_path=path)
                        timed.append(_TimedPoint(lights, pipeline, path, renderer,
                                                 timer_queries(renderer) if timers else None))
                        for _ in range(sweep.warmup):
                            renderer.render(readback=False)
                    for round_index in range(sweep.runs):
                        what = (f"{len(timed)} points" if len(timed) > 1 else
                                f"{timed[0].pipeline} ({timed[0].light_path}), "
                                f"{timed[0].lights} lights")
                        report(f"round {round_index + 1} of {sweep.runs}: {what}, "
                               f"{shells} shells")
                        for k in order.sample(range(len(timed)), len(timed)):
                            timed[k].time_round(sweep.round_ms)
                    results += [point.result(shells) for point in timed]
                finally:
                    for point in timed:
                        point.renderer.release()
        info = {**renderer_info(gl, scene), "gl_timer_queries": timers,
                "interleaved": sweep.interleave}
    finally:
        if owns:
            gl.release()
    return BenchReport(info, results)


def renderer_info(gl: GLContext, scene: Scene) -> dict[str, Any]:
    """What the numbers were measured on: GL driver, features, G-buffer size, CPUs, scene."""
    layout = scene.gbuffer_layout()
    return {**gl.info, **gl.features.names(), "gbuffer_bytes_per_pixel": layout.bytes_per_pixel,
            "gbuffer_layout": layout.describe(),
            "cpus": os.cpu_count(), "scene": scene.source,
            "scene_lights": len(scene.lights)}


# -- outputs -------------------------------------------------------------------------------------

def write_json(report: BenchReport, path: str | Path) -> Path:
    return write_text(path, report.to_json())


def write_csv(report: BenchReport, path: str | Path) -> Path:
    return write_text(path, report.to_csv())


def plot_image(report: BenchReport, title: str | None = None) -> np.ndarray:
    """The plot as RGBA pixels: median ms (min..max shaded) against extra lights, one line per
    pipeline, one panel per shell count."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import NullLocator, ScalarFormatter

    shells = sorted({r.shells for r in report.results})
    series = list(dict.fromkeys((r.pipeline, r.light_path) for r in report.results))
    figure = Figure(figsize=(4.2 * len(shells) + 0.6, 3.8), dpi=100, layout="constrained")
    FigureCanvasAgg(figure)  # Agg without pyplot: no global backend state, no display needed
    # Shared log y: times span decades, and panels compare at a glance.
    axes = figure.subplots(1, len(shells), squeeze=False, sharey=True)[0]
    for ax, count in zip(axes, shells, strict=True):
        for pipeline, path in series:
            rows = sorted((r for r in report.results if r.shells == count and
                           (r.pipeline, r.light_path) == (pipeline, path)),
                          key=lambda r: r.lights)
            x = [r.lights for r in rows]
            label = f"{pipeline} ({path})" if path else pipeline
            line, = ax.plot(x, [r.median_ms for r in rows], marker="o", label=label)
            ax.fill_between(x, [r.min_ms for r in rows], [r.max_ms for r in rows],
                            color=line.get_color(), alpha=0.2, linewidth=0)
        ax.set_xscale("symlog", linthresh=1)  # light counts span decades and may include 0
        counts = sorted({r.lights for r in report.results})
        ax.set_xticks(counts, [str(c) for c in counts])
        ax.xaxis.set_minor_locator(NullLocator())
        ax.set_xlabel(f"extra point lights (+{report.renderer.get('scene_lights', 0)} "
                      "in the scene)")
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(ScalarFormatter())
        ax.set_ylabel("frame ms (median, min..max shaded)")
        ax.set_title(f"{count} shells" if len(shells) > 1 or count else "")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    if title:
        figure.suptitle(title, fontsize=9)
    figure.canvas.draw()
    return np.asarray(figure.canvas.buffer_rgba()).copy()


def write_plot(report: BenchReport, path: str | Path, title: str | None = None) -> Path:
    return write_image(path, plot_image(report, title or plot_title(report)))


def plot_title(report: BenchReport) -> str:
    first = report.results[0]
    return (f"{report.renderer.get('scene', '')}, {first.width}x{first.height}, "
            f"{first.runs} runs, {report.renderer.get('renderer', '')}")


def results_table(report: BenchReport):
    """A rich table of the results (stderr in the CLI), the slowest pass of each row last."""
    from rich.table import Table

    table = Table(title=plot_title(report), title_justify="left")
    for column in ("pipeline", "path", "lights", "shells", "median ms", "min ms", "max ms",
                   "stddev", "cpu ms", "us/draw", "slowest pass"):
        table.add_column(column, no_wrap=True, justify="left" if column in (
            "pipeline", "path", "slowest pass") else "right")
    for r in report.results:
        slowest = max(r.passes_ms.items(), key=lambda item: item[1], default=None)
        table.add_row(r.pipeline, r.light_path, str(r.lights), str(r.shells),
                      f"{r.median_ms:.2f}", f"{r.min_ms:.2f}", f"{r.max_ms:.2f}",
                      f"{r.stddev_ms:.2f}", f"{r.cpu_ms:.2f}", f"{r.cpu_us_per_draw:.1f}",
                      f"{slowest[0]} {slowest[1]:.2f} ms" if slowest else "")
    return table


def _fastest(rows: list[BenchResult], pipeline: str, lights: int,
             paths: Sequence[str] | None = None) -> BenchResult | None:
    found = [r for r in rows if r.pipeline == pipeline and r.lights == lights and
             (paths is None or r.light_path in paths)]
    return min(found, key=lambda r: r.median_ms, default=None)


def crossovers(report: BenchReport) -> list[str]:
    """Per shell count: the fewest extra lights from which the fastest deferred path beats
    naive forward (and every forward path), as lines to print."""
    lines = []
    for shells in sorted({r.shells for r in report.results}):
        rows = [r for r in report.results if r.shells == shells]
        counts = sorted({r.lights for r in rows})

        for against, paths in (("naive forward", ("naive",)), ("every forward path", None)):
            crossing = None
            for lights in counts:
                deferred = _fastest(rows, "deferred", lights)
                forward = _fastest(rows, "forward", lights, paths)
                if deferred is None or forward is None:
                    continue
                if deferred.median_ms < forward.median_ms:
                    crossing = crossing if crossing is not None else (lights, deferred)
                else:
                    crossing = None
            if crossing is None:
                lines.append(f"{shells} shells: deferred never beats {against} from some "
                             "light count on")
            else:
                lights, deferred = crossing
                lines.append(f"{shells} shells: deferred ({deferred.light_path}) beats "
                             f"{against} from {lights} extra lights on")
    return lines


def speedups(report: BenchReport) -> list[str]:
    """Per shell count, at the most extra lights swept: the fastest deferred path's median
    against naive forward's and the fastest forward path's, as lines to print."""
    lines = []
    for shells in sorted({r.shells for r in report.results}):
        rows = [r for r in report.results if r.shells == shells]
        lights = max(r.lights for r in rows)
        deferred = _fastest(rows, "deferred", lights)
        naive = _fastest(rows, "forward", lights, ("naive",))
        forward = _fastest(rows, "forward", lights)
        if deferred is None or forward is None:
            continue
        parts = []
        if naive is not None:
            parts.append(f"{naive.median_ms / deferred.median_ms:.1f}x naive forward "
                         f"({naive.median_ms:.1f} ms)")
        parts.append(f"{forward.median_ms / deferred.median_ms:.2f}x the fastest forward path "
                     f"({forward.light_path}, {forward.median_ms:.1f} ms)")
        lines.append(f"{shells} shells, {lights} extra lights: deferred ({deferred.light_path}) "
                     f"{deferred.median_ms:.1f} ms: {', '.join(parts)}")
    return lines


def growth(report: BenchReport) -> list[str]:
    """Per shell count, for the deferred path fastest at the most extra lights swept: its median
    at each light count against its own at the fewest, as lines to print (interleaved, the
    frames of a line's counts were timed in the same rounds)."""
    lines = []
    for shells in sorted({r.shells for r in report.results}):
        rows = [r for r in report.results if r.shells == shells]
        best = _fastest(rows, "deferred", max(r.lights for r in rows))
        if best is None:
            continue
        own = sorted((r for r in rows if r.pipeline == "deferred" and
                      r.light_path == best.light_path), key=lambda r: r.lights)
        if len(own) < 2:
            continue
        first = own[0]
        ratios = ", ".join(f"{r.lights}: {r.median_ms / first.median_ms:.2f}x" for r in own[1:])
        lines.append(f"{shells} shells, deferred ({best.light_path}) against its frame at "
                     f"{first.lights} extra lights ({first.median_ms:.1f} ms): {ratios}")
    return lines
