"""What shadows cost: `lights.toml` at 1280x720 through every light path of both pipelines,
unshadowed against (a) its directional light shadowed (3 cascades of 2048^2) and (b) 16 spot
lights added, unshadowed against shadowed (1024^2 each; the 4096^2 atlas holds all 16).
Median wall-clock frame time around ``ctx.finish()``, and the ``shadows`` pass's alone, and
the frame's CPU time (llvmpipe's threads included). ``--camera orbit`` turns the camera by a
degree a frame around its target (the cascades follow it; still lights' maps are kept), ``still``
draws the same frame again. Run from the repository root:

    python benchmarks/shadows.py [--size WxH] [--runs N] [--camera still|orbit]
                                 [--paths deferred:tiled,forward:naive,...]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from dataclasses import replace

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


def orbit(renderer: Renderer, degrees: float) -> None:
    """The camera turned by ``degrees`` about the vertical through its target."""
    camera = renderer.scene.camera
    target = np.asarray(camera.target, np.float64)
    offset = np.asarray(camera.position, np.float64) - target
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    turned = (c * offset[0] + s * offset[2], offset[1], -s * offset[0] + c * offset[2])
    renderer.scene.camera = replace(camera, position=tuple(float(v) for v in target + turned))


def timed(renderer: Renderer, runs: int, moving: bool) -> tuple[float, float, float]:
    """(median frame ms, median ms of the shadows pass, median frame CPU ms)."""
    ctx = renderer.gl.ctx
    frames, shadow, cpu = [], [], []
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
        if moving:
            orbit(renderer, 1.0)
        ctx.finish()
        start, cpu_start = time.perf_counter(), time.process_time()
        renderer.render(readback=False)
        ctx.finish()
        frames.append((time.perf_counter() - start) * 1000.0)
        cpu.append((time.process_time() - cpu_start) * 1000.0)
    if moving:
        orbit(renderer, 1.0)
    renderer.render(readback=False, before_pass=before, on_pass=after)
    return statistics.median(frames), (shadow[0] if shadow else 0.0), statistics.median(cpu)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--camera", choices=("still", "orbit"), default="still")
    parser.add_argument("--paths", default=",".join(f"{p}:{q}" for p, q in PATHS))
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    paths = [tuple(item.split(":")) for item in args.paths.split(",")]
    gl = create_context()
    cases = ["plain", "directional", "spots", "spots shadowed"]
    print(f"camera {args.camera}; each cell: frame ms (shadows pass ms) [frame CPU ms]")
    print("| pipeline | light path | unshadowed | directional shadowed (3 x 2048^2) | ratio | "
          "16 spots | 16 spots shadowed (16 x 1024^2) | ratio |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for pipeline, path in paths:
        ms = {}
        for case in cases:
            with Renderer(scene_for(case), pipeline, size, gl=gl, light_path=path) as renderer:
                ms[case] = timed(renderer, args.runs, args.camera == "orbit")
        plain, directional = ms["plain"], ms["directional"]
        spots, shadowed = ms["spots"], ms["spots shadowed"]
        print(f"| {pipeline} | {path} | {plain[0]:.1f} [{plain[2]:.0f}] | {directional[0]:.1f} "
              f"({directional[1]:.1f}) [{directional[2]:.0f}] | "
              f"{directional[0] / plain[0]:.2f}x [{directional[2] / plain[2]:.2f}x] | "
              f"{spots[0]:.1f} [{spots[2]:.0f}] | {shadowed[0]:.1f} ({shadowed[1]:.1f}) "
              f"[{shadowed[2]:.0f}] | {shadowed[0] / spots[0]:.2f}x "
              f"[{shadowed[2] / spots[2]:.2f}x] |", flush=True)


if __name__ == "__main__":
    main()
