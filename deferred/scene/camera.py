"""The perspective camera (pyrr builds the matrices; column-vector convention) and its checks.

Matrices here are numpy (4, 4) arrays acting on column vectors (``p' = M @ p``). GLSL wants them
column-major, which is ``M.T`` in numpy's row-major memory: use :func:`gl_bytes`. A camera may
name a ``parent`` node: its position, target and up are then in that node's space, and each
frame's state holds the camera placed in the world (``deferred.scene.timeline.camera_at``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pyrr
from pydantic import ConfigDict, Field, model_validator

from deferred.memo import kept_while
from deferred.scene.transform import model_matrix  # noqa: F401 - where it was first found
from deferred.validation import StrictValues

Vec3 = tuple[float, float, float]
MAX_DEPTH_RANGE = 1e7  # far / near


def gl_bytes(matrix: np.ndarray) -> bytes:
    """Bytes of a column-vector matrix in the column-major order GLSL expects."""
    return np.ascontiguousarray(np.asarray(matrix, dtype=np.float32).T).tobytes()


@dataclass(frozen=True)
class Camera:
    position: tuple[float, float, float] = (0.0, 1.0, 4.0)
    target: tuple[float, float, float] = (0.0, 0.5, 0.0)
    up: tuple[float, float, float] = (0.0, 1.0, 0.0)
    fov: float = 45.0  # vertical, degrees
    near: float = 0.05
    far: float = 100.0
    # a node (or its label) whose space position, target and up are in; None: the world
    parent: Any = None

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


def camera_values(camera: Camera) -> dict[str, Any]:
    """The camera's checked values (what :class:`CameraModel` validates), without its parent."""
    return {"position": camera.position, "target": camera.target, "up": camera.up,
            "fov": camera.fov, "near": camera.near, "far": camera.far}


class CameraModel(StrictValues):
    """A scene file's ``[camera]``, checked (the loader's, and every camera the tracks make)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    position: Vec3 = (0.0, 1.0, 4.0)
    target: Vec3 = (0.0, 0.5, 0.0)
    up: Vec3 = (0.0, 1.0, 0.0)
    fov: float = Field(45.0, gt=1.0, lt=179.0, description="vertical field of view, degrees")
    near: float = Field(0.05, gt=0.0)
    far: float = Field(100.0, gt=0.0)

    @model_validator(mode="after")
    def _check(self) -> CameraModel:
        if self.far <= self.near:
            raise ValueError("far must be greater than near")
        if self.far / self.near > MAX_DEPTH_RANGE:
            # measured: at 1e8 the deferred pipeline's depth reconstruction loses the scene
            raise ValueError(f"far / near is {self.far / self.near:.3g}; at most "
                             f"{MAX_DEPTH_RANGE:g} (the depth buffer's precision): raise near "
                             "or lower far")
        if np.allclose(self.position, self.target):
            raise ValueError("position and target are the same point")
        forward = np.subtract(self.target, self.position, dtype=float)
        side = np.cross(forward / np.linalg.norm(forward), np.asarray(self.up, dtype=float))
        if np.linalg.norm(side) < 1e-6:
            raise ValueError("up is parallel to the view direction (or zero); "
                             "choose another up vector")
        return self
