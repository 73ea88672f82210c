"""All lights of a frame packed into one GPU buffer, read by both pipelines.

Each light is four vec4s (``Light.record``), its type id stored in ``color.w``; lights are grouped
by type so each deferred lighting pass draws one contiguous range. With GL 4.3 the records live in a
shader storage buffer (``LightBuffer`` block); on GL 3.3 in an RGBA32F texture, one row per light
(``u_lights``). ``common/light_buffer.glsl`` reads both.
"""

from __future__ import annotations

import moderngl
import numpy as np

from .context import Features
from .light import Light

RECORD_VEC4S = 4


class LightBuffer:
    def __init__(self, ctx: moderngl.Context, features: Features):
        self.ctx = ctx
        self.storage = features.storage_buffers
        self.count = 0
        self.ranges: dict[type[Light], tuple[int, int]] = {}
        self._buffer: moderngl.Buffer | None = None
        self._texture: moderngl.Texture | None = None
        self._capacity = 0

    @staticmethod
    def pack(lights: list[Light], view: np.ndarray) -> tuple[np.ndarray, dict]:
        ordered = sorted(lights, key=lambda light: light.type_id)  # stable: scene order kept
        records = np.zeros((max(len(ordered), 1), RECORD_VEC4S, 4), dtype=np.float32)
        ranges: dict[type[Light], tuple[int, int]] = {}
        for index, light in enumerate(ordered):
            record = np.asarray(light.record(view), dtype=np.float32).reshape(RECORD_VEC4S, 4)
            records[index] = record
            records[index, 0, 3] = float(light.type_id)
            start, count = ranges.get(type(light), (index, 0))
            ranges[type(light)] = (start, count + 1)
        return records, ranges

    def upload(self, lights: list[Light], view: np.ndarray) -> None:
        records, self.ranges = self.pack(lights, view)
        self.count = len(lights)
        rows = len(records)
        if rows > self._capacity:
            self._release_storage()
            self._capacity = max(rows, 16)
            if self.storage:
                self._buffer = self.ctx.buffer(reserve=self._capacity * RECORD_VEC4S * 16)
            else:
                self._texture = self.ctx.texture((RECORD_VEC4S, self._capacity), 4, dtype="f4")
                self._texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        if self.storage:
            self._buffer.write(records.tobytes())
        else:
            self._texture.write(records.tobytes(), viewport=(0, 0, RECORD_VEC4S, rows))

    def range(self, light_type: type[Light]) -> tuple[int, int]:
        return self.ranges.get(light_type, (0, 0))

    def bind(self, program: moderngl.Program, texture_unit: int) -> None:
        if "u_light_count" in program:
            program["u_light_count"].value = self.count
        if self.storage and "LightBuffer" in program:
            self._buffer.bind_to_storage_buffer(0)
            program["LightBuffer"].binding = 0
        elif not self.storage and "u_lights" in program:
            self._texture.use(location=texture_unit)
            program["u_lights"].value = texture_unit

    def _release_storage(self) -> None:
        if self._buffer is not None:
            self._buffer.release()
            self._buffer = None
        if self._texture is not None:
            self._texture.release()
            self._texture = None

    def release(self) -> None:
        self._release_storage()
        self._capacity = 0
