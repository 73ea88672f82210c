"""Rectangular area light: a ``size[0]`` by ``size[1]`` rectangle of uniform radiance facing
``direction``, lit by linearly transformed cosines (:mod:`deferred.interfaces.area`)."""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np
from pydantic import Field

from deferred.api import AreaLight, AreaLightParams, area_light_frame, lights

Extent = Annotated[float, Field(gt=0.0, le=1.0e4)]


class RectParams(AreaLightParams):
    size: tuple[Extent, Extent] = Field((1.0, 0.5), description="width and height, world "
                                        "units (along its x and y)")
    rotation: float = Field(0.0, ge=-360.0, le=360.0, description="degrees about its normal "
                            "(0: x horizontal)")


def rotated_axes(params) -> tuple[np.ndarray, np.ndarray]:
    """Unit x and y of a light's polygon: :func:`area_light_frame` turned by ``rotation``."""
    x, y, _ = area_light_frame(params.direction)
    angle = math.radians(params.rotation)
    c, s = math.cos(angle), math.sin(angle)
    return c * x + s * y, c * y - s * x


@lights.register
class RectLight(AreaLight):
    name = "rect"
    Params = RectParams
    glsl_file = "lights/rect/rect.glsl"
    glsl_function = "rect_light"

    def half_axes(self) -> tuple[np.ndarray, np.ndarray]:
        x, y = rotated_axes(self.params)
        width, height = self.params.size
        return x * (width / 2.0), y * (height / 2.0)

    def emitter_radius(self) -> float:
        width, height = self.params.size
        return math.sqrt(width * height / math.pi)
