"""Directional light: parallel rays, no falloff (full-screen in the deferred pipeline)."""

from __future__ import annotations

import numpy as np
from pydantic import Field

from deferred.api import (
    Light,
    LightVolume,
    NonZeroVec3,
    ShadowParams,
    ShadowProjection,
    lights,
    view_direction,
)


class DirectionalParams(ShadowParams):
    direction: NonZeroVec3 = Field((-0.4, -1.0, -0.6), description="direction the light travels")
    cascades: int = Field(3, ge=1, le=4, description="shadow cascades over the view's depth")
    cascade_lambda: float = Field(0.75, ge=0.0, le=1.0, description="cascade splits: 0 "
                                  "uniform, 1 logarithmic (the practical split scheme's lambda)")
    shadow_distance: float = Field(40.0, gt=0.0, description="view depth the cascades cover "
                                   "(at most the camera's far plane)")


@lights.register
class DirectionalLight(Light):
    name = "directional"
    Params = DirectionalParams
    glsl_file = "lights/directional/directional.glsl"
    glsl_function = "directional_light"
    volume = LightVolume.FULLSCREEN
    shadow_projection = ShadowProjection.CASCADES

    def record(self, view: np.ndarray) -> np.ndarray:
        record = np.zeros((4, 4), dtype=np.float32)
        record[0, :3] = self.radiance()
        record[2, :3] = view_direction(view, self.params.direction)
        return record
