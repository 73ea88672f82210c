"""What temporal anti-aliasing costs a frame (#25): the built-in demo at 640x360 in each
pipeline without and with ``[[effect]] type = "taa"``, frames of a moving sequence (t = k / 24,
the camera on a turntable), median wall-clock ms around ``ctx.finish()`` over the timed frames
after warm-up ones; and the taa passes' own median ms (the motion vectors, the resolve and the
sharpen), timed by finishing the GL work before and after each.

    python benchmarks/taa_cost.py [--size WxH] [--frames N] [--warmup N]
"""

from __future__ import annotations

import argparse
import statistics
import time

from deferred.effects.taa import TAA
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene

TAA_PASSES = ("motion.camera", "motion.objects", "post.taa", "post.taa_sharpen")


def run(pipeline: str, taa: bool, size: tuple[int, int], frames: int, warmup: int):
    scene = load_scene()
    if taa:
        scene.effects.append(TAA())
    scene.set_turntable(10.0)
    totals, own = [], []
    with Renderer(scene, pipeline, size) as renderer:
        ctx = renderer.gl.ctx
        marks: dict[str, float] = {}

        def before(render_pass, frame):
            if render_pass.name in TAA_PASSES:
                ctx.finish()
                marks["start"] = time.perf_counter()

        def after(render_pass, frame):
            if render_pass.name in TAA_PASSES:
                ctx.finish()
                marks["own"] = marks.get("own", 0.0) + time.perf_counter() - marks["start"]

        for k in range(warmup + frames):
            ctx.finish()
            start = time.perf_counter()
            renderer.render(time=k / 24.0, readback=False)
            ctx.finish()
            if k >= warmup:
                totals.append((time.perf_counter() - start) * 1000.0)
        if taa:  # the passes' own time, in frames apart (finishing around them costs)
            for k in range(frames):
                marks.clear()
                renderer.render(time=(warmup + frames + k) / 24.0, readback=False,
                                before_pass=before, on_pass=after)
                own.append(marks["own"] * 1000.0)
    return statistics.median(totals), (statistics.median(own) if own else 0.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--warmup", type=int, default=3)
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    for pipeline in ("deferred", "forward"):
        plain, _ = run(pipeline, False, size, args.frames, args.warmup)
        with_taa, own = run(pipeline, True, size, args.frames, args.warmup)
        print(f"{pipeline:9} {size[0]}x{size[1]}: {plain:7.1f} ms, with taa {with_taa:7.1f} ms "
              f"(taa's passes {own:.1f} ms)", flush=True)


if __name__ == "__main__":
    main()
