"""The viewer's camera controller: orbit, pan and zoom about a target, a fly mode, and a reset
to the scene's camera.

The controller keeps yaw, pitch and distance about a target (the orbit's parameters) and makes
a :class:`~deferred.scene.camera.Camera` from them; untouched (or just reset) it hands back the
scene's own camera object, so a frame of the viewer is the frame ``deferred render`` draws.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from deferred.scene.camera import Camera

ORBIT_DEGREES_PER_PIXEL = 0.3
ZOOM_STEP = 0.9  # the distance is multiplied by this per wheel step
FLY_UNITS_PER_SECOND = 1.5  # of the orbit's distance at reset
MAX_PITCH = 89.0


class CameraController:
    """Orbit / pan / zoom (and fly) about the camera's target, ``up`` as the vertical."""

    def __init__(self, camera: Camera):
        self.home = camera
        self.fly = False
        self.reset()

    def reset(self, camera: Camera | None = None) -> None:
        """Back to ``camera`` (default: the camera the controller started from)."""
        if camera is not None:
            self.home = camera
        home = self.home
        self.up = _unit(np.asarray(home.up, dtype=np.float64))
        self.target = np.asarray(home.target, dtype=np.float64)
        offset = np.asarray(home.position, dtype=np.float64) - self.target
        self.distance = float(np.linalg.norm(offset))
        self.yaw, self.pitch = self._angles(offset / self.distance)
        self.home_distance = self.distance
        self._moved = False

    @property
    def moved(self) -> bool:
        """Whether the camera differs from the one reset to."""
        return self._moved

    def _basis(self) -> tuple[np.ndarray, np.ndarray]:
        """Two unit vectors spanning the plane normal to ``up`` (yaw 0 is along the first)."""
        helper = np.array([0.0, 0.0, 1.0]) if abs(self.up[2]) < 0.9 else np.array([1.0, 0, 0])
        first = _unit(helper - self.up * np.dot(helper, self.up))
        return first, np.cross(self.up, first)

    def _angles(self, direction: np.ndarray) -> tuple[float, float]:
        first, second = self._basis()
        height = float(np.clip(np.dot(direction, self.up), -1.0, 1.0))
        pitch = math.degrees(math.asin(height))
        yaw = math.degrees(math.atan2(float(np.dot(direction, second)),
                                      float(np.dot(direction, first))))
        return yaw, pitch

    def _direction(self) -> np.ndarray:
        """Unit vector from the target to the eye."""
        first, second = self._basis()
        yaw, pitch = math.radians(self.yaw), math.radians(self.pitch)
        return (math.cos(pitch) * (math.cos(yaw) * first + math.sin(yaw) * second)
                + math.sin(pitch) * self.up)

    def camera(self) -> Camera:
        """The camera as the controller has it (the home camera itself when not moved)."""
        if not self._moved:
            return self.home
        position = self.target + self.distance * self._direction()
        return replace(self.home, position=tuple(float(v) for v in position),
                       target=tuple(float(v) for v in self.target))

    # -- gestures --------------------------------------------------------------------------------
    def orbit(self, dx: float, dy: float) -> None:
        """Turn by a mouse drag of (dx, dy) pixels: about the target (fly mode: about the eye)."""
        if dx == 0 and dy == 0:
            return
        eye = self.target + self.distance * self._direction()
        self.yaw -= dx * ORBIT_DEGREES_PER_PIXEL
        self.pitch = float(np.clip(self.pitch + dy * ORBIT_DEGREES_PER_PIXEL,
                                   -MAX_PITCH, MAX_PITCH))
        if self.fly:  # the eye stays, the target swings round it
            self.target = eye - self.distance * self._direction()
        self._moved = True

    def pan(self, dx: float, dy: float, viewport_height: int) -> None:
        """Slide the target and the eye by a drag of (dx, dy) pixels: the point under the mouse
        at the target's depth follows it."""
        if dx == 0 and dy == 0:
            return
        forward = -self._direction()
        right = _unit(np.cross(forward, self.up))
        up = np.cross(right, forward)
        per_pixel = 2.0 * self.distance * math.tan(math.radians(self.home.fov) / 2.0) / \
            max(viewport_height, 1)
        self.target = self.target - right * dx * per_pixel + up * dy * per_pixel
        self._moved = True

    def zoom(self, steps: float) -> None:
        """Move toward the target by wheel ``steps`` (positive: closer); never onto it."""
        if steps == 0:
            return
        near = self.home.near * 2.0
        self.distance = max(self.distance * ZOOM_STEP ** steps, near)
        self._moved = True

    def fly_move(self, forward: float, right: float, up: float, seconds: float) -> None:
        """Fly mode's keys: move the eye and the target together, in units of the home
        distance per second."""
        if forward == right == up == 0:
            return
        ahead = -self._direction()
        side = _unit(np.cross(ahead, self.up))
        step = FLY_UNITS_PER_SECOND * self.home_distance * seconds
        self.target = self.target + (ahead * forward + side * right + self.up * up) * step
        self._moved = True


def _unit(vector: np.ndarray) -> np.ndarray:
    return vector / np.linalg.norm(vector)
