"""Disc (elliptical) area light: an ellipse of diameters ``size`` of uniform radiance facing
``direction``. Linearly transformed cosines integrate polygons exactly; the disc is taken as the
regular polygon of ``DISC_SIDES`` sides with the same area (its irradiance differs from the
disc's by well under 1% wherever the disc lies above the horizon:
tests/lights/test_area_lights.py)."""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np
from pydantic import Field

from deferred.api import AreaLight, AreaLightParams, disc_polygon_radius, lights

from ..rect import rotated_axes

Extent = Annotated[float, Field(gt=0.0, le=1.0e4)]
DISC_SIDES = 12  # lights/disc/disc.glsl builds as many corners


class DiscParams(AreaLightParams):
    size: tuple[Extent, Extent] = Field((1.0, 1.0), description="diameters along its x and y, "
                                        "world units (equal: a disc)")
    rotation: float = Field(0.0, ge=-360.0, le=360.0, description="degrees about its normal "
                            "(0: x horizontal)")


@lights.register
class DiscLight(AreaLight):
    name = "disc"
    Params = DiscParams
    glsl_file = "lights/disc/disc.glsl"
    glsl_function = "disc_light"

    def half_axes(self) -> tuple[np.ndarray, np.ndarray]:
        """The polygon's circumradii along x and y (the ellipse's, grown to keep its area)."""
        x, y = rotated_axes(self.params)
        scale = disc_polygon_radius(1.0, DISC_SIDES)
        width, height = self.params.size
        return x * (width / 2.0 * scale), y * (height / 2.0 * scale)

    def emitter_radius(self) -> float:
        width, height = self.params.size
        return math.sqrt(width * height) / 2.0
