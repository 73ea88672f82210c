"""A scene's frame graph: every pass of a frame in order, with its kind, what it reads and
writes, and its median time (each pass fenced by ``ctx.finish()``), and the frame's.

    python benchmarks/frame_graph.py [SCENE] [--size 1280x720] [--pipeline deferred]
                                     [--light-path tiled] [--runs 3]
"""

from __future__ import annotations

import argparse
import statistics
import time

from deferred import Renderer, load_scene
from deferred.scene.size import parse_size


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=None)
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--pipeline", default="deferred")
    parser.add_argument("--light-path", default=None)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    size = parse_size(args.size)
    with Renderer(load_scene(args.scene or None), args.pipeline, size,
                  light_path=args.light_path) as renderer:
        renderer.render(readback=False)  # compiling
        started: dict[str, float] = {}
        times: dict[str, list[float]] = {}

        def before(render_pass, frame) -> None:
            frame.ctx.finish()
            started[render_pass.name] = time.perf_counter()

        def after(render_pass, frame) -> None:
            frame.ctx.finish()
            times.setdefault(render_pass.name, []).append(
                time.perf_counter() - started[render_pass.name])

        frames = []
        for _ in range(args.runs):
            renderer.render(readback=False, before_pass=before, on_pass=after)
            start = time.perf_counter()
            renderer.render(readback=False)
            renderer.gl.ctx.finish()
            frames.append(time.perf_counter() - start)
        print(f"{args.scene or 'the demo'}, {args.pipeline} "
              f"{renderer.pipeline.light_path}, {size[0]}x{size[1]}: "
              f"{len(renderer.passes)} passes")
        for render_pass in renderer.passes:
            ms = statistics.median(times.get(render_pass.name, [0.0])) * 1000
            print(f"  {render_pass.name:32s} {type(render_pass).__name__:24s} {ms:8.1f} ms  "
                  f"reads {', '.join(sorted(render_pass.reads)) or '-'}; "
                  f"writes {', '.join(sorted({*render_pass.writes, *render_pass.creates}))}")
        print(f"  frame (unfenced) median {statistics.median(frames) * 1000:.1f} ms")


if __name__ == "__main__":
    main()
