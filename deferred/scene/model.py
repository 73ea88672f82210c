"""The scene: camera, objects (mesh + transform + material), lights and effects, and its
timeline.

A scene may carry a timeline: ``[[event]]`` tables (``time``, ``object``, ``params``) that change
an object's material parameters from their time on. :meth:`SceneObject.params_at` gives an
object's parameters at a time and :meth:`Scene.apply_timeline` sets them on every object with
events (the renderer does so before each frame). Scene files are read by
:mod:`deferred.scene.loader`.
"""
from __future__ import annotations

import copy
import math
import numbers
import re
from bisect import bisect_right
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
from pydantic import ConfigDict, field_validator

from deferred.core.passes import Phase
from deferred.errors import InputError
from deferred.gbuffer.layout import GBufferLayout
from deferred.gl.meshes import MeshData
from deferred.interfaces import registry
from deferred.interfaces.effect import Effect
from deferred.interfaces.light import Light
from deferred.interfaces.material import Material, MaterialParams, compose_layout
from deferred.interfaces.shading import ShadingModel
from deferred.params import validate_params
from deferred.scene.camera import Camera, model_matrix
from deferred.scene.meshes import load_mesh
from deferred.validation import StrictValues

Vec3 = tuple[float, float, float]
MAX_SIZE = 16384
MIN_SCALE = 1e-6  # an object smaller is a mistake of units; 1/scale must fit float32
SIZE_TEXT = re.compile(r"([0-9]+)\s*[xX]\s*([0-9]+)")


class Transform(StrictValues):
    """An object's placement as a scene file gives it: finite numbers, a scale of at least
    ``MIN_SCALE`` on each axis (its normal matrix would overflow float32)."""

    model_config = ConfigDict(extra="forbid")
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotation: tuple[float, float, float] = (0.0, 0.0, 0.0)  # degrees, X then Y then Z
    scale: float | tuple[float, float, float] = 1.0

    @field_validator("scale")
    @classmethod
    def _check_scale(cls, scale: float | tuple[float, float, float]):
        if np.any(np.abs(np.broadcast_to(np.asarray(scale, dtype=float), (3,))) < MIN_SCALE):
            raise ValueError(f"must be at least {MIN_SCALE:g} in size")
        return scale


@dataclass(frozen=True)
class TimelineEvent:
    """From ``time`` (seconds) on, an object's material takes ``params`` (validated, as given);
    ``where`` names the event in errors (``scene.toml: event[2]``)."""

    time: float
    params: Mapping[str, Any]
    where: str | None = None


