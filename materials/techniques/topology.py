"""Mesh topology the techniques share: vertices welded by position, so a mesh split at its UV
seams (each seam vertex stored once per chart) is one surface to fins, strands and clumps."""

from __future__ import annotations

import numpy as np


def weld(positions: np.ndarray, tolerance: float = 1e-6) -> np.ndarray:
    """Index of each vertex's position group (vertices split at UV seams share one)."""
    keys = np.round(np.asarray(positions, np.float64) / tolerance).astype(np.int64)
    _, welded = np.unique(keys, axis=0, return_inverse=True)
    return welded.reshape(-1)
