"""The deferred pipeline's fixed cost a frame, where pixels cost little (160x90): the calls into
``deferred/gl/uniforms.py`` and the uniform writes that reach GL a frame (counted by cProfile),
and the frame's CPU time (median of 30 frames, llvmpipe's threads included), for a one-object
scene, ``lights.toml`` and the demo; the camera still (the same frame again) or turning a
degree a frame (``--orbit``).

    python benchmarks/frame_cost.py [--size 160x90] [--orbit]
"""

from __future__ import annotations

import argparse
import cProfile
import math
import pstats
import statistics
import time
from dataclasses import replace

import numpy as np

from deferred import Renderer, load_scene
from deferred.scene.loader import scene_from_dict
from deferred.scene.size import parse_size

ONE_OBJECT = {"camera": {"position": [0.0, 1.0, 4.0], "target": [0.0, 0.5, 0.0]},
              "object": [{"mesh": "builtin:sphere", "material": "standard"}],
              "light": [{"type": "directional", "direction": [-1.0, -1.0, -1.0]}]}


def turn(renderer: Renderer) -> None:
    camera = renderer.scene.camera
    target = np.asarray(camera.target, np.float64)
    x, y, z = np.asarray(camera.position, np.float64) - target
    c, s = math.cos(math.radians(1.0)), math.sin(math.radians(1.0))
    renderer.scene.camera = replace(camera, position=tuple(
        float(v) for v in target + (c * x + s * z, y, -s * x + c * z)))


def measure(scene, size: tuple[int, int], orbit: bool) -> tuple[float, float, float]:
    with Renderer(scene, "deferred", size) as renderer:
        for _ in range(3):
            renderer.render(readback=False)
        renderer.gl.ctx.finish()
        frames = 10
        profile = cProfile.Profile()
        profile.enable()
        for _ in range(frames):
            if orbit:
                turn(renderer)
            renderer.render(readback=False)
        renderer.gl.ctx.finish()
        profile.disable()
        calls = writes = 0
        for (path, _, name), (_, count, *_rest) in pstats.Stats(profile).stats.items():
            if path.endswith("uniforms.py"):
                calls += count
            if name == "_write" and path.endswith("uniforms.py"):
                writes += count
        cpu = []
        for _ in range(30):
            if orbit:
                turn(renderer)
            start = time.process_time()
            renderer.render(readback=False)
            renderer.gl.ctx.finish()
            cpu.append(time.process_time() - start)
        return calls / frames, writes / frames, statistics.median(cpu) * 1000


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="160x90")
    parser.add_argument("--orbit", action="store_true")
    args = parser.parse_args()
    size = parse_size(args.size)
    for name, scene in (("one object", lambda: scene_from_dict(dict(ONE_OBJECT))),
                        ("lights.toml", lambda: load_scene("benchmarks/lights.toml")),
                        ("the demo", lambda: load_scene(None))):
        calls, writes, cpu = measure(scene(), size, args.orbit)
        print(f"{name}: {calls:.0f} calls into uniforms.py a frame, {writes:.0f} uniform "
              f"writes, frame CPU {cpu:.2f} ms")


if __name__ == "__main__":
    main()
