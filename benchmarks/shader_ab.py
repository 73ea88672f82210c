"""Time variants of the framework's shaders against each other, frames interleaved in one
process: the way to see a 5% change on a machine whose speed moves by 30% in minutes.

Each VARIANT is a folder laid out like ``deferred/shaders`` holding only the files it changes
(``lighting/listed_lights.glsl``, say); ``-`` is the shaders as they are. One renderer is built
per variant on one GL context, and every round renders, for each variant in turn, one frame
timed by wall clock around ``render()`` and ``finish()`` and one with every pass fenced
(``deferred.bench.timing.time_passes``); each round starts from the next variant. Printed: each
variant's median and minimum frame time and its passes' medians. Run from the repository root:

    python benchmarks/shader_ab.py [--scene FILE] [--size WxH] [--lights N] [--rounds N]
                                   [--pipeline NAME] [--light-path PATH] VARIANT...

Cut-outs (a variant that leaves out part of a shader) measure what that part costs; the
results of the ones behind ``benchmarks/README.md`` ("Where the tiled shading's time goes")
are written there.
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

from deferred.bench.scenes import with_extra_lights
from deferred.bench.timing import interleaved_rounds
from deferred.errors import DeferredError
from deferred.gl.context import create_context
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene


def parse_size(text: str) -> tuple[int, int]:
    width, _, height = text.partition("x")
    return int(width), int(height)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("variants", nargs="+", metavar="VARIANT")
    parser.add_argument("--scene", default="benchmarks/lights.toml")
    parser.add_argument("--size", type=parse_size, default=(640, 360))
    parser.add_argument("--lights", type=int, default=1024, help="extra point lights")
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--pipeline", default="deferred")
    parser.add_argument("--light-path", default="tiled")
    args = parser.parse_args(argv)
    for variant in args.variants:
        if variant != "-" and not Path(variant).is_dir():
            print(f"{variant}: not a folder of shader files", file=sys.stderr)
            return 2
    try:
        scene = with_extra_lights(load_scene(args.scene), args.lights,
                                  args.size[0] / args.size[1])
        gl = create_context()
        renderers = []
        for variant in args.variants:
            renderer = Renderer(scene, args.pipeline, args.size, gl=gl,
                                light_path=args.light_path)
            if variant != "-":
                renderer.shaders.add_root(Path(variant), first=True)
            renderer.render(readback=False)  # compiles: a broken variant fails here
            renderers.append(renderer)
    except DeferredError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    frames, passes = interleaved_rounds(renderers, args.rounds)
    for variant, times, by_pass in zip(args.variants, frames, passes, strict=True):
        medians = ", ".join(f"{name} {statistics.median(ms):.2f}" for name, ms in by_pass.items()
                            if not name.endswith((".gbuffer", ".clear")))
        print(f"{variant}: median {statistics.median(times):.2f} ms, min {min(times):.2f} ms; "
              f"{medians}")
    for renderer in renderers:
        renderer.release()
    gl.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
