"""The light interface: a light type's parameters, GLSL function and records.

A light type is a class with a unique ``name`` (the scene file's ``type``), a pydantic ``Params``
model, a GLSL file defining ``vec3 <glsl_function>(LightRecord light, Surface s, vec3 P, vec3 V)``
and a ``record(view)`` method packing the light into four vec4s in view space
(``common/lighting.glsl`` documents the layout). The same record feeds both pipelines: the deferred
pass reads it per instance, the forward pass loops over all records per fragment.

``volume`` says how the deferred pass bounds a light: ``"fullscreen"`` (directional, ambient) or
``"sphere"`` (the record's ``position.xyz`` is the centre and ``position.w`` the radius), so that
cost follows the pixels a light touches.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from pydantic import Field

from deferred.names import LightVolume
from deferred.params import Params, validate_params
from deferred.validation import Radiance

if sys.version_info >= (3, 11):
    from importlib.resources.abc import Traversable
else:  # Python 3.10
    from importlib.abc import Traversable

Vec3 = tuple[float, float, float]

class LightParams(Params):
    """Base of every light's parameter model: a colour and its intensity."""

    color: Radiance = Field((1.0, 1.0, 1.0), description="linear RGB colour, each >= 0")
    intensity: float = Field(1.0, ge=0.0, description="multiplier of color")


class Light:
    """A light type: a ``name``, a validated ``Params`` model, a GLSL function
    (``glsl_file``, ``glsl_function``: ``vec3 f(LightRecord light, Surface s, vec3 P, vec3 V)``)
    and how it packs itself for the GPU (:meth:`record`: four ``vec4`` in view space).
    ``volume`` says whether it lights the whole screen or a sphere around it.
    """

    name: ClassVar[str]
    Params: ClassVar[type[LightParams]] = LightParams
    glsl_file: ClassVar[str] = ""
    glsl_function: ClassVar[str] = ""
    volume: ClassVar[LightVolume] = LightVolume.FULLSCREEN
    shader_root: ClassVar[Traversable | Path | None] = None
    type_id: ClassVar[int] = 0  # set by the registry

    def __init__(self, params: LightParams | None = None):
        self.params = params if params is not None else self.Params()

    @classmethod
    def from_dict(cls, values: dict[str, Any], where: str | None = None) -> Light:
        return cls(validate_params(cls.Params, values, where))

    def radiance(self) -> np.ndarray:
        return np.asarray(self.params.color, dtype=np.float64) * self.params.intensity

    def record(self, view: np.ndarray) -> np.ndarray:
        """(4, 4) float32: color, position, direction, extra (view space). See lighting.glsl.
        A function of ``params`` and ``view`` alone: the light buffer packs the records again
        only when one of them changes (``LightBuffer.upload``)."""
        raise NotImplementedError

    @classmethod
    def records(cls, lights: list[Light], view: np.ndarray) -> np.ndarray:
        """``(len(lights), 4, 4)`` float32: :meth:`record` of each light of this type. A type
        with many lights a frame (point, spot) overrides it with numpy over all of them (a
        ``record`` call per light is slow at a thousand lights: benchmarks/README.md)."""
        return np.stack([np.asarray(light.record(view), dtype=np.float32).reshape(4, 4)
                         for light in lights]) if lights else np.zeros((0, 4, 4), np.float32)


def view_point(view: np.ndarray, point) -> np.ndarray:
    """A world-space point in view space (``view`` is the 4x4 world-to-view matrix)."""
    return (view @ np.append(np.asarray(point, dtype=np.float64), 1.0))[:3]


def view_points(view: np.ndarray, points: np.ndarray) -> np.ndarray:
    """:func:`view_point` of ``(n, 3)`` points."""
    return points @ view[:3, :3].T + view[:3, 3]


def view_directions(view: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """:func:`view_direction` of ``(n, 3)`` directions."""
    d = directions @ view[:3, :3].T
    return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)


def radiances(lights: list[Light]) -> np.ndarray:
    """:meth:`Light.radiance` of each light, ``(n, 3)``."""
    return np.array([light.params.color for light in lights], np.float64) * \
        np.array([light.params.intensity for light in lights], np.float64)[:, None]


def view_direction(view: np.ndarray, direction) -> np.ndarray:
    """A world-space direction in view space, normalised (rotation only)."""
    d = view[:3, :3] @ np.asarray(direction, dtype=np.float64)
    return d / max(np.linalg.norm(d), 1e-12)