@dataclass(eq=False)  # identity: the model matrix is an array, and objects are unique anyway
class SceneObject:
    """A mesh drawn with a material at a transform.

    ``base_params`` are the material's parameters before any event (default: the material's
    parameters when the object is made); ``events`` its timeline, kept sorted by time (ties in
    the order given).
    """

    label: str
    mesh: MeshData
    material: Material
    model: np.ndarray
    base_params: MaterialParams | None = None
    events: tuple[TimelineEvent, ...] = ()
    where: str | None = None  # names the object in errors (``scene.toml: object[2]``)
    # params_at's validated states and the merged values they came from, by count of events
    # applied (cleared when the events change)
    _states: dict[int, MaterialParams] = field(default_factory=dict, init=False, repr=False)
    _values: dict[int, dict[str, Any]] = field(default_factory=dict, init=False, repr=False)
    _times: tuple[float, ...] = field(default=(), init=False, repr=False)
    # the parameters the timeline set last, and at what time (apply_time)
    _applied: MaterialParams | None = field(default=None, init=False, repr=False)
    _applied_time: float = field(default=0.0, init=False, repr=False)

    def __post_init__(self) -> None:
        if self.base_params is None:
            self.base_params = self.material.params
        self._set_events(self.events)

    def _set_events(self, events) -> None:
        self.events = tuple(sorted(events, key=lambda event: event.time))  # stable
        self._times = tuple(event.time for event in self.events)
        self._states.clear()
        self._values.clear()

    @property
    def event_times(self) -> tuple[float, ...]:
        """The times of this object's events, sorted."""
        return self._times

    def params_at(self, time: float) -> MaterialParams:
        """The material parameters at ``time``: ``base_params`` updated by every event with
        ``event.time <= time``, in time order (ties: the order given). Validated once per
        distinct set of events applied, then cached; the merged values are made from the
        nearest earlier set's, so asking every event time in turn costs each event once."""
        count = bisect_right(self._times, time)
        if count == 0:
            return self.base_params
        state = self._states.get(count)
        if state is None:
            where = self.events[count - 1].where
            state = validate_params(type(self.base_params), self._merged(count),
                                    f"{where}.params" if where else f"{self.label}: params")
            self._states[count] = state
        return state

    def _merged(self, count: int) -> dict[str, Any]:
        """``base_params`` with the first ``count`` events' params over them."""
        known = count
        while known > 0 and known not in self._values:
            known -= 1
        values = self._values[known] if known else self.base_params.model_dump()
        for index in range(known, count):
            values = {**values, **self.events[index].params}
            self._values[index + 1] = values
        return values

    def add_event(self, time: float, params: Mapping[str, Any],
                  where: str | None = None) -> TimelineEvent:
        """Add an event: from ``time`` (seconds, finite, >= 0) on, the material takes
        ``params``. ``params`` are checked over ``base_params`` at once, and so is the
        object's state at every event time from this one on; errors name ``where``."""
        return self.add_events([(time, params, where)])[0]

    def add_events(self, events: Sequence[tuple[float, Mapping[str, Any], str | None]]
                   ) -> list[TimelineEvent]:
        """:meth:`add_event` for several ``(time, params, where)`` at once: each is checked
        alone, then every state from the earliest of their times on is checked once (a
        scene file's events are added so: the cost grows with the events, not their
        square). None is kept if any is refused."""
        made = [self._checked_event(time, params, where) for time, params, where in events]
        if not made:
            return []
        previous = self.events
        self._set_events((*previous, *made))
        earliest = min(event.time for event in made)
        try:  # the merged states from its time on (the parameters' own cross-checks)
            for later in sorted({t for t in self._times if t >= earliest}):
                self.params_at(later)
            self._check_growing()
        except InputError:
            self._set_events(previous)
            raise
        self._values.clear()  # every state is made: the merged values are not needed again
        return made

    def _check_growing(self) -> None:
        """The material's ``timeline_growing`` parameters never fall from one state of the
        timeline to the next (an event lowering one would be ignored by its simulation)."""
        growing = type(self.material).timeline_growing
        if not growing:
            return
        before = self.base_params
        for time in sorted(set(self._times)):
            state = self.params_at(time)
            for key in growing:
                if getattr(state, key) < getattr(before, key):
                    event = self.events[bisect_right(self._times, time) - 1]
                    where = f"{event.where or self.label + ': event'}.params.{key}"
                    raise InputError(f"{key} may rise on a timeline, not fall (from "
                                     f"{getattr(before, key)} to {getattr(state, key)} at "
                                     f"{time:g} s): what it counts has happened", where)
            before = state

    def _checked_event(self, time: float, params: Mapping[str, Any],
                       where: str | None) -> TimelineEvent:
        where = where or f"{self.label}: event"
        if not (isinstance(time, int | float) and math.isfinite(time) and time >= 0.0):
            raise InputError(f"must be a finite number of seconds >= 0, got {time!r}",
                             f"{where}.time")
        params_where = f"{where}.params"
        material_cls = type(self.material)
        for key in material_cls.timeline_fixed:
            if key in params and params[key] != getattr(self.base_params, key, None):
                raise InputError(f"{material_cls.name} reads {key} once, at t = 0: a timeline "
                                 "cannot change it", f"{params_where}.{key}")
        # Every key checked against the material's model over the base (files, too)
        changed = material_cls.from_dict({**self.base_params.model_dump(), **params},
                                         self.material.base_dir, params_where)
        self._check_same_passes(changed, params, params_where)
        return TimelineEvent(float(time), MappingProxyType(dict(params)), where)

    def _check_same_passes(self, changed: Material, params: Mapping[str, Any],
                           where: str) -> None:
        """The pass graph is built once, from the parameters at t = 0: an event whose
        parameters would add or remove passes (fins on, shells from 0) cannot take effect."""
        def names(material: Material) -> list[str]:
            return [p.name for phase in Phase for p in material.passes(phase, self)]

        base = type(self.material)(self.base_params, self.material.base_dir)
        before, after = names(base), names(changed)
        if before != after:
            keys = [k for k in params if params[k] != getattr(self.base_params, k, None)]
            added = sorted(set(after) - set(before))
            removed = sorted(set(before) - set(after))
            change = ", ".join([*(f"+{n}" for n in added), *(f"-{n}" for n in removed)])
            raise InputError(f"changing {', '.join(keys) or 'these parameters'} on a timeline "
                             f"would change the object's passes ({change}), which are built "
                             "once from t = 0; set it in the object's own params",
                             f"{where}.{keys[0]}" if len(keys) == 1 else where)

    @property
    def params(self) -> MaterialParams:
        """The material's parameters as drawn last (the timeline's state at the frame's time
        for an object with events). Change them with :meth:`set_params`."""
        return self.material.params

    def set_params(self, **values: Any) -> MaterialParams:
        """Change material parameters from Python, validated as a scene file's are
        (``InputError`` naming the object and the key: ``ball: params.shells: ...``); returns
        the new parameters. They become the object's base: a timeline's events apply over
        them from their times on, and every state of the timeline is checked again. The object
        gets a material instance of its own first, so objects that shared one keep theirs. A
        renderer drawing the object picks the change up at its next frame (and rebuilds its
        passes where the change adds or removes some)."""
        where = f"{self.where}.params" if self.where else f"{self.label}: params"
        material_cls = type(self.material)
        changed = material_cls.from_dict({**self.base_params.model_dump(), **values},
                                         self.material.base_dir, where)
        previous = self.base_params
        self.base_params = changed.params
        self._states.clear()
        self._values.clear()
        try:
            # each event again over the new base: what a timeline may not change
            # (timeline_fixed, the passes), then every state and what may only rise
            for event in self.events:
                self._checked_event(event.time, event.params, event.where)
            for time in sorted(set(self._times)):
                self.params_at(time)
            self._check_growing()
        except InputError:
            self.base_params = previous
            self._states.clear()
            raise
        self._values.clear()
        self.material = copy.copy(self.material)
        self.material.params = self.params_at(self._applied_time)
        self._applied = self.material.params
        return self.base_params

    def apply_time(self, time: float) -> None:
        """Set the material's parameters to those of ``time`` (objects with events). Parameters
        assigned to ``material.params`` since the last time become the base, as
        :meth:`set_params` makes them, rather than being overwritten by the timeline."""
        if self._applied is not None and self.material.params is not self._applied:
            # what the assignment changed from the timeline's state, not that state itself
            assigned, applied = self.material.params.model_dump(), self._applied.model_dump()
            self.set_params(**{key: value for key, value in assigned.items()
                               if value != applied.get(key)})
        self._applied_time = time
        self.material.params = self._applied = self.params_at(time)

    def with_material(self, material: Material,
                      overrides: Mapping[str, Any] | None = None) -> SceneObject:
        """A copy of this object drawn with ``material``, whose parameters become the base;
        ``overrides`` (the parameters that made them) join every event too, so they hold at
        every time of the timeline (bench sweeps, debug views)."""
        events = tuple(replace(event, params=MappingProxyType({**event.params, **overrides}))
                       for event in self.events) if overrides else self.events
        return replace(self, material=material, base_params=material.params, events=events)


