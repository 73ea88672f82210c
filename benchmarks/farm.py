"""A sequence rendered by one process against worker processes (``deferred render --workers``):
the wall time of each, in interleaved rounds (one process, then --workers 1, then --workers 2,
each round in a shuffled order), each run a fresh ``deferred render`` command whose frames are
compared with the one process's (byte-identical or the run fails).

    python benchmarks/farm.py [SCENE] [--frames 48] [--size 640x360] [--rounds 3]

Prints per configuration the median wall time and spread, frames per second, the overhead
against one process per frame ((wall - wall of one process) / frames, and as a share of one
process's time per frame), and, from the frames' modification times, the time to the first
frame (starting, loading, compiling) and the steady time between frames after it, which is
where a per-frame cost of the distribution (encoding in the worker, the pipe, the driver's
write and manifest line) shows apart from the fixed cost of starting workers.
"""

from __future__ import annotations

import argparse
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CONFIGS = {"one process": [], "--workers 1": ["--workers", "1"],
           "--workers 2": ["--workers", "2"]}


def render(scene: str | None, frames: int, size: str, extra: list[str],
           out: Path) -> tuple[float, float, float]:
    """(wall s, s to the first frame, s a frame after it), from the files' times."""
    out.mkdir()
    command = [sys.executable, "-m", "deferred", "render", *([scene] if scene else []),
               "--frames", str(frames), "--size", size, "-o", str(out / "f_####.png"), *extra]
    started = time.time()
    start = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    wall = time.perf_counter() - start
    times = sorted(path.stat().st_mtime for path in out.glob("f_*.png"))
    return wall, times[0] - started, (times[-1] - times[0]) / max(len(times) - 1, 1)


def frames_of(folder: Path) -> dict[str, bytes]:
    return {path.name: path.read_bytes() for path in sorted(folder.glob("f_*.png"))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?")
    parser.add_argument("--frames", type=int, default=48)
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    walls: dict[str, list[float]] = {name: [] for name in CONFIGS}
    firsts: dict[str, list[float]] = {name: [] for name in CONFIGS}
    steady: dict[str, list[float]] = {name: [] for name in CONFIGS}
    order = random.Random(40)
    with tempfile.TemporaryDirectory() as folder:
        for round_index in range(args.rounds):
            names = list(CONFIGS)
            order.shuffle(names)
            reference = None
            for name in names:
                out = Path(folder) / f"{round_index}-{name.replace(' ', '_')}"
                wall, first, each = render(args.scene, args.frames, args.size, CONFIGS[name],
                                           out)
                walls[name].append(wall)
                firsts[name].append(first)
                steady[name].append(each)
                frames = frames_of(out)
                if reference is None:
                    reference = frames
                elif frames != reference:
                    raise SystemExit(f"{name}: frames differ from the round's first run")
                print(f"round {round_index + 1}: {name}: {wall:.1f} s, first frame at "
                      f"{first:.1f} s, then {each:.2f} s a frame", flush=True)
    base = statistics.median(walls["one process"])
    print(f"\n{args.scene or 'the demo'}, {args.frames} frames at {args.size}, "
          f"{args.rounds} rounds")
    print("| run | wall s (median, min-max) | frames/s | overhead per frame vs one process | "
          "first frame s | s a frame after it |")
    print("|---|---|---|---|---|---|")
    for name, times in walls.items():
        median = statistics.median(times)
        per_frame = (median - base) / args.frames
        print(f"| {name} | {median:.1f} ({min(times):.1f}-{max(times):.1f}) | "
              f"{args.frames / median:.2f} | {per_frame * 1000:+.0f} ms "
              f"({per_frame / (base / args.frames):+.0%}) | "
              f"{statistics.median(firsts[name]):.1f} | {statistics.median(steady[name]):.2f} |")


if __name__ == "__main__":
    main()
