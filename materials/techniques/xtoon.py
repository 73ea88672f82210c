"""X-toon ramps (Costigan, "Cartoon Hair Simulation", 4.3.3-4.3.6, after Barla et al.): a 2D
texture whose x axis is the light intensity max(N.L, 0) (4.3.3) and whose y axis is a metric
chosen per material:

- ``none``: y = 0, the 1D cartoon ramp of Fig. 4.7;
- ``depth``: y = D = 1 - log(z / z_min) / log(z_max / z_min) (4.3.4): near surfaces (D = 1) take
  the ramp as given, far ones (D = 0) a washed-out copy of it;
- ``backlight``: y = |N.V|^r (4.3.5): where y is small (the silhouette seen against the light)
  the ramp adds a rim colour to the diffuse;
- ``specular``: y = (N.H)^c (4.3.6, Barla's texture specular): the top rows add a highlight.

A ramp is generated from colour stops (``[[0.0, "#3a2a5a"], [0.5, "#8a6ac0"]]``: each colour
holds from its position up to the following one's, a quantised gradient) or read from an image (x to
the right, y up: the image's top row is y = 1). The toon shading model
(:mod:`deferred.materials.shading_models`) gathers every ramp of the scene's materials into one
texture array; a material writes its ramp's layer (:func:`ramp_layer`) into the G-buffer datum
``toon_ramp``, and the lights look the ramp up by it (``materials/shading_models/toon.glsl``).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np
from pydantic import Field, field_validator

from deferred.api import InputError, MaterialParams, read_image, srgb_decode

if TYPE_CHECKING:
    from deferred.api import Scene

RAMP_WIDTH = 256  # texels along N.L
RAMP_HEIGHT = 64  # texels along the metric
METRICS = ("none", "depth", "backlight", "specular")
HEX_COLOUR = re.compile(r"#([0-9a-fA-F]{6})")
# the metric's y where the generated ramps change: the rim's edge and the highlight's edge
RIM_EDGE = 0.3
HIGHLIGHT_EDGE = 0.85
WASH_OUT = 0.7  # how far the farthest depth row fades toward a light grey

Metric = Literal["none", "depth", "backlight", "specular"]
Stop = tuple[float, str]
# X-toon parameters are read into the ramp texture, not set as uniforms
XTOON_UNIFORM_OVERRIDES = {name: None for name in (
    "ramp", "ramp_image", "ramp_metric", "depth_range", "backlight_power", "backlight_color",
    "ramp_shininess", "highlight_color")}


def hex_to_linear(text: str, where: str = "colour") -> tuple[float, float, float]:
    """``#rrggbb`` (sRGB, as image editors give it) as linear RGB."""
    match = HEX_COLOUR.fullmatch(text.strip())
    if match is None:
        raise InputError(f"expected a colour as #rrggbb, got {text!r}", where)
    code = match.group(1)
    linear = srgb_decode(np.array([int(code[k:k + 2], 16) / 255.0 for k in (0, 2, 4)]))
    return tuple(float(c) for c in linear)


class XToonParams(MaterialParams):
    """The X-toon parameters of a material shaded by the ``toon`` model (a mixin)."""

    ramp: tuple[Stop, ...] = Field(
        ((0.0, "#4a4a4a"), (0.35, "#9a9a9a"), (0.75, "#ffffff")),
        description="colour stops [[x, \"#rrggbb\"], ...] along max(N.L, 0), x ascending "
                    "from 0: each colour holds until the following one (a quantised ramp); it "
                    "multiplies the albedo (4.3.3), so greys keep the material's colour")
    ramp_image: str | None = Field(None, description="a 2D ramp image instead of the stops "
                                                     "(x: max(N.L, 0); y, up: the metric)")
    ramp_metric: Metric = Field("none", description="the ramp's y axis: none, depth (4.3.4), "
                                                    "backlight (4.3.5) or specular (4.3.6)")
    depth_range: tuple[float, float] = Field(
        (2.0, 20.0), description="z_min, z_max of the depth metric (view-space units)")
    backlight_power: float = Field(1.0, gt=0.0, le=64.0, description="r of |N.V|^r (> 0: "
                                                                        "GLSL's pow(0, 0) is "
                                                                        "undefined)")
    backlight_color: tuple[float, float, float] = Field(
        (0.9, 0.8, 0.6), description="rim light added to the diffuse where |N.V|^r is small")
    ramp_shininess: float = Field(40.0, ge=1.0, le=2048.0,
                                  description="c of the specular metric (N.H)^c")
    highlight_color: tuple[float, float, float] = Field(
        (0.8, 0.8, 0.8), description="added by the specular metric's top rows")

    @field_validator("ramp")
    @classmethod
    def _stops(cls, stops: tuple[Stop, ...]) -> tuple[Stop, ...]:
        if not stops:
            raise ValueError("needs at least one colour stop")
        positions = [position for position, _ in stops]
        rising = all(b > a for a, b in zip(positions, positions[1:], strict=False))
        if positions[0] != 0.0 or not rising or positions[-1] > 1.0:
            raise ValueError("stop positions must start at 0 and rise within [0, 1]")
        for _, colour in stops:
            if HEX_COLOUR.fullmatch(colour.strip()) is None:
                raise ValueError(f"expected colours as #rrggbb, got {colour!r}")
        return stops

    @field_validator("depth_range")
    @classmethod
    def _depth_range(cls, value: tuple[float, float]) -> tuple[float, float]:
        if not 0.0 < value[0] < value[1]:
            raise ValueError("needs 0 < z_min < z_max")
        return value


