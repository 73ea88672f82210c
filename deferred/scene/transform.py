"""Placements: a node's local transform (position, rotation, scale) and its matrix.

A local transform is ``T R S``: scale (one number or one per axis) first, then the rotation,
then the translation; a node's world matrix is its parent's world matrix times its own local
one (parent first). The rotation is Euler angles in degrees with an explicit order, or a unit
quaternion ``[x, y, z, w]``:

- ``rotation_order = "XYZ"`` (the default) turns about X first, then Y, then Z
  (``R = Rz Ry Rx``); ``"ZYX"`` turns about Z first (``R = Rx Ry Rz``); all six orders are
  taken. The axes are the parent's (extrinsic).
- ``quaternion`` replaces ``rotation`` (giving both is an error); it is normalised.

Matrices are numpy (4, 4) float64 acting on column vectors (``p' = M @ p``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

import numpy as np
from pydantic import ConfigDict, Field, field_validator, model_validator

from deferred.validation import StrictValues

Vec3 = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]
RotationOrder = Literal["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]
ROTATION_ORDERS: tuple[str, ...] = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")
MIN_SCALE = 1e-6  # an object smaller is a mistake of units; 1/scale must fit float32


def scale_too_small(scale: float | Sequence[float]) -> bool:
    """Whether a scale (one number or one per axis) is under ``MIN_SCALE`` in size on an axis:
    the one rule for a scene file's, a track key's and Python's placements."""
    return bool(np.any(np.abs(np.asarray(scale, dtype=float)) < MIN_SCALE))


def _axis_rotation(axis: str, degrees: float) -> np.ndarray:
    """(4, 4) counter-clockwise rotation about one axis (column vectors): pyrr's row-vector
    rotation by minus the angle, transposed, written out (pyrr's call checks its arguments at
    every call: most of an animated object's CPU time), bit for bit the same numbers."""
    theta = -math.radians(degrees)
    c, s = np.cos(theta), np.sin(theta)
    rotation = np.identity(4)
    if axis == "X":
        rotation[1:3, 1:3] = [[c, s], [-s, c]]
    elif axis == "Y":
        rotation[0, 0], rotation[0, 2], rotation[2, 0], rotation[2, 2] = c, -s, s, c
    else:
        rotation[0:2, 0:2] = [[c, s], [-s, c]]
    return rotation


def euler_matrix(rotation_degrees: Sequence[float], order: str = "XYZ") -> np.ndarray:
    """(4, 4) rotation: each angle (degrees, ``rotation_degrees`` is X, Y, Z) about its axis,
    the first of ``order`` applied first."""
    angles = dict(zip("XYZ", (float(v) for v in rotation_degrees), strict=True))
    first, second, third = order
    return _axis_rotation(third, angles[third]) @ _axis_rotation(second, angles[second]) @ \
        _axis_rotation(first, angles[first])


