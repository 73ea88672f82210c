"""Keyframe tracks: the camera, a light or an object's transform moving over time, and the
turntable (docs/guide/animation.md).

A track animates one target (``camera``, ``object:NAME``, ``light:INDEX`` or ``light:NAME``)
through keys, each at a time and setting some of the target's properties:

- camera: ``position``, ``target``, ``fov``;
- light: ``position``, ``direction``, ``color``, ``intensity`` (those its type has);
- object: ``position``, ``rotation`` (degrees, X then Y then Z), ``scale``.

Each property follows the keys that set it, with the track's interpolation: ``step`` (a key's
value holds until the next key), ``linear``, or ``smooth``: a cubic Hermite spline with
Catmull-Rom tangents, ``(p[k+1] - p[k-1]) / (t[k+1] - t[k-1])`` at an inner key (the
non-uniform form) and zero at the first and last keys, so motion eases out of the first and
into the last and joins the held values before and after without a jolt. Before its first key a
property has the first key's value, after its last the last's. Rotations interpolate per Euler
component in degrees (``rotation = [0, 360, 0]`` after ``[0, 0, 0]`` is a full turn).

A smooth curve may overshoot its keys; where a property has a range (``fov`` in (1, 179),
``intensity`` and ``color`` >= 0, a ``scale`` keeping its sign and at least ``MIN_SCALE`` in
size) the whole curve is checked when the track is made, naming the keys around the overshoot.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np
from pydantic import ConfigDict, Field, ValidationError, field_validator

from deferred.errors import InputError, input_error
from deferred.scene.transform import MIN_SCALE, scale_too_small
from deferred.validation import (
    NonNegativeFloat,
    NonZeroVec3,
    StrictValues,
    closest,
    join_where,
    validation_problems,
)

Vec3 = tuple[float, float, float]
INTERPOLATIONS = ("step", "linear", "smooth")


KINDS = ("camera", "light", "object")
MAX_KEYS = 100_000


class _Key(StrictValues):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    time: float = Field(ge=0.0, description="seconds")


class CameraKey(_Key):
    """A key of a camera track: the properties it sets at ``time``."""

    position: Vec3 | None = None
    target: Vec3 | None = None
    fov: float | None = Field(None, gt=1.0, lt=179.0, description="vertical, degrees")


class LightKey(_Key):
    """A key of a light's track (the properties its type has)."""

    position: Vec3 | None = None
    direction: NonZeroVec3 | None = None
    color: tuple[NonNegativeFloat, NonNegativeFloat, NonNegativeFloat] | None = Field(
        None, description="linear RGB, each >= 0")
    intensity: float | None = Field(None, ge=0.0)


class ObjectKey(_Key):
    """A key of an object's track: its transform at ``time``."""

    position: Vec3 | None = None
    rotation: Vec3 | None = Field(None, description="degrees, applied X, then Y, then Z")
    scale: float | Vec3 | None = None

    @field_validator("scale")
    @classmethod
    def _scale(cls, scale: float | Vec3 | None) -> float | Vec3 | None:
        if scale is not None and scale_too_small(scale):
            raise ValueError(f"must be at least {MIN_SCALE:g} in size")
        return scale


KEY_MODELS: dict[str, type[_Key]] = {"camera": CameraKey, "light": LightKey,
                                     "object": ObjectKey}
PROPERTIES = {kind: tuple(name for name in model.model_fields if name != "time")
              for kind, model in KEY_MODELS.items()}
SCALAR = {"fov", "intensity"}


def parse_target(text: Any, where: str) -> tuple[str, str | None]:
    """``camera`` -> ("camera", None); ``object:ball`` -> ("object", "ball"); ``light:0`` ->
    ("light", "0"); anything else an ``InputError`` naming ``where``."""
    if isinstance(text, str):
        kind, colon, name = text.partition(":")
        if text == "camera":
            return "camera", None
        if colon and kind in ("object", "light") and name:
            return kind, name
    hint = closest(text.partition(":")[0], KINDS) if isinstance(text, str) else None
    said = f" (did you mean '{hint}'?)" if hint and hint != text else ""
    raise InputError(f"expected 'camera', 'object:NAME', 'light:INDEX' or 'light:NAME', got "
                     f"{text!r:.80}{said}", where)