@dataclass(frozen=True)
class XToonRamp:
    """One ramp as the shading model needs it: its texels' source and its metric's constants
    (hashable: the ramps of a scene are gathered by value)."""

    stops: tuple[Stop, ...]
    image: Path | None
    metric: Metric
    metric_constants: tuple[float, float]  # depth: z_min, z_max; backlight: r; specular: c
    backlight_color: tuple[float, float, float]
    highlight_color: tuple[float, float, float]
    # the scene key naming the image, for its errors (not part of the ramp's value)
    where: str | None = field(default=None, compare=False)

    @classmethod
    def from_params(cls, params: XToonParams, image: Path | None = None,
                    where: str | None = None) -> XToonRamp:
        constants = {"none": (0.0, 0.0), "depth": tuple(params.depth_range),
                     "backlight": (params.backlight_power, 0.0),
                     "specular": (params.ramp_shininess, 0.0)}[params.ramp_metric]
        return cls(tuple((float(x), c) for x, c in params.ramp), image, params.ramp_metric,
                   constants, tuple(params.backlight_color), tuple(params.highlight_color),
                   where)

    def texels(self) -> np.ndarray:
        """(RAMP_HEIGHT, RAMP_WIDTH, 3) linear RGB, row 0 at y = 0."""
        if self.image is not None:
            pixels = read_image(self.image, srgb_to_linear=True,
                                where=self.where)[::-1, :, :3]  # bottom row 0
            rows = (np.arange(RAMP_HEIGHT) + 0.5) / RAMP_HEIGHT * pixels.shape[0]
            cols = (np.arange(RAMP_WIDTH) + 0.5) / RAMP_WIDTH * pixels.shape[1]
            return np.ascontiguousarray(pixels[rows.astype(int)][:, cols.astype(int)],
                                        np.float32)
        return generated_ramp(self.stops, self.metric, self.backlight_color,
                              self.highlight_color)

    def constants(self) -> tuple[float, float, float, float]:
        """The shading model's row for the ramp: metric index, its two constants, 1 (an
        X-toon ramp: x = max(N.L, 0), fetched without filtering)."""
        return (float(METRICS.index(self.metric)), *self.metric_constants, 1.0)


def stop_colours(stops: Sequence[Stop], width: int = RAMP_WIDTH) -> np.ndarray:
    """(width, 3): each texel the colour of the last stop at or before its x (texel centres)."""
    x = (np.arange(width) + 0.5) / width
    positions = np.array([position for position, _ in stops])
    colours = np.array([hex_to_linear(colour) for _, colour in stops])
    return colours[np.searchsorted(positions, x, side="right") - 1]


def generated_ramp(stops: Sequence[Stop], metric: Metric,
                   backlight_color=(0.9, 0.8, 0.6), highlight_color=(0.8, 0.8, 0.8),
                   width: int = RAMP_WIDTH, height: int = RAMP_HEIGHT) -> np.ndarray:
    """(height, width, 3): the stops' ramp along x, varied along y by the metric."""
    base = stop_colours(stops, width)[None, :, :]
    y = ((np.arange(height) + 0.5) / height)[:, None, None]
    if metric == "depth":  # D = 1 near: the ramp; D = 0 far: washed out toward a light grey
        grey = np.full(3, min(1.0, float(base.mean()) + 0.3))
        washed = base + WASH_OUT * (grey - base)
        texels = washed + y * (base - washed)
    elif metric == "backlight":  # a hard rim where |N.V|^r is small
        texels = base + np.where(y < RIM_EDGE, 1.0, 0.0) * np.asarray(backlight_color)
    elif metric == "specular":  # a hard highlight where (N.H)^c is large
        texels = base + np.where(y >= HIGHLIGHT_EDGE, 1.0, 0.0) * np.asarray(highlight_color)
    else:
        texels = np.broadcast_to(base, (height, width, 3))
    return np.ascontiguousarray(texels, np.float32)


def scene_ramps(scene: Scene) -> list[XToonRamp]:
    """The X-toon ramps of the scene's materials, each once, in object order: layers
    ``first_layer ...`` of the toon shading model's texture array."""
    ramps: dict[XToonRamp, None] = {}
    for obj in scene.objects:
        ramp = getattr(obj.material, "xtoon_ramp", None)
        if ramp is not None:
            ramps.setdefault(ramp(), None)
    return list(ramps)


def ramp_layer(scene: Scene, ramp: XToonRamp, first_layer: int) -> int:
    """The texture-array layer of ``ramp`` in ``scene`` (the G-buffer datum toon_ramp holds
    it in 8 bits: at most 256 layers)."""
    ramps = scene_ramps(scene)
    if first_layer + len(ramps) > 256:
        raise InputError(f"the scene's materials have {len(ramps)} different X-toon ramps; the "
                         f"toon model holds {256 - first_layer}")
    if ramp not in ramps:
        raise InputError("the material's X-toon ramp is not among the scene's (it was changed "
                         "outside its params)")
    return first_layer + ramps.index(ramp)
