"""glTF animations on the scene's timeline: each channel a curve of one node's translation,
rotation or scale (``weights``, the morph targets', are read and left out with a warning)
interpolated as the glTF 2.0 specification says (appendix C): ``STEP`` holds a key's value,
``LINEAR`` interpolates (rotations by spherical linear interpolation along the shorter arc),
``CUBICSPLINE`` is the cubic Hermite spline of the keys' in- and out-tangents (a rotation's
result normalised). Before the first key a channel holds the first value, after the last the
last.

A node's channels become one :class:`GltfTrack` in its ``tracks``: the timeline evaluates it as
it evaluates a scene file's track (``SceneNode.local_at``), as ``position``, ``quaternion`` and
``scale`` over the node's own placement.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from deferred.scene.gltf.accessors import read_accessor
from deferred.scene.gltf.document import GltfDocument
from deferred.scene.tracks import curve_key_times, curve_properties, key_before
from deferred.scene.transform import MIN_SCALE

INTERPOLATIONS = ("LINEAR", "STEP", "CUBICSPLINE")
PATHS = {"translation": ("position", 3), "rotation": ("quaternion", 4), "scale": ("scale", 3),
         "weights": ("weights", None)}


@dataclass(frozen=True, eq=False)
class ChannelCurve:
    """One channel's keys: ``times`` (K,) rising, ``values`` (K, D); for ``CUBICSPLINE`` the
    keys' ``in_tangents`` and ``out_tangents`` (K, D) too; ``rotation`` for a quaternion."""

    times: np.ndarray
    values: np.ndarray
    interpolation: str
    rotation: bool = False
    in_tangents: np.ndarray | None = None
    out_tangents: np.ndarray | None = None
    keys: tuple[int, ...] = ()

    def at(self, time: float) -> np.ndarray:
        """The value at ``time`` (a unit quaternion for a rotation)."""
        times, values = self.times, self.values
        k = key_before(times, time)
        if k is None:  # held before the first key and after the last
            return values[0] if time <= times[0] else values[-1]
        if self.interpolation == "STEP":
            return values[k]
        span = times[k + 1] - times[k]
        s = (time - times[k]) / span
        if self.interpolation == "LINEAR":
            if self.rotation:
                return slerp(values[k], values[k + 1], s)
            return values[k] + s * (values[k + 1] - values[k])
        s2, s3 = s * s, s * s * s
        value = ((2 * s3 - 3 * s2 + 1) * values[k] + span * (s3 - 2 * s2 + s) *
                 self.out_tangents[k] + (-2 * s3 + 3 * s2) * values[k + 1] +
                 span * (s3 - s2) * self.in_tangents[k + 1])
        if self.rotation:
            length = float(np.linalg.norm(value))
            return value / length if length > 1e-12 else values[k]
        return value


def slerp(a: np.ndarray, b: np.ndarray, s: float) -> np.ndarray:
    """Spherical linear interpolation of unit quaternions along the shorter arc."""
    dot = float(np.dot(a, b))
    if dot < 0.0:
        b, dot = -b, -dot
    if dot > 0.9995:  # nearly parallel: linear, normalised
        out = a + s * (b - a)
        return out / np.linalg.norm(out)
    theta = math.acos(min(1.0, dot))
    sin_theta = math.sin(theta)
    return (math.sin((1.0 - s) * theta) * a + math.sin(s * theta) * b) / sin_theta


@dataclass(frozen=True, eq=False)
class GltfTrack:
    """A node's channels of one animation, as the timeline reads a track: ``at(time)`` the
    placement's animated parts (``position``, ``quaternion``, ``scale``)."""

    target: str
    curves: Mapping[str, ChannelCurve]
    where: str
    kind: str = "object"
    name: str | None = None
    interpolation: str = "gltf"
    subject: Any = field(default=None, repr=False)

    properties = property(lambda self: curve_properties(self))
    key_times = property(lambda self: curve_key_times(self))

    def at(self, time: float) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for prop, curve in self.curves.items():
            value = curve.at(time)
            if prop == "scale":
                value = np.copysign(np.maximum(np.abs(value), MIN_SCALE),
                                    np.where(value == 0.0, 1.0, value))
            out[prop] = tuple(float(v) for v in value)
        return out


