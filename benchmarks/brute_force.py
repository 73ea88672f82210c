"""Light evaluations per second: the tiled path against this machine's brute-force limit.

Brute force is the tiled path's full-screen pass looping every point light at every covered
pixel, with no lists and no early-out (``ALL_LIGHTS`` in ``lighting/list_shading.frag``): its
rate is pixel-light evaluations per second of the light code itself. The tiled path's rate is
the work it really does, the length of each pixel's tile list summed over covered pixels, per
second of its shading pass. Run from the repository root:

    python benchmarks/brute_force.py [LIGHTS]
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np

from deferred.bench.scenes import with_extra_lights
from deferred.gl.context import create_context
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene

SIZE = (640, 360)


def shading_ms(renderer: Renderer, runs: int = 3) -> float:
    """Median milliseconds of the list shading pass (finish() on both sides)."""
    ctx = renderer.gl.ctx
    times = []
    started = {}

    def before(render_pass, frame):
        if render_pass.name == "lighting.tiled":
            ctx.finish()
            started["t"] = time.perf_counter()

    def after(render_pass, frame):
        if render_pass.name == "lighting.tiled":
            ctx.finish()
            times.append((time.perf_counter() - started["t"]) * 1000.0)

    renderer.render(readback=False)
    for _ in range(runs):
        renderer.render(before_pass=before, on_pass=after, readback=False)
    return statistics.median(times)


def main() -> None:
    lights = int(sys.argv[1]) if len(sys.argv) > 1 else 256
    gl = create_context()
    scene = with_extra_lights(load_scene("benchmarks/lights.toml"), lights, SIZE[0] / SIZE[1])
    with Renderer(scene, "deferred", SIZE, gl=gl, light_path="tiled") as renderer:
        tiled = shading_ms(renderer)
        counts = renderer.light_lists.counts()
        grid = renderer.light_lists.grid
        depth = renderer.targets.read("linear_depth")[..., 0]
        local = renderer.light_buffer.local_count
        ys, xs = np.nonzero(depth > 0.0)
        lists = counts[(ys // grid.tile) * grid.columns + xs // grid.tile]
        tiled_evaluations = float(lists.sum())
        shading = next(p for p in renderer.passes if p.name == "lighting.tiled")
        shading.defines = {**shading.defines, "ALL_LIGHTS": "1"}
        brute = shading_ms(renderer)
    covered = len(xs)
    brute_rate = covered * local / (brute / 1000.0)
    tiled_rate = tiled_evaluations / (tiled / 1000.0)
    print(f"{lights} point lights at {SIZE[0]}x{SIZE[1]}, {covered} covered pixels")
    print(f"brute force: {brute:.1f} ms, {covered * local / 1e6:.1f} M evaluations, "
          f"{brute_rate / 1e9:.3f} G evaluations per second")
    print(f"tiled lists: {tiled:.1f} ms, {tiled_evaluations / 1e6:.2f} M list entries "
          f"({lists.mean():.1f} per pixel), {tiled_rate / 1e9:.3f} G per second, "
          f"{tiled_rate / brute_rate:.2f}x the brute-force rate; "
          f"{brute / tiled:.1f}x faster than brute force for the same image")
    gl.release()


if __name__ == "__main__":
    main()