def key_before(times: np.ndarray, time: float) -> int | None:
    """The key ``k`` with ``times[k] <= time < times[k + 1]``; None at or before the first key
    and at or after the last (where a curve holds an end's value)."""
    if time <= times[0] or time >= times[-1]:
        return None
    return bisect_right(times, time) - 1


@dataclass(frozen=True, eq=False)
class Curve:
    """One property's keys: ``times`` (K,) strictly rising, ``values`` (K, D); ``keys`` the
    index in its track of each key (for errors)."""

    times: np.ndarray
    values: np.ndarray
    interpolation: str
    keys: tuple[int, ...]

    def at(self, time: float) -> np.ndarray:
        """The value at ``time`` (D,), held before the first key and after the last."""
        times, values = self.times, self.values
        k = key_before(times, time)
        if k is None:  # held before the first key and after the last
            return values[0] if time <= times[0] else values[-1]
        if self.interpolation == "step":
            return values[k]
        h = times[k + 1] - times[k]
        s = (time - times[k]) / h
        if self.interpolation == "linear":
            return values[k] + s * (values[k + 1] - values[k])
        m0, m1 = self._tangent(k), self._tangent(k + 1)
        s2, s3 = s * s, s * s * s
        return ((2 * s3 - 3 * s2 + 1) * values[k] + (s3 - 2 * s2 + s) * h * m0
                + (3 * s2 - 2 * s3) * values[k + 1] + (s3 - s2) * h * m1)

    def _tangent(self, k: int) -> np.ndarray:
        """Catmull-Rom's tangent at key ``k`` (non-uniform times); zero at the ends."""
        if k == 0 or k == len(self.times) - 1:
            return np.zeros_like(self.values[k])
        return (self.values[k + 1] - self.values[k - 1]) / (self.times[k + 1] - self.times[k - 1])

    def segment_extremes(self) -> list[tuple[int, np.ndarray, np.ndarray]]:
        """For each segment between keys: (its first key's index in the curve, the least and
        the greatest value each component reaches on it)."""
        out = []
        for k in range(len(self.times) - 1):
            p0, p1 = self.values[k], self.values[k + 1]
            if self.interpolation != "smooth":
                out.append((k, np.minimum(p0, p1), np.maximum(p0, p1)))
                continue
            h = self.times[k + 1] - self.times[k]
            big0, big1 = h * self._tangent(k), h * self._tangent(k + 1)
            a = 2 * p0 + big0 - 2 * p1 + big1  # p(s) = a s^3 + b s^2 + c s + d
            b = -3 * p0 - 2 * big0 + 3 * p1 - big1
            low, high = np.minimum(p0, p1), np.maximum(p0, p1)
            for d in range(len(p0)):
                for s in _unit_roots(3 * a[d], 2 * b[d], big0[d]):
                    value = ((a[d] * s + b[d]) * s + big0[d]) * s + p0[d]
                    low[d], high[d] = min(low[d], value), max(high[d], value)
            out.append((k, low, high))
        return out


def _unit_roots(a: float, b: float, c: float) -> list[float]:
    """The roots of ``a s^2 + b s + c`` strictly inside (0, 1)."""
    if abs(a) < 1e-300:
        roots = [-c / b] if abs(b) > 1e-300 else []
    else:
        disc = b * b - 4 * a * c
        if disc < 0:
            return []
        root = math.sqrt(disc)
        roots = [(-b - root) / (2 * a), (-b + root) / (2 * a)]
    return [s for s in roots if 0.0 < s < 1.0]


def curve_properties(track: Any) -> tuple[str, ...]:
    """The properties a track (anything with ``curves``) animates."""
    return tuple(track.curves)


def curve_key_times(track: Any) -> tuple[float, ...]:
    """Every key's time of a track (anything with ``curves`` holding ``times``), sorted."""
    return tuple(sorted({float(t) for curve in track.curves.values() for t in curve.times}))


