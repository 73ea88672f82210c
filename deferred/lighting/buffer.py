"""All lights of a frame packed into one GPU buffer, read by both pipelines.

Each light is four vec4s (``Light.record``), its type id stored in ``color.w``, then the vec4s
of its type's own data (``Light.data``): a row is as wide as the widest type of the scene
needs, so a scene whose types declare no data keeps rows of four. Full-screen lights
(ambient, directional) come first, then volume lights, each group by type, so each deferred
lighting pass draws one contiguous range and the tiled paths loop ``[0, global_count)`` for the
lights every pixel gets. Volume lights whose sphere lies outside the view frustum are dropped on
the CPU before anything is uploaded (:func:`visible_spheres`, vectorised). The records live in an
RGBA32F texture, one row per light (``u_lights``, read by ``common/light_buffer.glsl``), on every
GL level: llvmpipe fetches texels faster than storage-buffer vec4s (benchmarks/README.md). The
full-screen lights' records are also a uniform array (``u_fullscreen_lights``), which the light
loops of the list and forward paths read at every pixel.
"""

from __future__ import annotations

import itertools
from typing import TYPE_CHECKING, Any

import moderngl
import numpy as np

from deferred.errors import InputError, RenderError
from deferred.interfaces.light import RECORD_VEC4S, Light
from deferred.lighting.dispatch import (
    FULLSCREEN_LIGHT_CAPACITY,
    FULLSCREEN_UNIFORM,
    light_range_uniform,
)
from deferred.names import LightVolume

if TYPE_CHECKING:
    from deferred.gl.uniforms import ProgramUniforms

LIGHT_BUFFER = "light_buffer"  # its name on a frame's blackboard


def visible_spheres(records: np.ndarray, projection: np.ndarray) -> np.ndarray:
    """Which view-space spheres (``records[:, 1]``: centre xyz, radius w) touch the frustum of
    ``projection``: the planes of the frustum from its rows (Gribb and Hartmann), all at once."""
    if len(records) == 0:
        return np.zeros(0, bool)
    rows = np.asarray(projection, dtype=np.float64)
    planes = np.stack([rows[3] + rows[0], rows[3] - rows[0], rows[3] + rows[1],
                       rows[3] - rows[1], rows[3] + rows[2], rows[3] - rows[2]])
    planes /= np.linalg.norm(planes[:, :3], axis=1, keepdims=True)
    centres = np.c_[records[:, 1, :3].astype(np.float64), np.ones(len(records))]
    distance = centres @ planes.T  # (lights, planes), positive inside
    return np.all(distance >= -records[:, 1, 3:4].astype(np.float64), axis=1)


def fullscreen_overflow(count: int) -> str:
    return (f"{count} full-screen (ambient, directional) lights; a frame holds at most "
            f"{FULLSCREEN_LIGHT_CAPACITY}")


def row_vec4s(light_types) -> int:
    """``vec4``s a row of the buffer holds for lights of ``light_types``: the widest record."""
    return max([RECORD_VEC4S, *(cls.record_vec4s() for cls in light_types)])


def type_records(light_type: type[Light], lights: list[Light], view: np.ndarray) -> np.ndarray:
    """``light_type.records``, checked against the type's declaration: ``(n, 4 + len(data),
    4)`` finite numbers (a wrong shape would shift every later light's record)."""
    records = np.asarray(light_type.records(lights, view), dtype=np.float32)
    want = (len(lights), light_type.record_vec4s(), 4)
    if records.shape != want:
        data = f" and its {len(light_type.data)} data vec4s" if light_type.data else ""
        raise RenderError(f"light type '{light_type.name}': records() gave an array of shape "
                          f"{records.shape}; its four vec4s{data} make {want}")
    if not np.isfinite(records).all():
        raise RenderError(f"light type '{light_type.name}': records() gave a value that is not "
                          "a finite number")
    return records