def quaternion_matrix(quaternion: Sequence[float]) -> np.ndarray:
    """(4, 4) rotation of the quaternion ``[x, y, z, w]`` (normalised first)."""
    x, y, z, w = np.asarray(quaternion, dtype=np.float64) / np.linalg.norm(quaternion)
    rotation = np.identity(4)
    rotation[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    return rotation


def model_matrix(position: Sequence[float], rotation_degrees: Sequence[float],
                 scale: float | Sequence[float], order: str = "XYZ",
                 quaternion: Sequence[float] | None = None) -> np.ndarray:
    """``T @ R @ S``: the rotation ``quaternion`` where given, else ``rotation_degrees`` in
    ``order`` (by default X first, then Y, then Z)."""
    rotation = quaternion_matrix(quaternion) if quaternion is not None else \
        euler_matrix(rotation_degrees, order)
    scale = np.broadcast_to(np.asarray(scale, dtype=np.float64), (3,))
    translation = np.identity(4)
    translation[:3, 3] = np.asarray(position, dtype=np.float64)
    return translation @ rotation @ np.diag([*scale, 1.0])


def decompose(model: np.ndarray) -> tuple[Vec3, Vec3, Vec3]:
    """(position, rotation in degrees X then Y then Z, scale) of a model matrix made as
    :func:`model_matrix` makes them (a shear is lost)."""
    model = np.asarray(model, dtype=np.float64)
    linear = model[:3, :3]
    scale = np.linalg.norm(linear, axis=0)
    scale = np.where(scale > 0.0, scale, 1.0)
    if np.linalg.det(linear) < 0.0:
        scale[0] = -scale[0]
    rot = linear / scale  # Rz @ Ry @ Rx
    sin_y = -float(np.clip(rot[2, 0], -1.0, 1.0))
    if abs(sin_y) < 1.0 - 1e-9:
        x = math.atan2(rot[2, 1], rot[2, 2])
        z = math.atan2(rot[1, 0], rot[0, 0])
    else:  # gimbal lock: X and Z turn about one axis; all of it is X's
        x = math.atan2(-rot[1, 2], rot[1, 1])
        z = 0.0
    y = math.asin(sin_y)
    return (tuple(float(v) for v in model[:3, 3]),
            tuple(math.degrees(v) for v in (x, y, z)),
            tuple(float(v) for v in scale))


def read_only(matrix: np.ndarray) -> np.ndarray:
    """``matrix`` as a contiguous float64 array that refuses writes (a value, not a buffer)."""
    matrix = np.array(matrix, dtype=np.float64)
    matrix.setflags(write=False)
    return matrix


def nonzero_quaternion(quaternion: Quaternion | None) -> Quaternion | None:
    """``quaternion`` if it can be a rotation (of length > 0): the placements' one rule."""
    if quaternion is not None and float(np.linalg.norm(quaternion)) < 1e-9:
        raise ValueError("is zero: a rotation needs a quaternion of length > 0 "
                         "([0, 0, 0, 1] is none)")
    return quaternion


def one_rotation(rotation: Vec3, quaternion: Quaternion | None) -> None:
    """A placement turns by Euler angles or by a quaternion, not both."""
    if quaternion is not None and any(rotation):
        raise ValueError("give rotation (Euler degrees) or quaternion, not both")


class Transform(StrictValues):
    """A node's local placement as a scene file gives it: finite numbers, a scale of at least
    ``MIN_SCALE`` on each axis (its normal matrix would overflow float32), a rotation as Euler
    degrees in ``rotation_order`` or as a quaternion (not both)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)
    position: Vec3 = (0.0, 0.0, 0.0)
    rotation: Vec3 = Field((0.0, 0.0, 0.0), description="Euler degrees, in rotation_order")
    rotation_order: RotationOrder = Field("XYZ", description="the axis turned about first, "
                                          "then the second, then the third (parent's axes)")
    quaternion: Quaternion | None = Field(None, description="[x, y, z, w] instead of rotation")
    scale: float | Vec3 = Field(1.0, description="one number, or one per axis")

    @field_validator("scale")
    @classmethod
    def _check_scale(cls, scale: float | Vec3) -> float | Vec3:
        if scale_too_small(scale):
            raise ValueError(f"must be at least {MIN_SCALE:g} in size on every axis")
        return scale

    @field_validator("quaternion")
    @classmethod
    def _check_quaternion(cls, quaternion: Quaternion | None) -> Quaternion | None:
        return nonzero_quaternion(quaternion)

    @model_validator(mode="after")
    def _one_rotation(self) -> Transform:
        one_rotation(self.rotation, self.quaternion)
        return self

    def matrix(self) -> np.ndarray:
        """The local matrix ``T R S``."""
        return model_matrix(self.position, self.rotation, self.scale, self.rotation_order,
                            self.quaternion)

    def with_values(self, values: dict) -> Transform:
        """This placement with some of ``position``, ``rotation``, ``scale`` replaced (a
        track's values at a time: a rotation key replaces a quaternion)."""
        if "rotation" in values and self.quaternion is not None:
            values = {**values, "quaternion": None}
        return self.model_copy(update=values)


IDENTITY = Transform()
