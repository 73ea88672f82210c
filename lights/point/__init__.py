"""Point light: windowed inverse-square falloff reaching 0 at ``radius`` (a sphere volume)."""

from __future__ import annotations

import numpy as np
from pydantic import Field

from deferred.api import (
    Light,
    LightVolume,
    ShadowParams,
    ShadowProjection,
    lights,
    radiances,
    view_points,
)


class PointParams(ShadowParams):
    position: tuple[float, float, float] = Field((0.0, 2.0, 2.0), description="world position")
    radius: float = Field(10.0, gt=0.0, description="distance at which the light reaches 0")


def distance_falloff(d: np.ndarray, radius: float) -> np.ndarray:
    """numpy twin of ``distance_falloff`` in common/lighting.glsl."""
    window = np.clip(1.0 - (d / radius) ** 4, 0.0, 1.0)
    return window * window / (d * d + 1.0)


@lights.register
class PointLight(Light):
    name = "point"
    Params = PointParams
    glsl_file = "lights/point/point.glsl"
    glsl_function = "point_light"
    volume = LightVolume.SPHERE
    shadow_projection = ShadowProjection.CUBE

    def record(self, view: np.ndarray) -> np.ndarray:
        return self.records([self], view)[0]

    @classmethod
    def records(cls, lights: list[Light], view: np.ndarray) -> np.ndarray:
        records = np.zeros((len(lights), 4, 4), dtype=np.float32)
        if lights:
            records[:, 0, :3] = radiances(lights)
            records[:, 1, :3] = view_points(view, np.array([light.params.position
                                                            for light in lights], np.float64))
            records[:, 1, 3] = [light.params.radius for light in lights]
        return records
