"""Tonal art map generation time against the rows of Costigan's Table 5.1 (6 tones x 3 mips;
the thesis' times on a 2011 Core i3 laptop), and the time to read a cached TAM back.

    python benchmarks/tam_bench.py [--runs N] [--png OUT.png]

Each row is generated ``--runs`` times (no cache); the table gives the median and the fastest
run. ``--png`` writes the default TAM (512x512, 6 tones x 3 mips, 78 strokes, 10 candidates): the
tones side by side, one row per mip level, ink dark on white.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from deferred.materials.techniques.hatching import TamSettings, generate_tam, tonal_art_map

# (size, strokes, candidates) -> the thesis' time in seconds (Table 5.1)
TABLE_5_1 = {
    (256, 78, 10): 18.0,
    (512, 78, 10): 65.0,
    (1024, 78, 10): 240.0,
    (512, 36, 10): 30.0,
    (512, 120, 10): 96.0,
    (512, 78, 1): 13.0,
    (512, 78, 20): 120.0,
}


def timed(function, runs: int) -> list[float]:
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return times


def contact_sheet(path: Path) -> None:
    from PIL import Image

    tam = generate_tam(TamSettings())
    gap = 4
    width = tam.tones * (tam.size + gap)
    rows = []
    for level in tam.levels:
        paper = 255 - level[:, ::-1]  # row 0 at v = 0: flipped to show v up
        row = np.full((level.shape[1] + gap, width), 160, np.uint8)
        for tone, image in enumerate(paper):
            x = tone * (tam.size + gap)
            row[:image.shape[0], x:x + image.shape[1]] = image
        rows.append(row)
    Image.fromarray(np.concatenate(rows)).save(path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--png", type=Path, default=None)
    args = parser.parse_args()
    print(f"{'size':>9} {'strokes':>7} {'cand.':>5} {'thesis s':>8} {'median s':>8} "
          f"{'min s':>7} {'speed-up':>8}")
    for (size, strokes, candidates), thesis in TABLE_5_1.items():
        settings = replace(TamSettings(), size=size, strokes=strokes, candidates=candidates)
        times = timed(lambda settings=settings: generate_tam(settings), args.runs)
        median = statistics.median(times)
        print(f"{size:>4}x{size:<4} {strokes:>7} {candidates:>5} {thesis:>8.0f} {median:>8.3f} "
              f"{min(times):>7.3f} {thesis / median:>7.0f}x")
    with tempfile.TemporaryDirectory() as folder:
        tonal_art_map(TamSettings(), cache=Path(folder))
        times = timed(lambda: tonal_art_map(TamSettings(), cache=Path(folder)), args.runs)
    print(f"cached 512x512 TAM read back: median {statistics.median(times) * 1000:.1f} ms")
    if args.png:
        contact_sheet(args.png)
        print(f"wrote {args.png}")


if __name__ == "__main__":
    main()