class LightBuffer:
    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.count = 0
        self.global_count = 0  # full-screen lights, first in the buffer
        self.culled = 0  # volume lights dropped this frame: outside the view
        self.ranges: dict[type[Light], tuple[int, int]] = {}
        self._range_uniforms: dict[str, tuple[int, int]] = {}
        # the volume lights' spheres in view space (centre xyz, radius), after culling
        self.volume_spheres = np.zeros((0, 4), np.float32)
        self._uniforms: dict[str, Any] = {}  # what ``bind`` sets
        self._texture: moderngl.Texture | None = None
        self._capacity = 0
        self._packed: tuple | None = None  # what the texture holds the records of (upload)

    @staticmethod
    def pack(lights: list[Light], view: np.ndarray, projection: np.ndarray | None = None,
             shadow_slots: dict[int, int] | None = None) -> tuple[np.ndarray, dict, int]:
        """(records, type -> (offset, count), full-screen light count): full-screen lights
        first, then volume lights inside the frustum of ``projection`` (all when None). A
        light in ``shadow_slots`` (by ``id``) has its shadow slot in ``extra.w``
        (deferred.lighting.shadows), the others 0."""
        ordered = sorted(lights, key=lambda light: (light.volume != LightVolume.FULLSCREEN,
                                                    light.type_id))  # stable: scene order kept
        width = row_vec4s({type(light) for light in lights})
        records = np.zeros((len(ordered), width, 4), dtype=np.float32)
        start = 0
        for light_type, run in itertools.groupby(ordered, key=type):  # a run per type
            run = list(run)
            records[start:start + len(run), :light_type.record_vec4s()] = \
                type_records(light_type, run, view)
            records[start:start + len(run), 0, 3] = float(light_type.type_id)
            records[start:start + len(run), 3, 3] = [float((shadow_slots or {}).get(id(light), 0))
                                                     for light in run]
            start += len(run)
        keep = np.ones(len(ordered), bool)
        volumes = np.array([light.volume != LightVolume.FULLSCREEN for light in ordered], bool)
        if projection is not None and volumes.any():
            keep[volumes] = visible_spheres(records[volumes], projection)
        ordered = [light for light, kept in zip(ordered, keep, strict=True) if kept]
        records = records[keep] if keep.any() else np.zeros((1, width, 4), np.float32)
        ranges: dict[type[Light], tuple[int, int]] = {}
        for index, light in enumerate(ordered):
            start, count = ranges.get(type(light), (index, 0))
            ranges[type(light)] = (start, count + 1)
        global_count = sum(1 for light in ordered if light.volume == LightVolume.FULLSCREEN)
        return records, ranges, global_count

    def upload(self, lights: list[Light], view: np.ndarray,
               projection: np.ndarray | None = None,
               shadow_slots: dict[int, int] | None = None) -> None:
        """Pack the lights' records (culled by ``projection``'s frustum) into the texture. The
        same lights with the same parameters (frozen: a change replaces them) seen from the
        same camera give the same records, so they are packed and uploaded only when one of
        these changes: packing costs milliseconds a frame at 1024 lights."""
        key = (np.asarray(view).tobytes(),
               None if projection is None else np.asarray(projection).tobytes(),
               [(light, light.params) for light in lights], dict(shadow_slots or {}))
        if self._texture is not None and key == self._packed:
            return
        self._packed = None  # until this upload is done
        self._upload(lights, view, projection, shadow_slots)
        self._packed = key

    def _upload(self, lights: list[Light], view: np.ndarray,
                projection: np.ndarray | None, shadow_slots: dict[int, int] | None) -> None:
        records, ranges, global_count = self.pack(lights, view, projection, shadow_slots)
        # lights added after the renderer checked them (check_light_limits): refused before
        # anything here changes
        if global_count > FULLSCREEN_LIGHT_CAPACITY:
            raise InputError(fullscreen_overflow(global_count), "light")
        rows = len(records)
        limit = int(self.ctx.info["GL_MAX_TEXTURE_SIZE"])
        if rows > limit:
            raise InputError(f"{rows} lights; lights are kept in a texture of at most {limit} "
                             "rows", "light")
        self.ranges, self.global_count = ranges, global_count
        self.count = sum(count for _, count in self.ranges.values())
        self.volume_spheres = records[self.global_count:self.count, 1].copy()
        # every type's range, (0, 0) for a type with no light this frame (all culled), and for
        # a type of an earlier frame: a program keeps the value it was given last
        self._range_uniforms = {**dict.fromkeys(self._range_uniforms, (0, 0)),
                                **dict.fromkeys(map(light_range_uniform, map(type, lights)),
                                                (0, 0)),
                                **{light_range_uniform(light_type): span
                                   for light_type, span in self.ranges.items()}}
        fullscreen = np.zeros((FULLSCREEN_LIGHT_CAPACITY, RECORD_VEC4S, 4), np.float32)
        fullscreen[:self.global_count] = records[:self.global_count, :RECORD_VEC4S]
        self._uniforms = {"u_light_count": self.count, "u_global_light_count": self.global_count,
                          FULLSCREEN_UNIFORM: fullscreen.tobytes(), **self._range_uniforms}
        self.culled = len(lights) - self.count
        width = records.shape[1]
        if rows > self._capacity or self._texture is None or self._texture.width != width:
            self._release_storage()
            self._capacity = min(max(rows, 16), limit)
            self._texture = self.ctx.texture((width, self._capacity), 4, dtype="f4")
            self._texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._texture.write(records.tobytes(), viewport=(0, 0, width, rows))

    def range(self, light_type: type[Light]) -> tuple[int, int]:
        return self.ranges.get(light_type, (0, 0))

    @property
    def local_count(self) -> int:
        """Volume lights (after culling), right after the full-screen ones."""
        return self.count - self.global_count

    @property
    def texture(self) -> moderngl.Texture:
        """The records' texture (``u_lights``), for compute shaders to sample."""
        return self._texture

    def bind(self, uniforms: ProgramUniforms, texture_unit: int) -> int:
        """Set the counts and ranges on a program, and bind the records at ``texture_unit``
        where it reads them (a binding source of the frame); the next free unit."""
        uniforms.set_shared("lights", self._uniforms)  # a new dict each upload
        if "u_lights" in uniforms.members:
            self._texture.use(location=texture_unit)
            uniforms.set_one("u_lights", texture_unit)
            return texture_unit + 1
        return texture_unit

    def _release_storage(self) -> None:
        self._packed = None
        if self._texture is not None:
            self._texture.release()
            self._texture = None

    def release(self) -> None:
        self._release_storage()
        self._capacity = 0