@dataclass(frozen=True, eq=False)
class Track:
    """A target's keys: ``kind`` (camera, light, object) and ``name`` (the object's or the
    light's, as the target said it; None for the camera), the interpolation, each animated
    property's :class:`Curve`, ``where`` (``scene.toml: track[2]``) for errors, and the
    light it moves (``subject``, bound by ``Scene.add_track``)."""

    target: str
    kind: str
    name: str | None
    interpolation: str
    curves: Mapping[str, Curve]
    where: str
    subject: Any = field(default=None, repr=False)

    properties = property(lambda self: curve_properties(self))
    key_times = property(lambda self: curve_key_times(self))

    def at(self, time: float) -> dict[str, Any]:
        """The animated properties at ``time``: a float for ``fov`` and ``intensity``, a tuple
        of three floats for the rest."""
        out: dict[str, Any] = {}
        for name, curve in self.curves.items():
            value = curve.at(time)
            out[name] = float(value[0]) if name in SCALAR else tuple(float(v) for v in value)
        return out


_RANGES: dict[str, tuple[float | None, float | None, str]] = {
    # property: (least, greatest, what the range is), the bounds themselves excluded for fov
    "fov": (1.0, 179.0, "in (1, 179)"),
    "intensity": (0.0, None, ">= 0"),
    "color": (0.0, None, ">= 0"),
}


def make_track(target: str, keys: Any, interpolation: Any = "linear",
               where: str = "track") -> Track:
    """A :class:`Track` of ``keys`` (a list of mappings: ``time`` and the properties set then)
    for ``target``, checked: the target's form, the interpolation's name, every key's
    properties and values (one problem each, ``where.keys[1].position: ...``), keys in
    rising time, each setting something, and where it is smooth, the curve within each
    property's range between keys."""
    kind, name = parse_target(target, join_where(where, "target"))
    if not (isinstance(interpolation, str) and interpolation in INTERPOLATIONS):
        hint = closest(interpolation, INTERPOLATIONS)
        said = f"did you mean '{hint}'? " if hint else ""
        raise InputError(f"unknown interpolation {interpolation!r:.80} ({said}choose from "
                         f"{', '.join(INTERPOLATIONS)})", join_where(where, "interpolation"))
    if isinstance(keys, str | bytes | Mapping) or not isinstance(keys, Sequence) or not keys:
        raise InputError("expected a list of keys, each a table with a time and the "
                         "properties it sets", join_where(where, "keys"))
    if len(keys) > MAX_KEYS:
        raise InputError(f"{len(keys)} keys; at most {MAX_KEYS:,}", join_where(where, "keys"))
    model = KEY_MODELS[kind]
    allowed = PROPERTIES[kind]
    problems: list[InputError] = []
    parsed: list[_Key | None] = []
    for index, key in enumerate(keys):
        at = join_where(where, f"keys[{index}]")
        if not isinstance(key, Mapping):
            problems.append(InputError(f"expected a table with a time and the properties it "
                                       f"sets, got {type(key).__name__}", at))
            parsed.append(None)
            continue
        strays = [k for k in key if k != "time" and k not in allowed]
        for stray in strays:
            hint = closest(stray, allowed)
            said = f" (did you mean '{hint}'?)" if hint else ""
            problems.append(InputError(
                f"{'an' if kind[0] in 'aeiou' else 'a'} {kind}'s keys set time and "
                f"{', '.join(allowed)}, not "
                f"{str(stray)[:40]!r}{said}",
                join_where(at, str(stray)[:80])))
        try:
            made = model(**{k: v for k, v in key.items() if k not in strays})
        except ValidationError as exc:
            problems += validation_problems(exc, at, model)
            parsed.append(None)
            continue
        if not strays and not made.model_fields_set - {"time"}:
            problems.append(InputError(f"sets nothing: give one of {', '.join(allowed)}", at))
        parsed.append(made)
    if not problems:
        for index in range(1, len(parsed)):
            before, key = parsed[index - 1].time, parsed[index].time
            if not key > before:
                problems.append(InputError(
                    f"{key:g} s is not after the key before it ({before:g} s): keys go in "
                    "rising time, one key a time", join_where(where, f"keys[{index}].time")))
    if problems:
        raise input_error(problems)
    curves: dict[str, Curve] = {}
    for prop in allowed:
        given = [(index, key) for index, key in enumerate(parsed)
                 if prop in key.model_fields_set and getattr(key, prop) is not None]
        if not given:
            continue
        values = np.array([np.broadcast_to(np.asarray(getattr(key, prop), np.float64),
                                           (1,) if prop in SCALAR else (3,))
                           for _, key in given], np.float64)
        curves[prop] = Curve(np.array([key.time for _, key in given], np.float64), values,
                             interpolation, tuple(index for index, _ in given))
    for prop, curve in curves.items():
        _check_range(kind, prop, curve, where)
    return Track(str(target), kind, name, interpolation, MappingProxyType(curves), where)


