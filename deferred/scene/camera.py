"""Perspective camera and transform helpers (pyrr builds the matrices; column-vector convention).

Matrices here are numpy (4, 4) arrays acting on column vectors (``p' = M @ p``). GLSL wants them
column-major, which is ``M.T`` in numpy's row-major memory: use :func:`gl_bytes`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pyrr

from deferred.memo import kept_while


def gl_bytes(matrix: np.ndarray) -> bytes:
    """Bytes of a column-vector matrix in the column-major order GLSL expects."""
    return np.ascontiguousarray(np.asarray(matrix, dtype=np.float32).T).tobytes()


def model_matrix(position, rotation_degrees, scale) -> np.ndarray:
    """Translation @ Rz @ Ry @ Rx @ Scale: rotations are applied X first, then Y, then Z."""
    rx, ry, rz = np.radians(np.asarray(rotation_degrees, dtype=np.float64))
    rot = (pyrr.matrix44.create_from_z_rotation(-rz).T
           @ pyrr.matrix44.create_from_y_rotation(-ry).T
           @ pyrr.matrix44.create_from_x_rotation(-rx).T)
    scale = np.broadcast_to(np.asarray(scale, dtype=np.float64), (3,))
    translation = pyrr.matrix44.create_from_translation(np.asarray(position, dtype=np.float64)).T
    return translation @ rot @ np.diag([*scale, 1.0])


@dataclass(frozen=True)
class Camera:
    position: tuple[float, float, float] = (0.0, 1.0, 4.0)
    target: tuple[float, float, float] = (0.0, 0.5, 0.0)
    up: tuple[float, float, float] = (0.0, 1.0, 0.0)
    fov: float = 45.0  # vertical, degrees
    near: float = 0.05
    far: float = 100.0

    # The camera is frozen, so its matrices are made once (pyrr's look-at alone was 8% of a
    # frame's Python time on a small scene) and handed out read-only.
    @kept_while()
    def view(self) -> np.ndarray:
        return _read_only(pyrr.matrix44.create_look_at(
            np.array(self.position, dtype=np.float64), np.array(self.target, dtype=np.float64),
            np.array(self.up, dtype=np.float64)).T)

    @kept_while()
    def projection(self, aspect: float) -> np.ndarray:
        return _read_only(pyrr.matrix44.create_perspective_projection(
            self.fov, aspect, self.near, self.far, dtype=np.float64).T)

    @kept_while()
    def inverse_projection(self, aspect: float) -> np.ndarray:
        return _read_only(np.linalg.inv(self.projection(aspect)))

    def pulled_back(self, factor: float) -> Camera:
        """This camera ``factor`` times as far from its target, looking the same way."""
        target = np.asarray(self.target, np.float64)
        position = target + factor * (np.asarray(self.position, np.float64) - target)
        return replace(self, position=tuple(float(v) for v in position))


def _read_only(matrix: np.ndarray) -> np.ndarray:
    matrix = np.ascontiguousarray(matrix)
    matrix.setflags(write=False)
    return matrix
