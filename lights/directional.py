"""Directional light: parallel rays, no falloff (full-screen in the deferred pipeline)."""

from __future__ import annotations

import numpy as np
from pydantic import Field

from deferred.api import Light, LightParams, LightVolume, NonZeroVec3, lights, view_direction


class DirectionalParams(LightParams):
    direction: NonZeroVec3 = Field((-0.4, -1.0, -0.6), description="direction the light travels")


@lights.register
class DirectionalLight(Light):
    name = "directional"
    Params = DirectionalParams
    glsl_file = "lights/directional.glsl"
    glsl_function = "directional_light"
    volume = LightVolume.FULLSCREEN

    def record(self, view: np.ndarray) -> np.ndarray:
        record = np.zeros((4, 4), dtype=np.float32)
        record[0, :3] = self.radiance()
        record[2, :3] = view_direction(view, self.params.direction)
        return record