@dataclass
class Scene:
    """A scene ready to render (meshes loaded, materials and lights validated)."""

    camera: Camera = field(default_factory=Camera)
    objects: list[SceneObject] = field(default_factory=list)
    lights: list[Light] = field(default_factory=list)
    size: tuple[int, int] = (1280, 720)
    background: tuple[float, float, float] = (0.02, 0.02, 0.025)
    exposure: float = 1.0
    tonemap: str = "aces"
    light_path: str | None = None
    effects: list[Effect] = field(default_factory=list)
    source: str = "<memory>"

    def apply_timeline(self, time: float) -> None:
        """Set each object's material parameters to those of ``time`` (seconds): objects
        with events only; the others keep theirs. An object with events that shares its
        material instance with another object (``Scene.add`` takes an instance) is given a copy
        of its own first (``copy.copy``: so ``obj.material`` is another object from the first
        frame on, and state a material keeps in containers is shared by the copies), so its
        events never change the other."""
        users: dict[int, int] | None = None
        for obj in self.objects:
            if not obj.events:
                continue
            if users is None:
                users = Counter(id(other.material) for other in self.objects)
            if users[id(obj.material)] > 1:
                users[id(obj.material)] -= 1
                obj.material = copy.copy(obj.material)
                users[id(obj.material)] = 1
            obj.apply_time(time)

    def add_event(self, obj: SceneObject | str, time: float, params: Mapping[str, Any],
                  where: str | None = None) -> TimelineEvent:
        """:meth:`SceneObject.add_event` for the object ``obj`` or the one labelled so."""
        if isinstance(obj, str):
            found = [o for o in self.objects if o.label == obj]
            if not found:
                names = ", ".join(o.label[:40] for o in self.objects[:10]) or "none"
                if len(self.objects) > 10:
                    names += f", ... ({len(self.objects)} in all)"
                raise InputError(f"no object named '{obj[:80]}' (objects: {names})",
                                 f"{where}.object" if where else "object")
            obj = found[0]
        return obj.add_event(time, params, where)

    def gbuffer_layout(self) -> GBufferLayout:
        """The G-buffer of this scene: the core plus the data its materials declare."""
        return compose_layout(obj.material for obj in self.objects)

    def shading_models(self) -> list[type[ShadingModel]]:
        """The shading models the scene's materials use, by id (only these are compiled)."""
        found = {registry.shading_models.get(obj.material.shading_model)
                 for obj in self.objects}
        return sorted(found, key=lambda cls: cls.type_id)

    def light_types(self) -> list[type[Light]]:
        """The light types of the scene, by id (only these are compiled)."""
        return sorted({type(light) for light in self.lights}, key=lambda cls: cls.type_id)

    def add_object(self, mesh: MeshData | str, material: Material | str = "standard",
                   position=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0), scale=1.0,
                   label: str | None = None, params: Mapping[str, Any] | None = None,
                   base_dir: str | Path | None = None) -> SceneObject:
        """Add an object: ``mesh`` a :class:`MeshData` or a name as a scene file gives it
        (``builtin:torus?segments=78``, a file relative to ``base_dir``); ``material`` a
        registered name with ``params`` (validated as a scene file's are) or an instance;
        position, rotation (degrees, XYZ) and scale as in a scene file. Errors are
        ``InputError``s naming the argument (``mesh``, ``material``, ``ball: params.shells``).
        A renderer drawing the scene draws the object from its next frame."""
        if label is not None and not (isinstance(label, str) and label.strip()):
            raise InputError(f"must be a name, got {label!r}", "label")
        taken = {o.label for o in self.objects}
        if label in taken:
            raise InputError(f"an object is named '{label}' already", "label")
        folder = None if base_dir is None else Path(base_dir)
        if isinstance(mesh, str):
            mesh = load_mesh(mesh, folder, "mesh")
        elif not isinstance(mesh, MeshData):
            raise InputError(f"expected a MeshData or a mesh name, got {type(mesh).__name__}",
                             "mesh")
        label = label or unique_label(taken, mesh.name)
        if isinstance(material, str):
            material = registry.materials.get(material, "material").from_dict(
                dict(params or {}), folder, f"{label}: params")
        elif not isinstance(material, Material):
            raise InputError(f"expected a Material or a material name, got "
                             f"{type(material).__name__}", "material")
        elif params:
            raise InputError("give params with a material name; an instance has its own",
                             "params")
        place = validate_params(Transform, {"position": position, "rotation": rotation,
                                            "scale": scale}, None)
        obj = SceneObject(label, mesh, material,
                          model_matrix(place.position, place.rotation, place.scale))
        self.objects.append(obj)
        return obj

    add = add_object  # the shorter name of earlier versions

    def add_light(self, type: str, **params: Any) -> Light:
        """Add a light of a registered ``type`` (``point``, ``spot``, ``directional``,
        ``ambient``, a plugin's) with its parameters, validated as a scene file's are
        (``InputError`` naming the light and the key). A renderer drawing the scene lights
        with it from its next frame."""
        light = registry.lights.get(type, "type").from_dict(
            params, f"light[{len(self.lights)}] ({type})")
        self.lights.append(light)
        return light

    def remove(self, item: SceneObject | Light | Effect | str) -> None:
        """Remove an object (itself or its label), a light or an effect; ``InputError`` when
        the scene does not hold it. A renderer drawing the scene leaves it out from its next
        frame."""
        if isinstance(item, str):
            found = [o for o in self.objects if o.label == item]
            if not found:
                names = ", ".join(o.label for o in self.objects[:10]) or "none"
                raise InputError(f"no object named '{item[:80]}' (objects: {names})", "item")
            item = found[0]
        for collection in (self.objects, self.lights, self.effects):
            for index, held in enumerate(collection):
                if held is item:
                    del collection[index]
                    return
        raise InputError(f"the scene holds no {type(item).__name__} {item!r:.80}", "item")


