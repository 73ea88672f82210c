"""Deferred against forward with 16 and 256 lights for the subsurface material and for rect
lights (#36): the bunny (examples/meshes/bunny.ply) on a floor under a shadowed directional
light, plus N lights placed as ``deferred bench`` places its extra point lights
(``deferred.bench.scenes.extra_point_lights``, seeded): in the ``subsurface`` case the bunny is
the subsurface material and the N lights are point lights; in the ``rect`` case the bunny is
the standard material and each of the N lights is a rect light (0.3 x 0.2, unshadowed, facing
down) where the point light would be. Each point's renderers are made once and their frames
timed in turn, round after round (interleaved), the wall clock around ``render()`` and
``ctx.finish()`` (``deferred.bench.timing.time_frame``): the median ms a frame over the rounds
and the spread (lowest to highest round's median).

    python benchmarks/area_subsurface.py [--size WxH] [--rounds N] [--frames N] [--lights 16,256]
"""

from __future__ import annotations

import argparse
import statistics
from dataclasses import replace
from pathlib import Path

from deferred.bench.scenes import extra_point_lights
from deferred.bench.timing import time_frame
from deferred.interfaces import registry
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

BUNNY = str(Path(__file__).resolve().parent.parent / "examples" / "meshes" / "bunny.ply")
POINTS = [("deferred", "tiled"), ("deferred", "volumes"), ("forward", "tiled")]


def base_scene(material: str, size: tuple[int, int]):
    params = {"color": [0.86, 0.62, 0.5], "specular_intensity": 0.3}
    if material == "subsurface":
        params["radius"] = 0.03
    return scene_from_dict({
        "size": list(size),
        "camera": {"position": [0.35, 0.75, 1.9], "target": [0.0, 0.42, 0.0], "fov": 38.0},
        "object": [{"mesh": "builtin:plane", "scale": 3.0},
                   {"mesh": BUNNY, "material": material, "params": params}],
        "light": [{"type": "directional", "direction": [0.6, -0.55, -0.45], "intensity": 1.0,
                   "shadows": True},
                  {"type": "ambient", "intensity": 0.05}]})


def with_lights(case: str, count: int, size: tuple[int, int]):
    scene = base_scene("subsurface" if case == "subsurface" else "standard", size)
    lights = extra_point_lights(scene, count, size[0] / size[1])
    if case == "rect":
        rect = registry.lights.get("rect")
        lights = [rect.from_dict({"position": light.params.position, "direction": [0, -1, 0],
                                  "size": [0.3, 0.2], "color": light.params.color,
                                  "intensity": light.params.intensity,
                                  "radius": light.params.radius}) for light in lights]
    return replace(scene, lights=[*scene.lights, *lights])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--frames", type=int, default=1, help="frames a point a round")
    parser.add_argument("--lights", default="16,256")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    print("| case | lights | pipeline | light path | ms a frame (median) | spread |")
    print("|---|---:|---|---|---:|---:|")
    for case in ("subsurface", "rect"):
        for count in (int(v) for v in args.lights.split(",")):
            scene = with_lights(case, count, size)
            renderers = [Renderer(scene, pipeline, size, light_path=path)
                         for pipeline, path in POINTS]
            try:
                for renderer in renderers:  # compile and upload before timing
                    renderer.render(readback=False)
                rounds: list[list[float]] = [[] for _ in POINTS]
                for _ in range(args.rounds):
                    for times, renderer in zip(rounds, renderers, strict=True):
                        times.append(statistics.median(time_frame(renderer)
                                                       for _ in range(args.frames)))
            finally:
                for renderer in renderers:
                    renderer.release()
            for (pipeline, path), times in zip(POINTS, rounds, strict=True):
                print(f"| {case} | {count} | {pipeline} | {path} | "
                      f"{statistics.median(times):.1f} | {min(times):.1f}-{max(times):.1f} |",
                      flush=True)


if __name__ == "__main__":
    main()
