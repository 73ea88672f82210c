"""The rim light: parallel light weighted by (1 - N.V)^power, so it outlines silhouettes."""

import numpy as np
from pydantic import Field

from deferred.api import Light, LightParams, LightVolume, NonZeroVec3, view_direction

from . import SHADERS


class RimParams(LightParams):
    direction: NonZeroVec3 = Field((0.0, -0.3, -1.0), description="direction the light travels")
    power: float = Field(3.0, ge=0.5, le=16.0, description="exponent of 1 - N.V")


class RimLight(Light):
    name = "rim"
    Params = RimParams
    glsl_file = "velvet/rim_light.glsl"
    glsl_function = "rim_light"
    volume = LightVolume.FULLSCREEN
    shader_root = SHADERS

    def record(self, view: np.ndarray) -> np.ndarray:
        record = np.zeros((4, 4), dtype=np.float32)
        record[0, :3] = self.radiance()
        record[2, :3] = view_direction(view, self.params.direction)
        record[2, 3] = self.params.power
        return record
