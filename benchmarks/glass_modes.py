"""The glass scene (benchmarks/glass.toml) timed as ``deferred bench`` times it, in both of the
glass's modes: every glass object's ``mode`` set to ``wboit`` and then to ``exact``, each a
sweep of light counts through every light path of both pipelines. Writes
``benchmarks/results/glass-MODE-WxH.csv`` and prints the median frame times as the table in
benchmarks/README.md ("Glass"). Run from the repository root:

    python benchmarks/glass_modes.py [--size 640x360] [--lights 16,256] [--runs 3]
                                     [--modes wboit,exact]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from deferred.bench.harness import Sweep, run_bench
from deferred.bench.report import BenchReport, write_csv
from deferred.scene.loader import scene_from_dict
from deferred.validation import parse_toml

SCENE = Path("benchmarks/glass.toml")
PATHS = [("deferred", "volumes"), ("deferred", "tiled"), ("deferred", "clustered"),
         ("forward", "naive"), ("forward", "tiled")]


def glass_scene(mode: str):
    """benchmarks/glass.toml with every glass object in ``mode``."""
    data = parse_toml(SCENE.read_text(), str(SCENE))
    for obj in data["object"]:
        if obj.get("material") == "glass":
            obj.setdefault("params", {})["mode"] = mode
    return scene_from_dict(data, str(SCENE), SCENE.parent)


def table(reports: dict[str, BenchReport]) -> str:
    """Median ms a frame: a row a mode and light count, a column a light path."""
    lines = ["| mode | extra lights | " + " | ".join(
                 f"{pipeline} {path}" for pipeline, path in PATHS) + " |",
             "|---|---:|" + "---:|" * len(PATHS)]
    for mode, report in reports.items():
        for lights in sorted({r.lights for r in report.results}):
            medians = {(r.pipeline, r.light_path): r.median_ms for r in report.results
                       if r.lights == lights}
            cells = [f"{medians[key]:.1f}" if key in medians else "-" for key in PATHS]
            lines.append(f"| {mode} | {lights} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--lights", default="16,256")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--warmup", type=int, default=1)
    parser.add_argument("--modes", default="wboit,exact")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    sweep = Sweep(lights=[int(v) for v in args.lights.split(",")], shells=[0],
                  size=(width, height), runs=args.runs, warmup=args.warmup)
    reports = {}
    for mode in args.modes.split(","):
        reports[mode] = run_bench(glass_scene(mode), sweep, note=print)
        write_csv(reports[mode], Path("benchmarks/results") / f"glass-{mode}-{args.size}.csv")
        print(f"{mode} done", flush=True)
    print(table(reports))


if __name__ == "__main__":
    main()
