"""What shadows cost: `lights.toml` at 1280x720 through every light path of both pipelines,
unshadowed against (a) its directional light shadowed (3 cascades of 2048^2) and (b) 16 spot
lights added, unshadowed against shadowed (1024^2 each; the 4096^2 atlas holds all 16).
Median wall-clock frame time around ``ctx.finish()``, and the ``shadows`` pass's alone, and
the frame's CPU time (llvmpipe's threads included). ``--camera orbit`` turns the camera by a
degree a frame around its target (the cascades follow it; still lights' maps are kept), ``still``
draws the same frame again; ``--cascade-updates staggered`` draws the far cascades in turn
while the camera moves (``deferred.lighting.shadows.stagger``; the shadows pass's time is then
the mean of two frames, one of each far cascade's turn).

``--allocation fixed`` gives every spot's map its 1024^2 (``coverage``, the default, sizes
them by the part of the screen each lights: ``[shadows] allocation``); ``--allocation both``
times the spots with fixed and with coverage maps one after the other and prints, for each,
the atlas's texels the maps hold and those the timed frames drew a frame (the directional case
is left out: its cascades cover the view).
``--move-spots`` turns the spots a degree a frame about the vertical (every map drawn again
each frame), ``--hold`` holds the sizes from frame to frame as the live viewer does.
``--spots receding`` puts the 16 spots over a long floor in four rows going away from the
camera, a cube under each, so they cover unequal parts of the screen (``ring``: the ring over
lights.toml's shapes, each lighting most of the view). Run from the repository root:

    python benchmarks/shadows.py [--size WxH] [--runs N] [--camera still|orbit]
                                 [--cascade-updates every_frame|staggered]
                                 [--paths deferred:tiled,forward:naive,...]
                                 [--allocation fixed|coverage|both] [--spots ring|receding]
                                 [--rounds N] [--move-spots] [--hold]
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
from deferred.scene.loader import load_scene, scene_from_dict

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


PLAIN = {"color": [0.5, 0.48, 0.45], "specular_intensity": 0.2}


def receding_scene(shadows: bool, size: tuple[int, int]):
    """16 spots in four rows of four over a long floor, the rows 5 units apart going away
    from the camera, each aimed straight down at a cube: the near row lights much of the
    screen, the far row little."""
    objects = [{"mesh": "builtin:plane", "scale": 14.0, "position": [0.0, 0.0, -6.0],
                "params": PLAIN}]
    lights = [{"type": "ambient", "color": [0.05, 0.05, 0.06]}]
    for row in range(4):
        z = 4.0 - 5.0 * row
        for column in range(4):
            x = (column - 1.5) * (2.0 + row)
            objects.append({"mesh": "builtin:cube", "position": [x, 0.3, z], "scale": 0.3,
                            "rotation": [0.0, 25.0 * column, 0.0], "params": PLAIN})
            lights.append({"type": "spot", "position": [x + 0.4, 3.0, z + 0.3],
                           "direction": [-0.15, -1.0, -0.1], "radius": 5.0, "intensity": 8.0,
                           "inner_angle": 30.0, "outer_angle": 40.0,
                           "color": [1.0, 0.9, 0.8], "shadows": shadows,
                           "shadow_resolution": 1024})
    return scene_from_dict({"size": list(size), "camera": {
        "position": [0.0, 4.5, 9.0], "target": [0.0, 0.0, -3.0], "fov": 50.0, "far": 60.0},
        "object": objects, "light": lights}, "receding spots")


def scene_for(case: str, spots: str = "ring", allocation: str = "coverage",
              size: tuple[int, int] = (1280, 720)):
    if spots == "receding" and case.startswith("spots"):
        scene = receding_scene(case == "spots shadowed", size)
    else:
        scene = load_scene("benchmarks/lights.toml")
        directional = next(light for light in scene.lights if light.name == "directional")
        if case == "directional":
            directional.params = directional.params.model_copy(update={
                "shadows": True, "cascades": 3, "shadow_resolution": 2048})
        if case.startswith("spots"):
            scene.lights.extend(spot_lights(shadows=case == "spots shadowed"))
    scene.shadow_budget = replace(scene.shadow_budget, allocation=allocation)
    return scene


def orbit(renderer: Renderer, degrees: float) -> None:
    """The camera turned by ``degrees`` about the vertical through its target."""
    camera = renderer.scene.camera
    target = np.asarray(camera.target, np.float64)
    offset = np.asarray(camera.position, np.float64) - target
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    turned = (c * offset[0] + s * offset[2], offset[1], -s * offset[0] + c * offset[2])
    renderer.scene.camera = replace(camera, position=tuple(float(v) for v in target + turned))


def texels(atlas, before: dict) -> tuple[int, int]:
    """The atlas's texels this frame's maps hold, and those of the maps its shadow pass drew
    (the squares whose drawn-with key changed from ``before``)."""
    if atlas is None:
        return 0, 0
    held = sum(tile.size * tile.size for tile in atlas.tiles)
    return held, sum(rect[2] * rect[2] for rect, key in atlas.drawn.items()
                     if before.get(rect) != key)


def turn_spots(renderer: Renderer, degrees: float) -> None:
    """Every spot light turned by ``degrees`` about the vertical through the origin, its
    direction with it: every spot's map is drawn again."""
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))

    def turned(v):
        return [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]

    for light in renderer.scene.lights:
        if light.name == "spot":
            light.params = light.params.model_copy(update={
                "position": turned(light.params.position),
                "direction": turned(light.params.direction)})


