"""The framework's CPU time per draw call: the marginal cost of one more object's draw.

The bench's ``cpu_ms`` is the rendering thread's CPU time over ``render()`` less its time
inside the GL calls that draw (``deferred.bench.timing.time_cpu``); ``cpu_us_per_draw`` divides that
by the frame's draws, so on a scene of few objects it is mostly the frame's fixed work (the
light records, the camera, one-draw passes) spread over them. This script separates the two:
it renders scenes of N standard-material cubes (N = 25, 100, 400 by default, every cube its own
colour, so every draw writes its material uniforms), and fits the CPU time per frame against
the draws: the slope is the CPU time per draw call, the intercept the frame's fixed work. The
frames are small (160x90 by default): the GL work is not what is measured. Run from the
repository root:

    python benchmarks/draw_overhead.py [N,N,...] [--size WxH] [--runs R] [--trials T]
                                       [--moving]
"""

from __future__ import annotations

import argparse
import statistics
import timeit
from dataclasses import replace

import numpy as np

from deferred.bench.timing import cpu_frame, time_cpu
from deferred.gl.context import create_context
from deferred.lights.ambient import AmbientLight
from deferred.lights.directional import DirectionalLight
from deferred.render.renderer import Renderer
from deferred.scene.camera import Camera
from deferred.scene.meshes import load_mesh
from deferred.scene.scene import Scene

PATHS = {"deferred": ("tiled", "clustered", "volumes"), "forward": ("naive", "tiled")}


def cube_grid(count: int) -> Scene:
    """``count`` cubes on a square grid in front of the camera, each its own colour."""
    side = int(np.ceil(np.sqrt(count)))
    scene = Scene(camera=Camera(position=(0.0, 0.0, 1.6 * side), target=(0.0, 0.0, 0.0)),
                  source=f"{count} cubes")
    scene.lights = [AmbientLight.from_dict({}), DirectionalLight.from_dict({})]
    mesh = load_mesh("builtin:cube")
    rng = np.random.default_rng(7)
    for index in range(count):
        row, column = divmod(index, side)
        position = (column - (side - 1) / 2, row - (side - 1) / 2, 0.0)
        scene.add(mesh, "standard", position=position, scale=0.35,
                  params={"color": [float(c) for c in rng.uniform(0.2, 0.9, 3)]})
    return scene


def python_loop_ms() -> float:
    """The machine's speed at running Python: the best of 5 runs of ``sum(range(10000))``
    2000 times, in ms (about 300 on this machine when it is calm, up to 450 when it is not:
    the per-draw figures move with it)."""
    return 1000.0 * min(timeit.repeat("sum(range(10000))", number=2000, repeat=5))


def moving_frames(renderer: Renderer, runs: int) -> tuple[float, int]:
    """:func:`time_cpu` with the camera moved before each frame (outside the timing): the
    view changes each frame (before the view was split from the model, every object's
    transforms were made again with it)."""
    samples = []
    for index in range(runs):
        camera = renderer.scene.camera
        x, y, z = camera.position
        renderer.scene.camera = replace(camera, position=(x + 0.01 * (-1) ** index, y, z))
        samples.append(cpu_frame(renderer))
    return statistics.median(ms for ms, _ in samples), samples[-1][1]


def measure(counts: list[int], size: tuple[int, int], runs: int, trials: int,
            moving: bool = False) -> None:
    """Per light path of each pipeline: the CPU time per frame at each count (median over the
    trials), and the slope of a line through them per trial: median and range over trials.
    The counts' renderers are kept side by side and measured in turn in every trial, so a
    change in the machine's speed falls on all of them alike. ``moving``: the camera moves
    every frame."""
    frames = moving_frames if moving else time_cpu
    gl = create_context()
    print(f"the Python loop before: {python_loop_ms():.0f} ms")
    print(f"{'pipeline':9} {'path':9} " + " ".join(f"{n:>6} ms" for n in counts) +
          "   us/draw: median (range over trials)   fixed ms   draws")
    for pipeline, paths in PATHS.items():
        for path in paths:
            renderers = [Renderer(cube_grid(count), pipeline, size, gl=gl, light_path=path)
                         for count in counts]
            try:
                for renderer in renderers:
                    for _ in range(2):
                        renderer.render(readback=False)
                cpu, draws = [[] for _ in counts], []
                slopes, intercepts = [], []
                for _ in range(trials):
                    measured = [frames(renderer, runs) for renderer in renderers]
                    draws = [d for _, d in measured]
                    for column, (ms, _) in zip(cpu, measured, strict=True):
                        column.append(ms)
                    slope, intercept = np.polyfit(draws, [ms for ms, _ in measured], 1)
                    slopes.append(1000.0 * slope)
                    intercepts.append(intercept)
            finally:
                for renderer in renderers:
                    renderer.release()
            print(f"{pipeline:9} {path:9} " +
                  " ".join(f"{statistics.median(c):9.2f}" for c in cpu) +
                  f"   {statistics.median(slopes):6.1f} ({min(slopes):.1f}-{max(slopes):.1f})"
                  f"{'':21}{statistics.median(intercepts):6.2f}   " +
                  ",".join(str(d) for d in draws))
    print(f"the Python loop after: {python_loop_ms():.0f} ms")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("counts", nargs="?", default="25,100,400")
    parser.add_argument("--size", default="160x90")
    parser.add_argument("--runs", type=int, default=8, help="frames per measurement")
    parser.add_argument("--trials", type=int, default=15)
    parser.add_argument("--moving", action="store_true",
                        help="move the camera before every frame")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    measure([int(n) for n in args.counts.split(",")], (width, height), args.runs, args.trials,
            args.moving)


if __name__ == "__main__":
    main()
