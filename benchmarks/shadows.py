"""What shadows cost: `lights.toml` at 1280x720 through every light path of both pipelines,
unshadowed against (a) its directional light shadowed (3 cascades of 2048^2) and (b) 16 spot
lights added, unshadowed against shadowed (1024^2 each; the 4096^2 atlas holds all 16).
Median wall-clock frame time around ``ctx.finish()``, and the ``shadows`` pass's alone. Run from
the repository root:

    python benchmarks/shadows.py [--size WxH] [--runs N]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from deferred.gl.context import create_context
from deferred.interfaces import registry
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene

PATHS = [("deferred", "volumes"), ("deferred", "tiled"), ("deferred", "clustered"),
         ("forward", "naive"), ("forward", "tiled")]


def spot_lights(shadows: bool, count: int = 16) -> list:
    """``count`` spot lights on a ring over the shapes, each aimed at a point of the floor."""
    spot = registry.lights.get("spot")
    out = []
    for k in range(count):
        angle = 2.0 * np.pi * k / count
        position = (2.2 * np.cos(angle), 2.4, 2.2 * np.sin(angle))
        target = (0.8 * np.cos(angle + 1.0), 0.0, 0.8 * np.sin(angle + 1.0))
        direction = tuple(float(t - p) for t, p in zip(target, position, strict=True))
        out.append(spot.from_dict({
            "position": [float(p) for p in position], "direction": list(direction),
            "radius": 6.0, "intensity": 1.5, "inner_angle": 25.0, "outer_angle": 35.0,
            "color": [1.0, 0.9, 0.8], "shadows": shadows, "shadow_resolution": 1024}))
    return out


def scene_for(case: str):
    scene = load_scene("benchmarks/lights.toml")
    directional = next(light for light in scene.lights if light.name == "directional")
    if case == "directional":
        directional.params = directional.params.model_copy(update={
            "shadows": True, "cascades": 3, "shadow_resolution": 2048})
    if case.startswith("spots"):
        scene.lights.extend(spot_lights(shadows=case == "spots shadowed"))
    return scene


def timed(renderer: Renderer, runs: int) -> tuple[float, float]:
    """(median frame ms, median ms of the shadows pass)."""
    ctx = renderer.gl.ctx
    frames, shadow = [], []
    started = {}

    def before(render_pass, frame):
        if render_pass.name == "shadows":
            ctx.finish()
            started["t"] = time.perf_counter()

    def after(render_pass, frame):
        if render_pass.name == "shadows":
            ctx.finish()
            shadow.append((time.perf_counter() - started["t"]) * 1000.0)

    renderer.render(readback=False)  # shaders compile
    for _ in range(runs):
        ctx.finish()
        start = time.perf_counter()
        renderer.render(readback=False)
        ctx.finish()
        frames.append((time.perf_counter() - start) * 1000.0)
    renderer.render(readback=False, before_pass=before, on_pass=after)
    return statistics.median(frames), (shadow[0] if shadow else 0.0)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    gl = create_context()
    cases = ["plain", "directional", "spots", "spots shadowed"]
    print("| pipeline | light path | unshadowed | directional shadowed (3 x 2048^2) | ratio | "
          "16 spots | 16 spots shadowed (16 x 1024^2) | ratio |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for pipeline, path in PATHS:
        ms = {}
        for case in cases:
            with Renderer(scene_for(case), pipeline, size, gl=gl, light_path=path) as renderer:
                ms[case] = timed(renderer, args.runs)
        plain, directional = ms["plain"][0], ms["directional"]
        spots, shadowed = ms["spots"][0], ms["spots shadowed"]
        print(f"| {pipeline} | {path} | {plain:.1f} | {directional[0]:.1f} "
              f"(shadows {directional[1]:.1f}) | {directional[0] / plain:.2f}x | {spots:.1f} | "
              f"{shadowed[0]:.1f} (shadows {shadowed[1]:.1f}) | {shadowed[0] / spots:.2f}x |",
              flush=True)


if __name__ == "__main__":
    main()
