"""Area lights: a polygon of uniform radiance lighting a surface by linearly transformed cosines
(Heitz, Dupuy, Hill and Neubelt 2016, "Real-Time Polygonal-Light Shading with Linearly
Transformed Cosines").

An area light type (``rect``, ``disc``) derives from :class:`AreaLight`. Its record is a
sphere light's (centre and range in ``position``, the normal in ``direction``, the radiance in
``color``) and its data the polygon's two half axes (``axis_x``, ``axis_y``: view-space vectors
from the centre to the middle of an edge). Its GLSL builds an ``AreaLight``
(``lighting/area.glsl``: the polygon's corners relative to the shaded point and the radiance
arriving) and calls ``shade_area``, which the shading models answer: a model with an
``area_function`` integrates its own lobes over the polygon (``blinn_phong`` and ``pbr`` by
LTC), any other takes the light as a point light in the direction of the polygon's vector form
factor with the radiance of its solid angle (:mod:`deferred.interfaces.shading`).

The LTC tables are Heitz et al.'s published fit of GGX (``shaders/lighting/ltc_ggx.npz``,
converted from ``fit/results/ltc.js`` of https://github.com/selfshadow/ltc_code, BSD licence,
copyright 2017 Eric Heitz, Jonathan Dupuy, Stephen Hill and David Neubelt): 64 x 64 texels over
(roughness, sqrt(1 - N.V)), the inverse matrix's four free entries normalised by its middle one,
and the lobe's magnitude and Fresnel-weighted part. An area light gives them as its textures.

Shadows: the six cube maps of a point light at the centre, filtered by percentage-closer soft
shadows (Fernando 2005) sized by the light's equivalent disc (``shadow_filter = "pcss"``): a
blocker search, then a filter whose width follows the penumbra the light's size makes.
"""

from __future__ import annotations

import functools
import math
from importlib import resources
from typing import TYPE_CHECKING, ClassVar, Literal

import moderngl
import numpy as np
from pydantic import Field

from deferred.interfaces.light import Light, LightDatum, ShadowParams
from deferred.names import LightVolume, ShadowProjection
from deferred.validation import NonZeroVec3

if TYPE_CHECKING:
    from deferred.core.frame import Frame

LTC_TABLE = "lighting/ltc_ggx.npz"  # a file of deferred.shaders
AREA_GLSL = "lighting/area.glsl"


@functools.lru_cache(maxsize=1)
def ltc_tables() -> tuple[np.ndarray, np.ndarray]:
    """``(matrix (64, 64, 4), amplitude (64, 64, 2))`` float32, rows by sqrt(1 - N.V), columns
    by roughness (the module documentation)."""
    with resources.files("deferred.shaders").joinpath(LTC_TABLE).open("rb") as file:
        tables = np.load(file)
        return tables["matrix"].copy(), tables["amplitude"].copy()


def ltc_textures(frame: Frame) -> dict[str, moderngl.Texture]:
    """The LTC tables as the samplers ``lighting/area.glsl`` reads, made once a renderer."""

    def create(components: int, array: np.ndarray):
        def make(ctx: moderngl.Context) -> moderngl.Texture:
            size = array.shape[0]
            texture = ctx.texture((size, size), components,
                                  np.ascontiguousarray(array, np.float32).tobytes(), dtype="f4")
            texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
            texture.repeat_x = texture.repeat_y = False
            return texture
        return make

    matrix, amplitude = ltc_tables()
    return {"u_ltc_matrix": frame.resources.texture("ltc_matrix", create(4, matrix)),
            "u_ltc_amplitude": frame.resources.texture("ltc_amplitude", create(2, amplitude))}


class AreaLightParams(ShadowParams):
    """A one-sided emitter of uniform radiance (``color`` x ``intensity``, per unit area and
    solid angle) facing ``direction``."""

    position: tuple[float, float, float] = Field((0.0, 2.0, 0.0),
                                                 description="world position of its centre")
    direction: NonZeroVec3 = Field((0.0, -1.0, 0.0),
                                   description="its normal: the side it shines toward")
    radius: float = Field(10.0, gt=0.0, description="range: the light fades to 0 at this "
                          "distance from its centre (its bounding sphere)")
    shadow_resolution: int = Field(512, description="texels on a side of each of its six maps "
                                   "(a power of two)")
    shadow_filter: Literal["pcss", "pcf", "soft"] = Field(
        "pcss", description="pcss (a penumbra as wide as the light's size makes it), pcf or "
                            "soft (a fixed-width filter)")


def light_frame(direction, up_hint=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit (x, y, normal) of a light facing ``direction``: x horizontal where it can be (world
    +Y as up, +Z where the light faces along Y)."""
    normal = np.asarray(direction, np.float64)
    normal = normal / np.linalg.norm(normal)
    up = np.asarray(up_hint if up_hint is not None else
                    ((0.0, 0.0, 1.0) if abs(normal[1]) > 0.99 else (0.0, 1.0, 0.0)), np.float64)
    x = np.cross(up, normal)
    x /= np.linalg.norm(x)
    return x, np.cross(normal, x), normal


class AreaLight(Light):
    """Base of the area light types (the module documentation). A subclass gives
    :meth:`half_axes` (world-space half axes of its polygon) and :meth:`emitter_radius`, and a
    GLSL function building its polygon."""

    Params: ClassVar[type[AreaLightParams]] = AreaLightParams
    volume = LightVolume.SPHERE
    shadow_projection = ShadowProjection.CUBE
    area = True
    data = (LightDatum("axis_x", "xyz: view-space vector from the centre to the middle of the "
                                 "polygon's +x edge (half its width); w: unused"),
            LightDatum("axis_y", "xyz: view-space vector from the centre to the middle of the "
                                 "polygon's +y edge (half its height); w: unused"))

    def half_axes(self) -> tuple[np.ndarray, np.ndarray]:
        """World-space vectors from the centre to the middle of the +x and +y edges."""
        raise NotImplementedError

    def emitter_radius(self) -> float:
        """The radius of the disc of the light's area: the penumbra's size (PCSS)."""
        raise NotImplementedError

    @classmethod
    def textures(cls, frame: Frame) -> dict[str, moderngl.Texture]:
        return ltc_textures(frame)

    def record(self, view: np.ndarray) -> np.ndarray:
        record = np.zeros((self.record_vec4s(), 4), dtype=np.float32)
        params = self.params
        rotation = np.asarray(view, np.float64)[:3, :3]
        record[0, :3] = self.radiance()
        record[1, :3] = (np.asarray(view, np.float64) @
                         np.append(np.asarray(params.position, np.float64), 1.0))[:3]
        record[1, 3] = params.radius
        normal = rotation @ np.asarray(params.direction, np.float64)
        record[2, :3] = normal / np.linalg.norm(normal)
        axis_x, axis_y = self.half_axes()
        record[4, :3] = rotation @ axis_x
        record[5, :3] = rotation @ axis_y
        return record


def disc_polygon_radius(radius: float, sides: int) -> float:
    """The circumradius of a regular ``sides``-gon with the area of a disc of ``radius``."""
    return radius * math.sqrt(2.0 * math.pi / (sides * math.sin(2.0 * math.pi / sides)))
