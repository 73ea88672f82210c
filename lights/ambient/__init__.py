"""Ambient hemisphere light: sky colour above, ground colour below (full-screen, diffuse only)."""

from __future__ import annotations

import numpy as np
from pydantic import Field

from deferred.api import (
    Light,
    LightParams,
    LightVolume,
    NonZeroVec3,
    Radiance,
    lights,
    view_direction,
)


class AmbientParams(LightParams):
    color: Radiance = Field((0.3, 0.35, 0.45), description="sky colour, linear RGB >= 0")
    ground: Radiance = Field((0.1, 0.08, 0.06), description="ground colour, linear RGB >= 0")
    up: NonZeroVec3 = Field((0.0, 1.0, 0.0), description="world up")


@lights.register
class AmbientLight(Light):
    name = "ambient"
    Params = AmbientParams
    glsl_file = "lights/ambient/ambient.glsl"
    glsl_function = "ambient_light"
    volume = LightVolume.FULLSCREEN

    def record(self, view: np.ndarray) -> np.ndarray:
        record = np.zeros((4, 4), dtype=np.float32)
        record[0, :3] = self.radiance()
        record[2, :3] = view_direction(view, self.params.up)
        record[3, :3] = np.asarray(self.params.ground, dtype=np.float64) * self.params.intensity
        return record
