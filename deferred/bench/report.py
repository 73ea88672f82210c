"""The bench's results and what it writes of them: rows, JSON, CSV, a plot, the table on the
terminal and the lines comparing the pipelines."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import statistics
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from deferred.gl.context import GLContext
from deferred.io.images import write_image, write_text
from deferred.names import LightPath, Pipeline
from deferred.scene.scene import Scene

COLUMNS = ("pipeline", "light_path", "lights", "shells", "width", "height", "runs", "frames",
           "median_ms",
           "mean_ms", "min_ms", "max_ms", "stddev_ms", "times_ms", "passes_ms", "cpu_ms",
           "draw_calls", "cpu_us_per_draw", "gpu_passes_ms")
JSON_COLUMNS = ("times_ms", "passes_ms", "gpu_passes_ms")


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
    rounds: int = 0  # the sweep's runs (each a round of frames); 0: one a timed frame

    @property
    def cpu_us_per_draw(self) -> float:
        return 1000.0 * self.cpu_ms / max(self.draw_calls, 1)

    @property
    def runs(self) -> int:
        """The runs asked for (``--runs``), each a round of one to ``ROUND_FRAMES`` frames."""
        return self.rounds or len(self.times_ms)

    @property
    def frames(self) -> int:
        """The frames timed over all runs (``times_ms``)."""
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
                "runs": self.runs, "frames": self.frames, "median_ms": self.median_ms,
                "mean_ms": self.mean_ms,
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



def renderer_info(gl: GLContext, scene: Scene) -> dict[str, Any]:
    """What the numbers were measured on: GL driver, features, G-buffer size, CPUs, scene."""
    layout = scene.gbuffer_layout()
    return {**gl.info, **gl.features.names(), "gbuffer_bytes_per_pixel": layout.bytes_per_pixel,
            "gbuffer_layout": layout.describe(),
            "cpus": os.cpu_count(), "scene": scene.source,
            "scene_lights": len(scene.lights)}



def write_json(report: BenchReport, path: str | Path) -> Path:
    return write_text(path, report.to_json())


def write_csv(report: BenchReport, path: str | Path) -> Path:
    return write_text(path, report.to_csv())


def plot_image(report: BenchReport, title: str | None = None) -> np.ndarray:
    """The plot as RGBA pixels: median ms (min..max shaded) against extra lights, one line per
    pipeline, one panel per shell count (matplotlib: the ``plot`` extra)."""
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
    """``demo.toml, 64x48, 2 runs (3-8 frames timed a point), llvmpipe``: the runs asked for,
    and the frames they timed (a run times a point's frames back to back for ``round_ms``)."""
    first = report.results[0]
    frames = sorted({r.frames for r in report.results})
    counted = f"{frames[0]}" if len(frames) == 1 else f"{frames[0]}-{frames[-1]}"
    runs = f"{first.runs} run{'s' if first.runs != 1 else ''}"
    return (f"{report.renderer.get('scene', '')}, {first.width}x{first.height}, "
            f"{runs} ({counted} frames timed a point), {report.renderer.get('renderer', '')}")


def results_table(report: BenchReport):
    """A rich table of the results (stdout in the CLI), the slowest pass of each row last."""
    from rich.table import Table

    table = Table(title=plot_title(report), title_justify="left")
    sized = len({(r.width, r.height) for r in report.results}) > 1  # a --sweep of sizes
    for column in ("pipeline", "path", *(("size",) if sized else ()), "lights", "shells",
                   "median ms", "min ms", "max ms", "stddev", "cpu ms", "us/draw",
                   "slowest pass"):
        table.add_column(column, no_wrap=True, justify="left" if column in (
            "pipeline", "path", "size", "slowest pass") else "right")
    for r in report.results:
        slowest = max(r.passes_ms.items(), key=lambda item: item[1], default=None)
        table.add_row(r.pipeline, r.light_path, *((f"{r.width}x{r.height}",) if sized else ()),
                      str(r.lights), str(r.shells),
                      f"{r.median_ms:.2f}", f"{r.min_ms:.2f}", f"{r.max_ms:.2f}",
                      f"{r.stddev_ms:.2f}", f"{r.cpu_ms:.2f}", f"{r.cpu_us_per_draw:.1f}",
                      f"{slowest[0]} {slowest[1]:.2f} ms" if slowest else "")
    return table


def _fastest(rows: list[BenchResult], pipeline: str, lights: int,
             paths: Sequence[str] | None = None) -> BenchResult | None:
    found = [r for r in rows if r.pipeline == pipeline and r.lights == lights and
             (paths is None or r.light_path in paths)]
    return min(found, key=lambda r: r.median_ms, default=None)


def spread_ms(a: BenchResult, b: BenchResult) -> float:
    """The noise of the difference of two points' medians: their frames' standard deviations
    combined (the root of the sum of their squares)."""
    return math.hypot(a.stddev_ms, b.stddev_ms)


def tied(a: BenchResult, b: BenchResult) -> bool:
    """Whether the difference of the two medians is within :func:`spread_ms`: no winner."""
    return abs(a.median_ms - b.median_ms) <= spread_ms(a, b)


def _ms(r: BenchResult) -> str:
    """``12.3 ms``, or ``12.3 ± 4.5 ms`` where the frames varied (their standard deviation)."""
    return f"{r.median_ms:.1f} ms" if r.stddev_ms == 0.0 else \
        f"{r.median_ms:.1f} ± {r.stddev_ms:.1f} ms"


def _tie(a: BenchResult, b: BenchResult) -> str:
    return (f"the difference, {abs(a.median_ms - b.median_ms):.1f} ms, is within the spread, "
            f"{spread_ms(a, b):.1f} ms")


def noise(report: BenchReport) -> list[str]:
    """The sweep's noise as a line to print: the smallest and largest standard deviation of a
    point's frames, absolute and against its median; the rule that calls a difference a tie."""
    varied = [r for r in report.results if r.frames > 1]
    if not varied:
        return ["noise: one frame a point, no spread measured (more --runs measure it); "
                "every difference is taken as it is"]
    deviations = [r.stddev_ms for r in varied]
    shares = [100.0 * r.stddev_ms / r.median_ms for r in varied if r.median_ms > 0.0]
    share = f" ({min(shares):.0f}-{max(shares):.0f}% of its median)" if shares else ""
    return [f"noise: a point's frames vary by {min(deviations):.2f}-{max(deviations):.2f} ms "
            f"(standard deviation){share}; a difference within two points' combined spread is "
            "a tie"]


def crossovers(report: BenchReport) -> list[str]:
    """Per shell count: the fewest extra lights from which the fastest deferred path beats
    naive forward (and every forward path), as lines to print. A difference within the
    spread (:func:`tied`) beats nothing: the light counts where it is are named, with the
    numbers."""
    lines = []
    for shells in sorted({r.shells for r in report.results}):
        rows = [r for r in report.results if r.shells == shells]
        counts = sorted({r.lights for r in rows})

        for against, paths in (("naive forward", (LightPath.NAIVE,)), ("every forward path", None)):
            crossing = None
            ties = []
            for lights in counts:
                deferred = _fastest(rows, Pipeline.DEFERRED, lights)
                forward = _fastest(rows, Pipeline.FORWARD, lights, paths)
                if deferred is None or forward is None:
                    continue
                if tied(deferred, forward):
                    ties.append(f"{lights} ({_ms(deferred)} against {_ms(forward)})")
                    crossing = None
                elif deferred.median_ms < forward.median_ms:
                    crossing = crossing if crossing is not None else (lights, deferred)
                else:
                    crossing = None
            if crossing is None:
                line = (f"{shells} shells: deferred never beats {against} from some "
                        "light count on")
            else:
                lights, deferred = crossing
                line = (f"{shells} shells: deferred ({deferred.light_path}) beats "
                        f"{against} from {lights} extra lights on")
            if ties:
                line += f"; a tie within the noise at {', '.join(ties)} extra lights"
            lines.append(line)
    return lines


def _against(deferred: BenchResult, other: BenchResult, what: str, digits: int,
             path: str = "") -> str:
    said = f"{path}, {_ms(other)}" if path else _ms(other)
    if tied(deferred, other):
        return f"a tie with {what} ({said}: {_tie(deferred, other)})"
    return f"{other.median_ms / deferred.median_ms:.{digits}f}x {what} ({said})"


def speedups(report: BenchReport) -> list[str]:
    """Per shell count, at the most extra lights swept: the fastest deferred path's median
    against naive forward's and the fastest forward path's, as lines to print (a tie where
    the difference is within the spread)."""
    lines = []
    for shells in sorted({r.shells for r in report.results}):
        rows = [r for r in report.results if r.shells == shells]
        lights = max(r.lights for r in rows)
        deferred = _fastest(rows, Pipeline.DEFERRED, lights)
        naive = _fastest(rows, Pipeline.FORWARD, lights, (LightPath.NAIVE,))
        forward = _fastest(rows, Pipeline.FORWARD, lights)
        if deferred is None or forward is None:
            continue
        parts = []
        if naive is not None:
            parts.append(_against(deferred, naive, "naive forward", 1))
        parts.append(_against(deferred, forward, "the fastest forward path", 2,
                              forward.light_path))
        lines.append(f"{shells} shells, {lights} extra lights: deferred ({deferred.light_path}) "
                     f"{_ms(deferred)}: {', '.join(parts)}")
    return lines


def growth(report: BenchReport) -> list[str]:
    """Per shell count, for the deferred path fastest at the most extra lights swept: its median
    at each light count against its own at the fewest, as lines to print (interleaved, the
    frames of a line's counts were timed in the same rounds; a tie where the difference is
    within the spread)."""
    lines = []
    for shells in sorted({r.shells for r in report.results}):
        rows = [r for r in report.results if r.shells == shells]
        best = _fastest(rows, Pipeline.DEFERRED, max(r.lights for r in rows))
        if best is None:
            continue
        own = sorted((r for r in rows if r.pipeline == Pipeline.DEFERRED and
                      r.light_path == best.light_path), key=lambda r: r.lights)
        if len(own) < 2:
            continue
        first = own[0]
        ratios = ", ".join(f"{r.lights}: {r.median_ms / first.median_ms:.2f}x"
                           f"{' (a tie within the noise)' if tied(r, first) else ''}"
                           for r in own[1:])
        lines.append(f"{shells} shells, deferred ({best.light_path}) against its frame at "
                     f"{first.lights} extra lights ({_ms(first)}): {ratios}")
    return lines
