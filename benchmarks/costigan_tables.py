"""Costigan's Chapter 5 performance tables again, on this machine: Table 5.2 (screen
resolution), Fig. 5.1 (strand count), Table 5.3 (hair and shape resolution against the outline
method), Table 5.4 (outline width) and Table 5.5 (anchors and animation). Table 5.1 (the tonal
art map's generation) is ``benchmarks/tam_bench.py``.

The thesis' defaults (5.1.3): 1024x768, 100 strands, 5 segments, 8 hair sampling points, 8
vertices a point; here combed hair on the built-in head, turning (a track), object-space
silhouette strokes (``silhouettes``) unless a row says image space (the ``edges`` effect),
deferred, one directional light. Each row renders ``--frames`` frames 1/30 s apart after one
untimed frame (the programs built, the hair settled) and gives the median of its frames'
process CPU time (on llvmpipe the "GPU" is this process's threads) and wall clock around
``ctx.finish()``, and the frame rate its CPU time makes (1000 / ms CPU: on a machine others
load, the wall clock counts their work too; on an idle one llvmpipe's threads share the frame,
so this is a floor). Table 5.5 takes
``anchored_head.toml``'s strands (150, from its pose files): anchors to the rest pose, or, with
"animated hair", keyframed from one parting to the other.

    OPENBLAS_NUM_THREADS=1 python benchmarks/costigan_tables.py [--frames N] [--only 5.3]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

EXAMPLES = Path(__file__).parents[1] / "examples" / "cartoon_hair"
TURNING = {"target": "object:head", "interpolation": "smooth",
           "keys": [{"time": 0.0, "rotation": [0.0, 0.0, 0.0]},
                    {"time": 0.5, "rotation": [0.0, 50.0, 0.0]},
                    {"time": 1.0, "rotation": [0.0, -40.0, 0.0]}]}


def thesis_scene(size=(1024, 768), strands=100, samples=8, sides=8, outline="object",
                 width=1.0, turning=True, anchors: dict | None = None) -> object:
    """The thesis' default set-up with one thing changed."""
    params = {"strands": strands, "style": "combed", "length": 0.2, "segments": 5,
              "hair_samples": samples, "sides": sides, "silhouettes": outline == "object",
              "stroke_width": width if outline == "object" else 3.0,
              "color": [0.85, 0.55, 0.25], "bend_stiffness": 0.4, "torsion_stiffness": 0.4,
              **(anchors or {})}
    return scene_from_dict({
        "size": list(size), "tonemap": "none", "background": [0.93, 0.93, 0.96],
        "camera": {"position": [0.0, 0.05, 0.6], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"name": "head", "mesh": "builtin:head", "material": "cartoon_hair",
                    "params": params}],
        "light": [{"type": "directional", "direction": [-0.5, -0.6, -0.6]}],
        "effect": [{"type": "edges", "width": int(width)}] if outline == "image" else [],
        "track": [TURNING] if turning else []}, str(EXAMPLES / "costigan_tables.toml"))


def timed(scene, frames: int) -> tuple[float, float]:
    """Median (process CPU ms, wall ms) a frame."""
    cpu_times, wall_times = [], []
    with Renderer(scene, "deferred") as renderer:
        ctx = renderer.gl.ctx
        renderer.render(time=0.0, readback=False)
        for frame in range(1, frames + 1):
            ctx.finish()
            cpu, wall = time.process_time(), time.perf_counter()
            renderer.render(time=frame / 30.0, readback=False)
            ctx.finish()
            cpu_times.append(time.process_time() - cpu)
            wall_times.append(time.perf_counter() - wall)
    return statistics.median(cpu_times) * 1000.0, statistics.median(wall_times) * 1000.0


def anchors(stiffness: float, animated: bool) -> dict:
    keyframes = {"keyframes": [str(EXAMPLES / "pose_left.json"),
                               str(EXAMPLES / "pose_right.json"),
                               str(EXAMPLES / "pose_left.json")],
                 "key_times": [0.0, 1.0, 2.0]} if animated else {}
    return {"strands_file": str(EXAMPLES / "pose_left.json"), "anchor_stiffness": stiffness,
            **keyframes}


TABLES = {
    "5.2": ("Table 5.2: screen resolution (thesis: 28 fps at each)", "resolution",
            [(f"{w}x{h}", {"size": (w, h)}) for w, h in ((800, 600), (1024, 768), (1366, 768))]),
    "5.1f": ("Fig. 5.1: strands (thesis: hundreds of fps for a few, 28 at 100, falling steeply "
             "past 150)", "strands",
             [(f"{n:,}", {"strands": n}) for n in (25, 50, 100, 150, 200, 400, 1000)]),
    "5.3": ("Table 5.3: hair sampling points x vertices a point, outline method (thesis fps: "
            "object 37, 28, 3; image 44, 32, 4; 32 x 32 here 32 x 16, the most sides a tube "
            "has)", "samples x sides, outline",
            [(f"{p} x {v}, {o}-space", {"samples": p, "sides": v, "outline": o})
             for o in ("object", "image") for p, v in ((6, 4), (8, 8), (32, 16))]),
    "5.4": ("Table 5.4: outline width (thesis fps: dilation 1: 32, 12: 23; stroke limit 0.1 "
            "and 1: 28 each; a dilation of 12 draws about what a stroke limit of 1 does)",
            "outline, width",
            [("image-space, width 1", {"outline": "image", "width": 1}),
             ("image-space, width 12", {"outline": "image", "width": 12}),
             ("object-space, stroke 1.2 px", {"outline": "object", "width": 1.2}),
             ("object-space, stroke 12 px", {"outline": "object", "width": 12.0})]),
    "5.5": ("Table 5.5: anchors and animation, anchored_head's 150 strands (thesis fps: 28, "
            "28, 26, 23-26, 23-26)", "anchor stiffness, skeleton, hair",
            [("0.01, still, still", {"turning": False, "anchors": anchors(0.01, False)}),
             ("0.01, turning, still", {"anchors": anchors(0.01, False)}),
             ("0.01, turning, animated", {"anchors": anchors(0.01, True)}),
             ("0, turning, animated", {"anchors": anchors(0.0, True)}),
             ("1, turning, animated", {"anchors": anchors(1.0, True)})]),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=5)
    parser.add_argument("--only", choices=sorted(TABLES), action="append")
    args = parser.parse_args()
    for key in args.only or TABLES:
        title, column, rows = TABLES[key]
        print(f"\n{title}\n\n| {column} | ms CPU | ms wall | fps (1000 / ms CPU) |\n"
              "|---|---:|---:|---:|")
        for label, change in rows:
            cpu, wall = timed(thesis_scene(**change), args.frames)
            print(f"| {label} | {cpu:.1f} | {wall:.1f} | {1000.0 / cpu:.1f} |", flush=True)


if __name__ == "__main__":
    main()