def timed(renderer: Renderer, runs: int, moving: bool,
          move_spots: bool = False) -> tuple[float, ...]:
    """(median frame ms, ms of the shadows pass, median frame CPU ms, atlas texels held,
    median texels drawn a frame, ms of the shadows pass drawing every map)."""
    ctx = renderer.gl.ctx
    frames, shadow, cpu, drawn = [], [], [], []
    started = {}
    atlas = renderer.shadow_atlas
    before_drawn: dict = {}

    def before(render_pass, frame):
        if render_pass.name == "shadows":
            ctx.finish()
            started["t"] = time.perf_counter()

    def after(render_pass, frame):
        if render_pass.name == "shadows":
            ctx.finish()
            shadow.append((time.perf_counter() - started["t"]) * 1000.0)

    def keep_drawn(render_pass, frame):
        if render_pass.name == "shadows" and atlas is not None:
            before_drawn.clear()
            before_drawn.update(atlas.drawn)

    def step():
        if moving:
            orbit(renderer, 1.0)
        if move_spots:
            turn_spots(renderer, 1.0)

    renderer.render(readback=False)  # shaders compile
    if moving:  # the first turn: staggered far cascades are all drawn, fitted wider
        step()
        renderer.render(readback=False)
    for _ in range(runs):
        step()
        ctx.finish()
        start, cpu_start = time.perf_counter(), time.process_time()
        renderer.render(readback=False, before_pass=keep_drawn)
        ctx.finish()
        frames.append((time.perf_counter() - start) * 1000.0)
        cpu.append((time.process_time() - cpu_start) * 1000.0)
        drawn.append(texels(atlas, before_drawn)[1])
    fenced = 2 if moving else 1  # moving: both turns of staggered far cascades
    for _ in range(fenced):
        step()
        renderer.render(readback=False, before_pass=before, on_pass=after)
    held = texels(atlas, before_drawn)[0]
    if atlas is not None:  # every map drawn again: what a change of every map costs
        atlas.drawn.clear()
        renderer.render(readback=False, before_pass=before, on_pass=after)
    return (statistics.median(frames), (statistics.mean(shadow[:fenced]) if shadow else 0.0),
            statistics.median(cpu),
            held, statistics.median(drawn), shadow[-1] if shadow else 0.0)