@dataclass
class GltfAnimation:
    """An animation: its name, and per node index the curves of its placement; ``duration``
    the last key's time; ``morph_nodes`` the nodes whose morph weights it moves (not drawn)."""

    name: str
    index: int
    curves: dict[int, dict[str, ChannelCurve]]
    duration: float
    where: str
    morph_nodes: list[int] = field(default_factory=list)

    def tracks(self, label_of: Mapping[int, str]) -> dict[int, GltfTrack]:
        """A track per animated node (by node index) among ``label_of``'s nodes."""
        return {node: GltfTrack(f"object:{label_of[node]}", MappingProxyType(curves),
                                f"{self.where} ({self.name})", name=label_of[node])
                for node, curves in self.curves.items() if node in label_of}


def read_animation(document: GltfDocument, index: int, raw: Any,
                   node_count: int) -> GltfAnimation:
    """Animation ``index``: each channel's sampler read and checked (times rising and >= 0,
    as many values as keys, the node and the path known; two channels of one node's path
    are an error)."""
    where = f"animations[{index}]"
    if not isinstance(raw, dict):
        raise document.error("expected an object", where)
    samplers = raw.get("samplers") or []
    curves: dict[int, dict[str, ChannelCurve]] = {}
    morph: list[int] = []
    duration = 0.0
    for number, channel in enumerate(raw.get("channels") or []):
        at = f"{where}.channels[{number}]"
        target = channel.get("target") if isinstance(channel, dict) else None
        if not isinstance(target, dict):
            raise document.error("has no target", at)
        node, path = target.get("node"), target.get("path")
        if node is None:
            continue  # a target only an extension names: nothing the framework moves
        if not isinstance(node, int) or isinstance(node, bool) or not 0 <= node < node_count:
            raise document.error(f"refers to nodes[{node!r:.20}], but the file has "
                                 f"{node_count} nodes", f"{at}.target.node")
        if path not in PATHS:
            raise document.error(f"unknown path {path!r:.40} (translation, rotation, scale or "
                                 "weights)", f"{at}.target.path")
        sampler_index = channel.get("sampler")
        if not isinstance(sampler_index, int) or not 0 <= sampler_index < len(samplers):
            raise document.error(f"refers to samplers[{sampler_index!r:.20}], but the "
                                 f"animation has {len(samplers)}", f"{at}.sampler")
        curve = _curve(document, samplers[sampler_index], path,
                       f"{where}.samplers[{sampler_index}]")
        duration = max(duration, float(curve.times[-1]))
        if path == "weights":
            morph.append(node)
            continue
        prop = PATHS[path][0]
        if prop in curves.setdefault(node, {}):
            raise document.error(f"nodes[{node}]'s {path} is moved by another channel of "
                                 "this animation already", at)
        curves[node][prop] = curve
    name = raw.get("name") if isinstance(raw.get("name"), str) else f"animation{index}"
    return GltfAnimation(name, index, curves, duration, where, sorted(set(morph)))


def _curve(document: GltfDocument, sampler: Any, path: str, where: str) -> ChannelCurve:
    if not isinstance(sampler, dict):
        raise document.error("expected an object", where)
    interpolation = sampler.get("interpolation", "LINEAR")
    if interpolation not in INTERPOLATIONS:
        raise document.error(f"unknown interpolation {interpolation!r:.40} (LINEAR, STEP or "
                             "CUBICSPLINE)", f"{where}.interpolation")
    times = read_accessor(document, sampler.get("input"), f"{where}.input", ("SCALAR",))
    times = times[:, 0].astype(np.float64)
    if times[0] < 0.0 or np.any(np.diff(times) <= 0.0):
        raise document.error("key times must be >= 0 and rise strictly",
                             f"accessors[{sampler['input']}]")
    width = PATHS[path][1]
    types = ("SCALAR",) if width is None else (f"VEC{width}",)
    output = read_accessor(document, sampler.get("output"), f"{where}.output", types)
    output = output.astype(np.float64)
    per_key = 3 if interpolation == "CUBICSPLINE" else 1
    if len(output) % (len(times) * per_key):
        raise document.error(f"{len(output)} values for {len(times)} keys"
                             + (" (3 a key: in-tangent, value, out-tangent)" if per_key == 3
                                else ""), f"accessors[{sampler['output']}]")
    # weights: a key holds one value per morph target
    output = output.reshape(len(times), per_key, -1)
    rotation = path == "rotation"
    values = output[:, 1] if per_key == 3 else output[:, 0]
    if rotation:
        lengths = np.linalg.norm(values, axis=1, keepdims=True)
        if np.any(lengths < 1e-9):
            raise document.error("a rotation key of length 0", f"accessors[{sampler['output']}]")
        values = values / lengths
    return ChannelCurve(times, values, interpolation, rotation,
                        output[:, 0] if per_key == 3 else None,
                        output[:, 2] if per_key == 3 else None)
