"""Write a word into a shell_fur wetness mask (Silva et al. Fig. 12 (c): "CGI10" on a furry
square). The text is rasterised with matplotlib's Agg canvas; the letters are covered by a grid
of small clumps, each texel inside a letter taking its grid cell's clump: (R, G) the cell centre
in UV, B the clump radius in UV (the cell's half diagonal and a little more, so every texel of
the cell lies inside its clump), A wetness 1. Texels outside the letters are dry (all zero).

The image is top row first, and its top row is v = 1 (``load_wetness_mask``): on
``builtin:plane`` (v = 1 at -z) the word reads left to right from a camera on +z looking at -z.
It is written as a float EXR (R, G, B, A) with ``deferred.io.images.write_image``.

Run from the repository root: python examples/shell_fur/word_mask.py [TEXT] [-o OUT.exr]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from deferred.io.images import write_image  # noqa: E402

HERE = Path(__file__).parent


def text_coverage(text: str, size: int, fit: float = 0.88, tallest: float = 0.4) -> np.ndarray:
    """(size, size) coverage in [0, 1] of ``text`` in bold sans, centred, as large as fits in
    ``fit`` of the width and ``tallest`` of the height; top row first."""
    figure = Figure(figsize=(size / 100.0, size / 100.0), dpi=100, facecolor="black")
    canvas = FigureCanvasAgg(figure)
    label = figure.text(0.5, 0.5, text, color="white", fontsize=100.0, fontweight="bold",
                        family="DejaVu Sans", ha="center", va="center")
    extent = label.get_window_extent(canvas.get_renderer())
    label.set_fontsize(100.0 * min(fit * size / extent.width, tallest * size / extent.height))
    canvas.draw()
    rgba = np.asarray(canvas.buffer_rgba(), dtype=np.float32) / 255.0
    coverage = rgba[..., 0]
    if coverage.shape != (size, size):
        raise RuntimeError(f"canvas is {coverage.shape}, expected {(size, size)}")
    return coverage


def word_mask(text: str, size: int = 512, cells: int = 64) -> np.ndarray:
    """(size, size, 4) float32 wetness mask image (top row first, top row v = 1): the letters of
    ``text`` covered by clumps on a ``cells`` x ``cells`` grid over the UV square."""
    inside = text_coverage(text, size) > 0.5
    rows, cols = np.indices((size, size))
    u = (cols + 0.5) / size
    v = 1.0 - (rows + 0.5) / size  # the top row is v = 1
    cell = 1.0 / cells
    centre_u = (np.floor(u / cell) + 0.5) * cell
    centre_v = (np.floor(v / cell) + 0.5) * cell
    image = np.zeros((size, size, 4), np.float32)
    image[..., 0] = np.where(inside, centre_u, 0.0)
    image[..., 1] = np.where(inside, centre_v, 0.0)
    image[..., 2] = np.where(inside, 0.75 * cell, 0.0)  # > half diagonal (0.707 cell)
    image[..., 3] = np.where(inside, 1.0, 0.0)
    return image


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("text", nargs="?", default="CGI10")
    parser.add_argument("-o", "--output", type=Path, default=HERE / "word_mask.exr")
    parser.add_argument("--size", type=int, default=512, help="texels per side")
    parser.add_argument("--cells", type=int, default=64, help="clumps per side of the grid")
    args = parser.parse_args()
    image = word_mask(args.text, args.size, args.cells)
    write_image(args.output, image, channels=("R", "G", "B", "A"))
    wet = float((image[..., 3] > 0).mean())
    print(f"wrote {args.output} ({args.size}x{args.size}, '{args.text}', {wet:.1%} wet)")


if __name__ == "__main__":
    main()
