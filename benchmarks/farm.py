"""A sequence rendered by one process against worker processes (``deferred render --workers``):
the wall time of each, in interleaved rounds (one process, then --workers 1, then --workers 2,
each round in a shuffled order), each run a fresh ``deferred render`` command whose frames are
compared with the one process's (byte-identical or the run fails).

    python benchmarks/farm.py [SCENE] [--frames 48] [--size 640x360] [--rounds 3]

Prints per configuration the median wall time and spread, frames per second, and the overhead
against one process per frame: (wall - wall of one process) / frames, and as a share of one
process's time per frame.
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


def render(scene: str | None, frames: int, size: str, extra: list[str], out: Path) -> float:
    out.mkdir()
    command = [sys.executable, "-m", "deferred", "render", *([scene] if scene else []),
               "--frames", str(frames), "--size", size, "-o", str(out / "f_####.png"), *extra]
    start = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    return time.perf_counter() - start


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
    order = random.Random(40)
    with tempfile.TemporaryDirectory() as folder:
        for round_index in range(args.rounds):
            names = list(CONFIGS)
            order.shuffle(names)
            reference = None
            for name in names:
                out = Path(folder) / f"{round_index}-{name.replace(' ', '_')}"
                walls[name].append(render(args.scene, args.frames, args.size, CONFIGS[name],
                                          out))
                frames = frames_of(out)
                if reference is None:
                    reference = frames
                elif frames != reference:
                    raise SystemExit(f"{name}: frames differ from the round's first run")
                print(f"round {round_index + 1}: {name}: {walls[name][-1]:.1f} s", flush=True)
    base = statistics.median(walls["one process"])
    print(f"\n{args.scene or 'the demo'}, {args.frames} frames at {args.size}, "
          f"{args.rounds} rounds")
    print("| run | wall s (median, min-max) | frames/s | overhead per frame vs one process |")
    print("|---|---|---|---|")
    for name, times in walls.items():
        median = statistics.median(times)
        per_frame = (median - base) / args.frames
        print(f"| {name} | {median:.1f} ({min(times):.1f}-{max(times):.1f}) | "
              f"{args.frames / median:.2f} | {per_frame * 1000:+.0f} ms "
              f"({per_frame / (base / args.frames):+.0%}) |")


if __name__ == "__main__":
    main()
