"""The edges effect's cost against its line width (Costigan's Table 5.4: width 12 took 28% of
the thesis' frame rate): the frame time and the edge passes' time of a scene at widths 1 and 12,
interleaved so the machine's drift falls on both.

    python benchmarks/outline_width.py [SCENE] [--size WxH] [--rounds N]
"""

from __future__ import annotations

import argparse
import statistics
import time

from deferred.interfaces import registry
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default="examples/cartoon_hair/spiky_head.toml")
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--rounds", type=int, default=15)
    args = parser.parse_args()
    size = tuple(int(side) for side in args.size.split("x"))
    renderers = {}
    for width in (1, 12):
        scene = load_scene(args.scene)
        scene.effects = [e for e in scene.effects if e.name != "edges"]
        scene.effects.append(registry.effects.get("edges").from_dict({"width": width}))
        renderers[width] = Renderer(scene, size=size)
    frames = {width: [] for width in renderers}
    edges = {width: [] for width in renderers}
    try:
        for renderer in renderers.values():
            renderer.render(readback=False)
        for _ in range(args.rounds):
            for width, renderer in renderers.items():
                ctx = renderer.gl.ctx
                ctx.finish()
                start = time.perf_counter()
                renderer.render(readback=False)
                ctx.finish()
                frames[width].append(time.perf_counter() - start)
                started: dict[str, float] = {}
                spent: list[float] = []

                def before(render_pass, frame, started=started, ctx=ctx):
                    ctx.finish()
                    started[render_pass.name] = time.perf_counter()

                def after(render_pass, frame, started=started, spent=spent, ctx=ctx):
                    ctx.finish()
                    if "edges" in render_pass.name:
                        spent.append(time.perf_counter() - started[render_pass.name])

                renderer.render(readback=False, before_pass=before, on_pass=after)
                edges[width].append(sum(spent))
    finally:
        for renderer in renderers.values():
            renderer.release()
    frame = {w: statistics.median(t) * 1000 for w, t in frames.items()}
    edge = {w: statistics.median(t) * 1000 for w, t in edges.items()}
    for width in renderers:
        print(f"width {width:2d}: frame {frame[width]:.1f} ms, edge passes {edge[width]:.2f} ms")
    print(f"width 12 / width 1: frame {frame[12] / frame[1]:.2f}x, "
          f"edge passes {edge[12] / edge[1]:.2f}x")


if __name__ == "__main__":
    main()
