"""Keyframed poses of cartoon hair blended shape by shape (Costigan 4.2.3: the anchors move
along a spline through the keyframes): :class:`PolylineShapes` holds each pose's bends and
lengths, :func:`interpolate_shapes` lays the pose at a time from them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .hair_strands import interpolate_keyframes, unit_vectors


@dataclass(frozen=True)
class PolylineShapes:
    """Keyframed polylines ``(K, S, N, 3)`` as what :func:`interpolate_shapes` blends: each
    polyline's first point ``(K, S, 1, 3)``, its first segment's direction and the normal of
    its frame there ``(K, S, 3)`` each, and every later segment's direction in the frame of the
    segment before it ``(K, S, N - 2, 3)`` (the frames carried along the polyline by the
    smallest rotation from each segment to the next: parallel transport), and the segments'
    lengths ``(K, S, N - 1, 1)``."""

    starts: np.ndarray
    first: np.ndarray
    normal: np.ndarray
    bends: np.ndarray
    lengths: np.ndarray

    @classmethod
    def of(cls, keyframes: np.ndarray) -> PolylineShapes:
        keyframes = np.asarray(keyframes, dtype=np.float64)
        segments = np.diff(keyframes, axis=2)
        lengths = np.linalg.norm(segments, axis=-1, keepdims=True)
        directions = segments / np.maximum(lengths, 1e-30)
        first = directions[:, :, 0]
        # one normal for every pose of a strand: the first pose's least axis, made normal
        axis = np.eye(3)[np.abs(first[0]).argmin(axis=-1)]
        normal = unit_vectors(axis - (axis * first).sum(-1, keepdims=True) * first)
        bends = np.empty(directions[:, :, 1:].shape)
        here, across = first, normal
        for i in range(directions.shape[2] - 1):
            following = directions[:, :, i + 1]
            binormal = np.cross(here, across)
            bends[:, :, i] = np.stack([(following * e).sum(-1) for e in (here, across, binormal)],
                                      axis=-1)
            across = _transport(across, here, following)
            here = following
        return cls(keyframes[:, :, :1], first, normal, bends, lengths)


def _transport(vectors: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """``vectors`` (..., 3) turned by the smallest rotation taking the unit ``start`` to the
    unit ``end`` (for opposite ones, whose rotation is not one, a half turn about the vector
    itself's plane: it is left as it is)."""
    middle = start + end
    along = 1.0 + (start * end).sum(-1, keepdims=True)
    turned = vectors - (vectors * middle).sum(-1, keepdims=True) / np.maximum(along, 1e-12) * \
        middle + 2.0 * (vectors * start).sum(-1, keepdims=True) * end
    return np.where(along > 1e-9, turned, vectors)


def interpolate_shapes(shapes: PolylineShapes, key_times: np.ndarray, time: float) -> np.ndarray:
    """The polylines ``(S, N, 3)`` at ``time`` between keyframed poses, shape by shape: the
    first point, the first segment's direction and frame, each later segment's bend in the frame
    of the one before (:class:`PolylineShapes`) and the lengths, each on
    :func:`interpolate_keyframes`' Catmull-Rom spline in time (directions made unit again), and
    the polyline laid segment after segment. Positions blended point by point shorten a
    strand's segments where its poses disagree (a strand combed left and combed right is,
    halfway, a stub through the head, which collisions and springs fold into kinks); bends
    blended in each segment's own frame keep every pose on the way as bent as the poses are
    at most (halfway between combed left and combed right the strand stands up)."""
    def unit_spline(values: np.ndarray) -> np.ndarray:
        blended = interpolate_keyframes(values, key_times, time)
        norm = np.linalg.norm(blended, axis=-1, keepdims=True)
        # opposite values in two poses cancel: the nearest key's there
        nearest = values[int(np.abs(np.asarray(key_times) - time).argmin())]
        return np.where(norm > 1e-6, blended / np.maximum(norm, 1e-30), nearest)

    start = interpolate_keyframes(shapes.starts, key_times, time)
    here = unit_spline(shapes.first)
    across = unit_spline(shapes.normal)
    across = unit_vectors(across - (across * here).sum(-1, keepdims=True) * here)
    bends = unit_spline(shapes.bends)
    lengths = interpolate_keyframes(shapes.lengths, key_times, time)
    directions = [here]
    for i in range(bends.shape[1]):
        binormal = np.cross(here, across)
        following = (bends[:, i, :1] * here + bends[:, i, 1:2] * across +
                     bends[:, i, 2:] * binormal)
        across = _transport(across, here, following)
        here = following
        directions.append(here)
    steps = np.stack(directions, axis=1) * lengths
    return np.concatenate([start, start + np.cumsum(steps, axis=1)], axis=1)
