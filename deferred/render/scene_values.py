"""The values a scene holds itself, checked as a scene file's are (a scene built or changed in
Python skips the loader)."""

from __future__ import annotations

import math

import numpy as np

from deferred.errors import InputError
from deferred.names import ENVIRONMENT_BACKGROUND
from deferred.params import validate_params
from deferred.render.pipeline import TONEMAPS
from deferred.scene.camera import CameraModel, camera_values
from deferred.scene.scene import Scene


def check_scene_values(scene: Scene) -> None:
    """The scene's own values as a scene file's are checked (a scene built or changed in
    Python skips the loader): the camera, the tone mapping operator, the background and the
    exposure; ``InputError`` naming the attribute."""
    validate_params(CameraModel, camera_values(scene.camera), "camera")
    if scene.tonemap not in TONEMAPS:
        raise InputError(f"unknown tone mapping operator {scene.tonemap!r} (choose from "
                         f"{', '.join(TONEMAPS)})", "tonemap")
    if isinstance(scene.background, str):
        if scene.background != ENVIRONMENT_BACKGROUND:
            raise InputError(f"expected three numbers or \"environment\", got "
                             f"{scene.background!r}", "background")
        if not any(light.name == ENVIRONMENT_BACKGROUND for light in scene.lights):
            raise InputError("\"environment\" shows the environment light's map: add a light "
                             "of type \"environment\"", "background")
    else:
        background = np.asarray(scene.background, dtype=np.float64)
        if background.shape != (3,) or not np.all(np.isfinite(background)) or \
                np.any(background < 0):
            raise InputError(f"expected three finite numbers >= 0, got {scene.background!r}",
                             "background")
    if not (isinstance(scene.exposure, float | int) and math.isfinite(scene.exposure) and
            scene.exposure > 0.0):
        raise InputError(f"expected a finite number > 0, got {scene.exposure!r}", "exposure")