def cell(m: list[float], d: list[float]) -> str:
    """A case's medians ``m`` and spreads ``d`` (max - min over the rounds) as a cell."""
    return (f"{m[0]:.0f}+-{d[0] / 2:.0f} ({m[1]:.1f}; {m[5]:.0f}) [{m[2]:.0f}] "
            f"{{{m[3] / 2**20:.2f} / {m[4] / 2**20:.2f}}}")


def allocations(args, size, paths, gl) -> None:
    """The spots unshadowed, then shadowed with fixed and with coverage maps, interleaved by
    rounds (``--runs`` frames a round, the median of the rounds' medians)."""
    print(f"camera {args.camera}{', spots turning' if args.move_spots else ''}, {args.spots} "
          "spots; each cell: frame ms (shadows pass ms; drawing every map ms) [frame CPU ms] "
          "{atlas Mi texels held / Mi texels drawn a frame}")
    print("| pipeline | light path | 16 spots | shadowed, fixed | ratio | shadowed, coverage "
          "| ratio |")
    print("|---|---|---:|---:|---:|---:|---:|")
    cases = [("spots", "fixed"), ("spots shadowed", "fixed"), ("spots shadowed", "coverage")]
    for pipeline, path in paths:
        rounds: dict = {case: [] for case in cases}
        for _ in range(args.rounds):
            for case in cases:
                scene = scene_for(case[0], args.spots, case[1], size)
                with Renderer(scene, pipeline, size, gl=gl, light_path=path) as renderer:
                    renderer.hold_shadow_sizes = args.hold
                    rounds[case].append(timed(renderer, args.runs, args.camera == "orbit",
                                              args.move_spots))
        ms = {case: [statistics.median(v) for v in zip(*rounds[case], strict=True)]
              for case in cases}
        spread = {case: [max(v) - min(v) for v in zip(*rounds[case], strict=True)]
                  for case in cases}
        plain = ms[cases[0]]

        print(f"| {pipeline} | {path} | {plain[0]:.0f} [{plain[2]:.0f}] | "
              + " | ".join(f"{cell(ms[case], spread[case])} | {ms[case][0] / plain[0]:.2f}x "
                           f"[{ms[case][2] / plain[2]:.2f}x]" for case in cases[1:]) + " |",
              flush=True)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--camera", choices=("still", "orbit"), default="still")
    parser.add_argument("--cascade-updates", choices=("every_frame", "staggered"),
                        default="every_frame")
    parser.add_argument("--paths", default=",".join(f"{p}:{q}" for p, q in PATHS))
    parser.add_argument("--allocation", choices=("fixed", "coverage", "both"),
                        default="coverage")
    parser.add_argument("--spots", choices=("ring", "receding"), default="ring")
    parser.add_argument("--rounds", type=int, default=1,
                        help="--allocation both: rounds of the three cases, interleaved")
    parser.add_argument("--move-spots", action="store_true",
                        help="--allocation both: the spots turn a degree a frame")
    parser.add_argument("--hold", action="store_true",
                        help="--allocation both: sizes held from frame to frame (the viewer's)")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    paths = [tuple(item.split(":")) for item in args.paths.split(",")]
    gl = create_context()
    if args.allocation == "both":
        allocations(args, size, paths, gl)
        return
    cases = ["plain", "directional", "spots", "spots shadowed"]
    print(f"camera {args.camera}, cascades {args.cascade_updates}; each cell: frame ms "
          "(shadows pass ms) [frame CPU ms]")
    print("| pipeline | light path | unshadowed | directional shadowed (3 x 2048^2) | ratio | "
          "16 spots | 16 spots shadowed (16 x 1024^2) | ratio |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for pipeline, path in paths:
        ms = {}
        for case in cases:
            scene = scene_for(case, args.spots, args.allocation, size)
            with Renderer(scene, pipeline, size, gl=gl, light_path=path,
                          cascade_updates=args.cascade_updates) as renderer:
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