def unique_label(taken: set[str], mesh_name: str, next_index: dict[str, int] | None = None
                 ) -> str:
    """``<mesh stem><n>`` with the least ``n`` not ``taken``. ``next_index`` (kept by a caller
    naming many objects, whose ``taken`` only grows) starts each stem's search where its last
    one ended, so naming n objects costs n, not n squared."""
    stem = mesh_name.removeprefix("builtin:").rsplit(".", 1)[0] or "object"
    index = next_index.get(stem, 0) if next_index is not None else 0
    while f"{stem}{index}" in taken:
        index += 1
    if next_index is not None:
        next_index[stem] = index
    return f"{stem}{index}"


def parse_size(text: str, where: str = "--size") -> tuple[int, int]:
    match = SIZE_TEXT.fullmatch(text.strip())  # digits only: int() takes "1_60" and "+160"
    if match is None:
        raise InputError(f"expected WIDTHxHEIGHT such as 1280x720, got '{text}'", where)
    return check_size((int(match.group(1)), int(match.group(2))), where)


def check_size(size: tuple[int, int], where: str) -> tuple[int, int]:
    """``size`` as (width, height) in whole pixels, each 1..``MAX_SIZE``; ``InputError``
    naming ``where`` otherwise (a string, three numbers, a fraction of a pixel)."""
    if isinstance(size, np.ndarray) and size.ndim == 1:
        size = size.tolist()
    if isinstance(size, str | bytes) or not isinstance(size, Sequence) or len(size) != 2 or \
            not all(isinstance(side, numbers.Integral) and not isinstance(side, bool)
                    for side in size):
        raise InputError(f"expected (width, height) in whole pixels, e.g. (1280, 720), "
                         f"got {size!r}", where)
    width, height = (int(side) for side in size)
    if not (1 <= width <= MAX_SIZE and 1 <= height <= MAX_SIZE):
        raise InputError(f"size {width}x{height} is impossible (each side 1..{MAX_SIZE})", where)
    return width, height
