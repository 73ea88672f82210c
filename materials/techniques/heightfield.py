"""The fur heightfield (Revie 2.4.1): strand heights the shells fade against.

Each texel holds the height (0..1 of the fur layer) a strand reaches there. The procedural one is
a jittered grid of tapered strands: a cone per cell, so a shell at depth ``s`` shows a strand's
cross-section shrinking toward its tip. It tiles (the shells sample it at ``density`` x UV).
"""

from __future__ import annotations

from pathlib import Path

import moderngl
import numpy as np

from deferred.imageio import read_image


def procedural_heightfield(size: int = 256, cells: int = 32, seed: int = 1,
                           min_length: float = 0.55, radius: float = 0.45) -> np.ndarray:
    """(size, size) float32 strand heights in [0, 1], seamless, deterministic for a seed."""
    rng = np.random.default_rng(seed)
    cell = size / cells
    jitter = rng.uniform(0.2, 0.8, (cells, cells, 2))
    lengths = rng.uniform(min_length, 1.0, (cells, cells))
    y, x = np.mgrid[0:size, 0:size].astype(np.float64) + 0.5
    height = np.zeros((size, size))
    # Each texel looks at its own cell and the 8 around it (wrapping, so the tile is seamless).
    cy, cx = (y // cell).astype(int), (x // cell).astype(int)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            ny, nx = (cy + dy) % cells, (cx + dx) % cells
            sy = (cy + dy + jitter[ny, nx, 0]) * cell
            sx = (cx + dx + jitter[ny, nx, 1]) * cell
            distance = np.hypot(y - sy, x - sx) / (radius * cell)
            height = np.maximum(height, lengths[ny, nx] * np.clip(1.0 - distance, 0.0, 1.0))
    return height.astype(np.float32)


def heightfield_texture(ctx: moderngl.Context, heights: np.ndarray) -> moderngl.Texture:
    heights = np.ascontiguousarray(heights[::-1], dtype=np.float32)  # GL rows bottom-up
    texture = ctx.texture((heights.shape[1], heights.shape[0]), 1, heights.tobytes(), dtype="f4")
    texture.repeat_x = texture.repeat_y = True
    # No mipmaps on purpose: shells threshold the height, and averaged heights fall below the
    # threshold, so minified fur would go bald instead of anti-aliased.
    texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
    return texture


def load_heightfield(path: Path) -> np.ndarray:
    """First channel of an image as heights (values are used as stored: no sRGB decoding)."""
    return read_image(path)[..., 0]
