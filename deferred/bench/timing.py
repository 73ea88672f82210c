"""How the bench times a frame: wall clock around ``render()`` and ``ctx.finish()``, each pass
the same way, the framework's own CPU time (the thread's CPU time less its time inside the
drawing GL calls), and GL timer queries where the driver answers them."""

from __future__ import annotations

import statistics
import time
from typing import Any

from deferred.gl.context import GLContext


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


def interleaved_rounds(renderers: list, rounds: int
                       ) -> tuple[list[list[float]], list[dict[str, list[float]]]]:
    """Frame times (ms, wall clock around ``ctx.finish()``) and per-pass times of each of
    ``renderers`` (variants on one context) over ``rounds``; each round starts from the next
    variant, so none always runs first after the others (A/B comparisons)."""
    frames: list[list[float]] = [[] for _ in renderers]
    passes: list[dict[str, list[float]]] = [{} for _ in renderers]
    order = list(zip(renderers, frames, passes, strict=True))
    for round_index in range(rounds):
        shift = round_index % len(order)
        for renderer, times, by_pass in order[shift:] + order[:shift]:
            ctx = renderer.gl.ctx
            ctx.finish()
            start = time.perf_counter()
            renderer.render(readback=False)
            ctx.finish()
            times.append((time.perf_counter() - start) * 1000.0)
            for name, ms in time_passes(renderer, 1).items():
                by_pass.setdefault(name, []).append(ms)
    return frames, passes
