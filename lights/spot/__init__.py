"""Spot light: a point light inside a cone (smooth between inner and outer angles)."""

from __future__ import annotations

import numpy as np
from pydantic import Field, model_validator

from deferred.api import (
    Light,
    LightVolume,
    NonZeroVec3,
    ShadowProjection,
    lights,
    radiances,
    view_directions,
    view_points,
)

from ..point import PointParams


class SpotParams(PointParams):
    direction: NonZeroVec3 = Field((0.0, -1.0, 0.0), description="axis of the cone")
    inner_angle: float = Field(20.0, ge=0.0, le=89.0, description="full intensity, degrees")
    outer_angle: float = Field(30.0, gt=0.0, le=90.0, description="zero beyond, degrees")

    @model_validator(mode="after")
    def _check(self) -> SpotParams:
        if self.outer_angle <= self.inner_angle:
            raise ValueError("outer_angle must be greater than inner_angle")
        return self


def cone_falloff(cos_angle: np.ndarray, cos_outer: float, cos_inner: float) -> np.ndarray:
    """numpy twin of ``cone_falloff`` in common/lighting.glsl (GLSL smoothstep)."""
    t = np.clip((cos_angle - cos_outer) / (cos_inner - cos_outer), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


@lights.register
class SpotLight(Light):
    name = "spot"
    Params = SpotParams
    glsl_file = "lights/spot/spot.glsl"
    glsl_function = "spot_light"
    volume = LightVolume.SPHERE
    shadow_projection = ShadowProjection.PERSPECTIVE

    def record(self, view: np.ndarray) -> np.ndarray:
        return self.records([self], view)[0]

    @classmethod
    def records(cls, lights: list[Light], view: np.ndarray) -> np.ndarray:
        records = np.zeros((len(lights), 4, 4), dtype=np.float32)
        if lights:
            params = [light.params for light in lights]
            records[:, 0, :3] = radiances(lights)
            records[:, 1, :3] = view_points(view, np.array([p.position for p in params]))
            records[:, 1, 3] = [p.radius for p in params]
            records[:, 2, :3] = view_directions(view, np.array([p.direction for p in params],
                                                               np.float64))
            records[:, 2, 3] = np.cos(np.radians([p.outer_angle for p in params]))
            records[:, 3, 0] = np.cos(np.radians([p.inner_angle for p in params]))
        return records
