"""The outlines' cost against their width (Costigan's Table 5.4: a dilation of 12 took 28% of
the thesis' frame rate, a stroke limit of 1 against 0.1 none): the frame time and the outline
passes' time of a scene at widths 1 and 12, interleaved so the machine's drift falls on both;
process CPU time (on llvmpipe the "GPU" is this process's threads) and wall clock around
``ctx.finish()``, the median of the rounds and their range.

- by default the ``edges`` effect's ``width`` (image space: its dilation passes);
- ``--strokes``: the cartoon hair's silhouette strokes' ``stroke_width`` (object space: quads
  as wide as asked, at most the tube's radius on screen), the edges effect left as the scene
  has it.

    python benchmarks/outline_width.py [SCENE] [--size WxH] [--rounds N] [--strokes]
"""

from __future__ import annotations

import argparse
import statistics
import time

from deferred.interfaces import registry
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene

WIDTHS = (1, 12)


def scene_at(path: str, width: int, strokes: bool):
    scene = load_scene(path)
    if strokes:
        for obj in scene.objects:
            if obj.material.name == "cartoon_hair":
                obj.set_params(silhouettes=True, stroke_width=float(width))
    else:
        scene.effects = [e for e in scene.effects if e.name != "edges"]
        scene.effects.append(registry.effects.get("edges").from_dict({"width": width}))
    return scene


def spread(values: list[float]) -> str:
    return (f"{statistics.median(values) * 1000:.1f} ({min(values) * 1000:.1f}-"
            f"{max(values) * 1000:.1f})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default="examples/cartoon_hair/spiky_head.toml")
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--strokes", action="store_true")
    args = parser.parse_args()
    size = tuple(int(side) for side in args.size.split("x"))
    outline = "silhouettes" if args.strokes else "edges"
    renderers = {width: Renderer(scene_at(args.scene, width, args.strokes), size=size)
                 for width in WIDTHS}
    timings: dict[tuple[int, str, str], list[float]] = {}
    try:
        for renderer in renderers.values():
            renderer.render(readback=False)
        for _ in range(args.rounds):
            for width, renderer in renderers.items():
                ctx = renderer.gl.ctx
                ctx.finish()
                cpu, wall = time.process_time(), time.perf_counter()
                renderer.render(readback=False)
                ctx.finish()
                timings.setdefault((width, "frame", "cpu"), []).append(time.process_time() - cpu)
                timings.setdefault((width, "frame", "wall"), []).append(
                    time.perf_counter() - wall)
                started: dict[str, tuple[float, float]] = {}
                spent = [0.0, 0.0]

                def before(render_pass, frame, started=started, ctx=ctx):
                    if outline in render_pass.name:
                        ctx.finish()
                        started[render_pass.name] = (time.process_time(), time.perf_counter())

                def after(render_pass, frame, started=started, spent=spent, ctx=ctx):
                    if render_pass.name in started:
                        ctx.finish()
                        cpu, wall = started.pop(render_pass.name)
                        spent[0] += time.process_time() - cpu
                        spent[1] += time.perf_counter() - wall

                renderer.render(readback=False, before_pass=before, on_pass=after)
                timings.setdefault((width, outline, "cpu"), []).append(spent[0])
                timings.setdefault((width, outline, "wall"), []).append(spent[1])
    finally:
        for renderer in renderers.values():
            renderer.release()
    print(f"{args.scene} at {args.size}, {outline} widths {WIDTHS}, {args.rounds} rounds: "
          "median (range) ms, CPU / wall")
    for width in WIDTHS:
        print(f"width {width:2d}: frame {spread(timings[width, 'frame', 'cpu'])} / "
              f"{spread(timings[width, 'frame', 'wall'])}; {outline} passes "
              f"{spread(timings[width, outline, 'cpu'])} / "
              f"{spread(timings[width, outline, 'wall'])}")
    for kind in ("cpu", "wall"):
        ratio = {part: statistics.median(timings[WIDTHS[1], part, kind]) /
                 statistics.median(timings[WIDTHS[0], part, kind]) for part in ("frame", outline)}
        print(f"width {WIDTHS[1]} / width {WIDTHS[0]} ({kind}): frame {ratio['frame']:.2f}x, "
              f"{outline} passes {ratio[outline]:.2f}x")


if __name__ == "__main__":
    main()
