"""Clumps of cartoon hair (Costigan 3.1: each guide strand stands for a clump of hair, and
strands that run together read as one lock): k-means clusters of the strands' shapes, which
the edges effect outlines as one (cartoon_hair's G-buffer datum ``strand_id``)."""

from __future__ import annotations

import numpy as np

CLUMP_ROUNDS = 12  # k-means rounds: clumps settle in a few; they are outlines, not physics
# strand-to-centre distances a clumping computes at most: a round costs strands x clumps, which
# grows with the square of the strands (20,000 strands of clumps of 6 are 67 million a round),
# so past this the rounds stop early and the clumps stay nearer the first assignment's (each
# strand to its nearest of the random seed strands)
CLUMP_WORK = 50_000_000


def strand_clumps(strands: np.ndarray, clump_size: int, seed: int = 0) -> np.ndarray:
    """``(S,)`` int: the clump of each strand ``(S, P, 3)``, about ``clump_size`` strands a
    clump, 0 ... clumps - 1, deterministic for ``seed``. Clumps are k-means clusters of the
    strands' shapes (root, middle and tip: strands that run together, as a grown spiky clump's
    do to their shared tip), so a clump is found in hair from a file too. ``clump_size`` 1:
    every strand its own clump."""
    strands = np.asarray(strands, np.float64)
    count = len(strands)
    clumps = max(1, int(round(count / max(int(clump_size), 1))))
    if clumps >= count:
        return np.arange(count)
    features = strands[:, [0, strands.shape[1] // 2, -1]].reshape(count, -1)
    rng = np.random.default_rng(seed)
    centres = features[np.sort(rng.choice(count, size=clumps, replace=False))]
    member = nearest_centre(features, centres)
    rounds = min(CLUMP_ROUNDS, CLUMP_WORK // (count * clumps) - 1)
    for _ in range(rounds):
        sums = np.zeros_like(centres)
        np.add.at(sums, member, features)
        sizes = np.bincount(member, minlength=clumps)[:, None]
        # an emptied clump keeps its centre (it may win strands back)
        centres = np.where(sizes > 0, sums / np.maximum(sizes, 1), centres)
        updated = nearest_centre(features, centres)
        if np.array_equal(updated, member):
            break
        member = updated
    # numbered by first strand, so a clump's number does not depend on the centres' order
    _, first, inverse = np.unique(member, return_index=True, return_inverse=True)
    return np.argsort(np.argsort(first))[inverse]


def nearest_centre(points: np.ndarray, centres: np.ndarray, block: int = 1024) -> np.ndarray:
    """The index of the nearest centre of each point, in blocks of points: a matrix product
    a block (many centres of many coordinates: k-means over strands)."""
    out = np.empty(len(points), dtype=np.int64)
    squares = (centres * centres).sum(axis=1)
    for start in range(0, len(points), block):
        part = points[start:start + block]
        # |p - c|^2 less |p|^2, the same for every centre: a matrix product, not a difference
        # array of points x centres x coordinates
        out[start:start + block] = (squares[None, :] - 2.0 * part @ centres.T).argmin(axis=1)
    return out
