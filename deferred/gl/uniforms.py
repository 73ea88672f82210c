"""Writing a program's uniforms, each only when its value changes.

GL keeps uniform values per program. A pass drawing many objects with one program (every
``standard`` object's G-buffer pass) used to write the camera, the light ranges and the material
again for each object; now only what differs from the program's last values reaches GL, and a
value is converted once (matrices to column-major bytes).

The values a :class:`ProgramUniforms` remembers are right only while every write to the program
goes through it: the frame writes uniforms only through here, and forgets the values when a frame
starts (``ShaderLibrary.forget_uniform_values``), so code between frames may write a program
directly.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Mapping
from typing import Any

import moderngl
import numpy as np

_UNSET = object()


class StableValues(dict):
    """Uniform values that are replaced, never changed in place (:meth:`ProgramUniforms
    .set_stable`). They hold what each program works out from them (``plans``, made on their
    first use), which so goes with them."""

    # ProgramUniforms -> the (name, GL value) pairs of these values that its program has: the
    # instance's own once set (a class default, not an __init__, which would cost each a call)
    plans: dict | None = None


_ONCE = object()  # a plan's place after the values' first use (set_stable)


def gl_value(value: Any) -> Any:
    """``value`` as moderngl takes it: a 2-D array becomes column-major float32 bytes (GLSL's
    matrix order), a 1-D array a tuple of floats; bytes (a matrix already converted) and
    numbers stay as they are."""
    if isinstance(value, np.ndarray):
        if value.ndim == 0:
            return value.item()
        if value.ndim == 2:
            return np.ascontiguousarray(value.T, dtype=np.float32).tobytes()
        return tuple(float(v) for v in value)
    return value


class ProgramUniforms:
    """The active uniforms of one program and the values last written to them.

    :meth:`set_shared` takes a dict many passes of a frame share (the camera, the light
    counts): while the program still holds that very dict's values it is not even looked
    through, which is most of the saving for a program drawing many objects.
    """

    __slots__ = ("members", "_program", "_writers", "_values", "_shared", "_owner")

    def __init__(self, program: moderngl.Program | moderngl.ComputeShader,
                 members: frozenset[str] | None = None):
        self._program = program
        # uniforms and blocks (``name in program`` walks every member each time)
        self.members: frozenset[str] = frozenset(program) if members is None else members
        self._writers: dict[str, Callable[[Any], None]] = {}  # name -> writes a value to GL
        self._values: dict[str, Any] = {}
        self._shared: dict[str, Mapping[str, Any]] = {}  # group -> the dict the program holds
        self._owner: dict[str, str] = {}  # uniform name -> the group it was last set by

    def set(self, values: Mapping[str, Any], _group: str | None = None) -> None:
        """Write the values the program has and does not hold already; names it lacks are
        skipped (:meth:`Frame.bind` checks them in strict mode)."""
        # the comparisons inline: a pass of many objects sets a few values a draw, and a call
        # a value was most of the cost (benchmarks/README.md); a call a write remains
        held = self._values
        members = self.members
        for name, value in values.items():  # a few values: cheaper than a set intersection
            if name not in members:
                continue
            if isinstance(value, np.ndarray):
                value = gl_value(value)
            if held.get(name, _UNSET) != value:
                self._write(name, value, _group)

    def set_stable(self, values: Mapping[str, Any]) -> None:
        """:meth:`set` for :class:`StableValues` (an object's transforms, a material's kept
        inputs): which of their names the program has, and their GL values, are worked out
        once, the second time they are set, not at every draw; the plan lasts as long as the
        values. Any other mapping is set by :meth:`set` (it may change in place)."""
        if values.__class__ is not StableValues:
            self.set(values)
            return
        plans = values.plans
        if plans is None:
            plans = values.plans = {}
        plan = plans.get(self)
        if plan is None or plan is _ONCE:
            if plan is None:  # values set once are set as a dict is (objects that move: their
                plans[self] = _ONCE  # transforms are new every frame): planned the second time
                self.set(values)
                return
            plan = plans[self] = tuple((name, gl_value(value)) for name, value in values.items()
                                       if name in self.members)
        held = self._values
        for name, value in plan:
            if held.get(name, _UNSET) != value:
                self._write(name, value)

    def _write(self, name: str, value: Any, group: str | None = None) -> None:
        """Write ``value`` to GL and remember it; ``group``: the shared dict writing it."""
        writer = self._writers.get(name)
        if writer is None:  # the first write: made once, then the one kept
            self._writers[name] = uniform_writer(self._program[name])
            writer = self._writers[name]
        writer(value)
        self._values[name] = value
        owner = self._owner.get(name)
        if owner is not None and owner != group:  # a shared dict's value overwritten
            self._shared.pop(owner, None)

    def set_shared(self, group: str, values: Mapping[str, Any]) -> None:
        """:meth:`set` for a dict shared by many passes, skipped while the program holds its
        values (the dict must not change while it is in use: pass a new one instead)."""
        if self._shared.get(group) is values:
            return
        self.set(values, group)
        for name in values:
            self._owner[name] = group
        self._shared[group] = values

    def bind_samplers(self, samplers: Mapping[str, Any], unit: int) -> int:
        """Bind the samplers the program has to units ``unit``, ``unit + 1``, ... (a later one
        of a name the program already took wins it); the next free unit."""
        members = self.members
        for name, texture in samplers.items():
            if name in members:
                texture.use(location=unit)
                self.set_one(name, unit)
                unit += 1
        return unit

    def set_one(self, name: str, value: Any) -> None:
        """Write one value the program has (one it lacks is skipped)."""
        if name in self.members:
            self.set({name: gl_value(value)})

    @property
    def written(self) -> Any:
        """The names written since the values were last forgotten (strict mode's check of
        uniforms nothing sets: ``ShaderLibrary.unset_uniforms``)."""
        return self._values.keys()

    def forget(self) -> None:
        """Drop the remembered values: the next write of each name reaches GL."""
        self._values.clear()
        self._shared.clear()


def uniform_writer(handle: Any) -> Callable[[Any], None]:
    """A function writing a value (bytes, a number or a sequence) to the uniform ``handle``.

    moderngl 5.12 and later write a uniform through two Python layers (``Uniform.value``
    packs with ``struct`` and calls ``Uniform.write``, which calls the context); for a uniform
    that is not an array this packs with a precompiled ``struct.Struct`` and calls the
    context's writer directly, the same bytes to the same call in a third of the time (a
    G-buffer pass of many objects writes two or three uniforms a draw). Other handles, and
    other moderngl versions, take the handle's own ``write`` and ``value``.
    """
    write_uniform = getattr(getattr(handle, "ctx", None), "_write_uniform", None)
    fmt = getattr(handle, "fmt", None)
    if write_uniform is None or fmt is None or getattr(handle, "array_length", None) != 1:
        size = getattr(handle, "array_length", 1) * getattr(handle, "element_size", 0)

        def write_by_handle(value: Any) -> None:
            if isinstance(value, bytes):
                # an array whose tail the program does not use is shorter than declared
                handle.write(value[:size] if size and len(value) > size else value)
            else:
                handle.value = value
        return write_by_handle
    program, location, gl_type = handle.program_obj, handle.location, handle.gl_type
    size = handle.element_size
    pack = struct.Struct(fmt).pack

    if handle.dimension > 1:
        def write(value: Any) -> None:
            write_uniform(program, location, gl_type, 1, size,
                          value if value.__class__ is bytes else pack(*value))
    else:
        def write(value: Any) -> None:
            write_uniform(program, location, gl_type, 1, size,
                          value if value.__class__ is bytes else pack(value))
    return write