def _check_range(kind: str, prop: str, curve: Curve, where: str) -> None:
    """The curve stays in the property's range between its keys (a smooth one may not)."""
    if kind == "object" and prop == "scale":
        if curve.interpolation == "step":  # held key by key: each key's own value counts
            for k, value in enumerate(curve.values):
                if np.any(np.abs(value) < MIN_SCALE):
                    raise InputError(f"a scale must be at least {MIN_SCALE:g} in size",
                                     join_where(where, f"keys[{curve.keys[k]}].scale"))
            return
        for k, low, high in curve.segment_extremes():
            if np.any((low < MIN_SCALE) & (high > -MIN_SCALE)):
                first, last = curve.keys[k], curve.keys[k + 1]
                raise InputError(
                    f"between keys {first} and {last} the scale passes through 0 (it must "
                    f"keep its sign and be at least {MIN_SCALE:g} in size); "
                    + ("use linear or add a key" if curve.interpolation == "smooth"
                       else "flip it at one key with step interpolation"),
                    join_where(where, f"keys[{last}].scale"))
        return
    if prop not in _RANGES:
        return
    least, greatest, said = _RANGES[prop]
    open_bounds = prop == "fov"
    for k, low, high in curve.segment_extremes():
        below = least is not None and (np.any(low <= least) if open_bounds
                                       else np.any(low < least))
        above = greatest is not None and np.any(high >= greatest)
        if below or above:
            first, last = curve.keys[k], curve.keys[k + 1]
            reached = float(np.min(low)) if below else float(np.max(high))
            raise InputError(f"the smooth curve between keys {first} and {last} reaches "
                             f"{reached:.4g} ({prop} must be {said}): use linear or add a key",
                             join_where(where, f"keys[{last}].{prop}"))


@dataclass(frozen=True)
class Turntable:
    """The camera orbiting its target once every ``period`` seconds from ``start``: around
    the world up axis (+Y) through the target, keeping its distance and height."""

    period: float
    start: float = 0.0

    def __post_init__(self) -> None:
        if not (isinstance(self.period, int | float) and math.isfinite(self.period)
                and self.period > 0.0):
            raise InputError(f"expected a finite number of seconds > 0, got {self.period!r}",
                             "turntable.period")
        if not (isinstance(self.start, int | float) and math.isfinite(self.start)
                and self.start >= 0.0):
            raise InputError(f"expected a finite number of seconds >= 0, got {self.start!r}",
                             "turntable.start")

    def angle(self, time: float) -> float:
        """Radians turned at ``time``; whole turns are exactly 0 (rounded to 1e-9 of a turn:
        the frame after the last of a loop is the first again, bit for bit)."""
        turns = round((time - self.start) / self.period, 9) % 1.0
        return 2.0 * math.pi * turns

    def orbit(self, position: Vec3, target: Vec3, time: float) -> Vec3:
        """``position`` turned about the vertical through ``target`` by :meth:`angle`
        (counter-clockwise seen from above)."""
        angle = self.angle(time)
        if angle == 0.0:
            return tuple(float(v) for v in position)
        dx, dz = position[0] - target[0], position[2] - target[2]
        c, s = math.cos(angle), math.sin(angle)
        return (float(target[0] + c * dx + s * dz), float(position[1]),
                float(target[2] - s * dx + c * dz))
