"""The split view's numbers: the difference of the two sides as PSNR (dB, on the 8-bit
images in [0, 1]; infinite when they are the same)."""

from __future__ import annotations

import math

import numpy as np


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    """PSNR of two uint8 images (RGB compared; alpha left out)."""
    a = np.asarray(a[..., :3], np.float64) / 255.0
    b = np.asarray(b[..., :3], np.float64) / 255.0
    mse = float(np.mean((a - b) ** 2))
    return math.inf if mse == 0.0 else 10.0 * math.log10(1.0 / mse)


def describe(value: float) -> str:
    return "identical" if math.isinf(value) else f"{value:.2f} dB"
