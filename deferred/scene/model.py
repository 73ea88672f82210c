"""The scene: camera, objects (mesh + transform + material), lights and effects, and its
timeline.

A scene may carry a timeline: ``[[event]]`` tables (``time``, ``object``, ``params``) that change
an object's material parameters from their time on, and keyframe tracks (``[[track]]``,
:mod:`deferred.scene.tracks`) that move the camera, lights and objects.
:meth:`SceneObject.params_at` gives an object's parameters at a time,
:meth:`SceneObject.model_at` its model matrix, :meth:`Scene.camera_at` and
:meth:`Scene.light_params_at` the camera and a light's parameters, and
:meth:`Scene.apply_timeline` sets them all (the renderer does so before each frame). Scene files
are read by :mod:`deferred.scene.loader`.
"""
from __future__ import annotations

import copy
import math
import numbers
import re
from bisect import bisect_right
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
from pydantic import ConfigDict, Field, field_validator, model_validator

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
from deferred.scene.tracks import (
    MIN_SCALE,
    Track,
    Turntable,
    decompose,
    make_track,
    scale_too_small,
)
from deferred.validation import StrictValues, join_where

Vec3 = tuple[float, float, float]
MAX_SIZE = 16384
MAX_DEPTH_RANGE = 1e7  # far / near
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
        if scale_too_small(scale):
            raise ValueError(f"must be at least {MIN_SCALE:g} in size")
        return scale


class CameraModel(StrictValues):
    """A scene file's ``[camera]``, checked (the loader's, and every camera the tracks make)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    position: Vec3 = (0.0, 1.0, 4.0)
    target: Vec3 = (0.0, 0.5, 0.0)
    up: Vec3 = (0.0, 1.0, 0.0)
    fov: float = Field(45.0, gt=1.0, lt=179.0, description="vertical field of view, degrees")
    near: float = Field(0.05, gt=0.0)
    far: float = Field(100.0, gt=0.0)

    @model_validator(mode="after")
    def _check(self) -> CameraModel:
        if self.far <= self.near:
            raise ValueError("far must be greater than near")
        if self.far / self.near > MAX_DEPTH_RANGE:
            # measured: at 1e8 the deferred pipeline's depth reconstruction loses the scene
            raise ValueError(f"far / near is {self.far / self.near:.3g}; at most "
                             f"{MAX_DEPTH_RANGE:g} (the depth buffer's precision): raise near "
                             "or lower far")
        if np.allclose(self.position, self.target):
            raise ValueError("position and target are the same point")
        forward = np.subtract(self.target, self.position, dtype=float)
        side = np.cross(forward / np.linalg.norm(forward), np.asarray(self.up, dtype=float))
        if np.linalg.norm(side) < 1e-6:
            raise ValueError("up is parallel to the view direction (or zero); "
                             "choose another up vector")
        return self


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
    # the placement ``model`` was made from, where known: the base of the object's tracks
    # (for a model given as a matrix alone, it is found from the matrix when first needed)
    transform: Transform | None = None
    tracks: tuple[Track, ...] = ()  # keyframe tracks of the transform (Scene.add_track)
    # params_at's validated states and the merged values they came from, by count of events
    # applied (cleared when the events change)
    _states: dict[int, MaterialParams] = field(default_factory=dict, init=False, repr=False)
    _values: dict[int, dict[str, Any]] = field(default_factory=dict, init=False, repr=False)
    _times: tuple[float, ...] = field(default=(), init=False, repr=False)
    # the parameters the timeline set last, and at what time (apply_time)
    _applied: MaterialParams | None = field(default=None, init=False, repr=False)
    _applied_time: float = field(default=0.0, init=False, repr=False)
    # the model matrix ``transform`` is the base of, and the one the tracks set last
    _base_model: np.ndarray | None = field(default=None, init=False, repr=False)
    _applied_model: np.ndarray | None = field(default=None, init=False, repr=False)
    # the contents of the model last seen as the base or set by the tracks (an in-place edit)
    _model_seen: np.ndarray | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        if self.base_params is None:
            self.base_params = self.material.params
        self._set_events(self.events)
        self._base_model = self.model
        self._model_seen = np.array(self.model)

    def _base_placement(self) -> Transform:
        """The placement the tracks animate: ``transform``, or, where ``model`` was set since
        the tracks last set it (or no placement is known), the placement of ``model``."""
        model = self.model
        # set by hand since: another array, or the tracks' or the base's array edited in place
        kept = (model is self._applied_model or model is self._base_model) and \
            self._model_seen is not None and np.array_equal(model, self._model_seen)
        if not kept:
            self._base_model, self.transform = model, None
            self._model_seen = np.array(model)
        if self.transform is None:
            position, rotation, scale = decompose(model)
            self.transform = Transform.model_construct(position=position, rotation=rotation,
                                                       scale=scale)
        return self.transform

    def model_at(self, time: float) -> np.ndarray:
        """The model matrix at ``time`` (seconds): the placement with the tracks' values at
        ``time`` over it; ``model`` itself for an object without tracks."""
        if not self.tracks:
            return self.model
        base = self._base_placement()
        values = {"position": base.position, "rotation": base.rotation, "scale": base.scale}
        for track in self.tracks:
            values.update(track.at(time))
        return model_matrix(values["position"], values["rotation"], values["scale"])

    def apply_tracks(self, time: float) -> None:
        """Set ``model`` to :meth:`model_at` ``time`` (objects with tracks)."""
        if self.tracks:
            self.model = self._applied_model = self.model_at(time)
            self._model_seen = np.array(self.model)

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



OPACITY_SCALES = (1.0, 0.5, 0.25, 0.125, 0.0625)  # ShadowBudget.opacity_scale's values


@dataclass(frozen=True)
class ShadowBudget:
    """The scene's shadow atlas (a ``[shadows]`` table): one depth texture of ``atlas_size``
    texels on a side holding every shadowed light's maps, for at most ``max_shadowed_lights``
    lights (those beyond, or whose maps do not fit, are drawn unshadowed, with a warning).
    Deep opacity maps (fur) have ``opacity_scale`` of the shadow maps' texels on a side, over
    the part of the atlas the lights' maps take."""

    atlas_size: int = 4096
    max_shadowed_lights: int = 16
    opacity_scale: float = 0.25


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
    shadow_budget: ShadowBudget = field(default_factory=ShadowBudget)
    effects: list[Effect] = field(default_factory=list)
    source: str = "<memory>"
    # the camera's and lights' keyframe tracks (add_track; objects keep theirs), the
    # turntable (set_turntable), and the lights' names (add_light, [[light]] name)
    tracks: list[Track] = field(default_factory=list)
    turntable: Turntable | None = None
    light_names: dict[str, Light] = field(default_factory=dict)
    # the camera and the lights' params the tracks animate, and what they set last
    _camera_base: Camera | None = field(default=None, init=False, repr=False, compare=False)
    _camera_applied: Camera | None = field(default=None, init=False, repr=False, compare=False)
    _light_bases: dict[int, tuple[Any, Any]] = field(default_factory=dict, init=False,
                                                     repr=False, compare=False)

    def apply_timeline(self, time: float) -> None:
        """Set everything the timeline moves to its state at ``time`` (seconds): each
        object's material parameters (objects with events; the others keep theirs) and model
        matrix (objects with tracks), the camera (camera tracks, the turntable) and the lights'
        parameters (lights with tracks). An object with events that shares its
        material instance with another object (``Scene.add`` takes an instance) is given a copy
        of its own first (``copy.copy``: so ``obj.material`` is another object from the first
        frame on, and state a material keeps in containers is shared by the copies), so its
        events never change the other."""
        if self.tracks or self.turntable is not None or self._camera_applied is not None:
            self._apply_tracks(time)
        users: dict[int, int] | None = None
        for obj in self.objects:
            if obj.tracks:
                obj.apply_tracks(time)
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
                raise InputError(f"no object named {obj[:80]!r} (objects: {names})",
                                 f"{where}.object" if where else "object")
            obj = found[0]
        return obj.add_event(time, params, where)

    # -- keyframe tracks -----------------------------------------------------------------------
    def add_track(self, target: str | SceneObject | Light, keys: Sequence[Mapping[str, Any]],
                  interpolation: str = "linear", where: str | None = None) -> Track:
        """Add a keyframe track (:mod:`deferred.scene.tracks`): ``target`` is ``"camera"``,
        ``"object:NAME"``, ``"light:INDEX"`` or ``"light:NAME"`` (or the object or light
        itself); ``keys`` a list of ``{"time": t, property: value, ...}`` in rising time;
        ``interpolation`` ``step``, ``linear`` or ``smooth``. Checked at once (``InputError``
        naming ``where``, default ``<source>: track[N]``, and the key): the keys, the
        properties the target has (a light's type), a property already moved by another
        track, and the camera and a light at every key's time. A renderer drawing the scene
        moves the target from its next frame."""
        where = where or f"{self.source}: track[{self._track_count()}]"
        subject: SceneObject | Light | None
        if isinstance(target, SceneObject):
            if not any(obj is target for obj in self.objects):
                raise InputError(f"the object {target.label!r} is not in the scene", "target")
            subject, target = target, f"object:{target.label}"
        elif isinstance(target, Light):
            subject = target
            index = next((i for i, light in enumerate(self.lights) if light is target), None)
            if index is None:
                raise InputError("the scene holds no such light", join_where(where, "target"))
            target = f"light:{index}"
        else:
            subject = None
        track = make_track(target, keys, interpolation, where)
        if subject is None and track.kind != "camera":
            subject = self._track_subject(track, join_where(where, "target"))
        if isinstance(subject, SceneObject):
            self._check_free(track, subject.tracks)
            subject.tracks = (*subject.tracks, track)
            try:
                for time in track.key_times:
                    subject.model_at(time)
            except BaseException:
                subject.tracks = subject.tracks[:-1]
                raise
            return track
        track = replace(track, subject=subject)
        if isinstance(subject, Light):
            fields = type(subject.params).model_fields
            for prop, curve in track.curves.items():
                if prop not in fields:
                    have = [p for p in ("position", "direction", "color", "intensity")
                            if p in fields]
                    raise InputError(f"a {type(subject).name} light has no {prop} (its keys may "
                                     f"set {', '.join(have)})",
                                     join_where(where, f"keys[{curve.keys[0]}].{prop}"))
        self._check_free(track, [t for t in self.tracks if t.subject is subject])
        self.tracks.append(track)
        try:  # the camera and the light as each key leaves them
            for time in track.key_times:
                if subject is None:
                    self.camera_at(time)
                else:
                    self.light_params_at(subject, time)
        except BaseException:
            self.tracks.remove(track)
            raise
        return track

    def _track_count(self) -> int:
        return len(self.tracks) + sum(len(obj.tracks) for obj in self.objects)

    def _track_subject(self, track: Track, where: str) -> SceneObject | Light:
        """The object or light ``track.name`` names."""
        name = track.name
        if track.kind == "object":
            found = [o for o in self.objects if o.label == name]
            if not found:
                names = ", ".join(o.label[:40] for o in self.objects[:10]) or "none"
                raise InputError(f"no object named {name[:80]!r} (objects: {names})", where)
            return found[0]
        light = self.light_names.get(name)
        if light is not None and any(held is light for held in self.lights):
            return light
        if name.isdigit() and int(name) < len(self.lights):
            return self.lights[int(name)]
        names = [n for n, held in self.light_names.items() if any(held is h for h in self.lights)]
        have = ("no lights" if not self.lights else "light:0" if len(self.lights) == 1
                else f"light:0 to light:{len(self.lights) - 1}")
        if names:
            have += ", or by name: " + ", ".join(n[:40] for n in names[:10])
        raise InputError(f"no light {name[:80]!r} (the scene has {have})", where)

    @staticmethod
    def _check_free(track: Track, others: Sequence[Track]) -> None:
        """No property of ``track`` is moved by another track of its target already."""
        for other in others:
            for prop in track.curves:
                if prop in other.curves:
                    raise InputError(f"{track.target}'s {prop} is moved by {other.where} "
                                     "already (one track a property)",
                                     join_where(track.where,
                                                f"keys[{track.curves[prop].keys[0]}].{prop}"))

    def set_turntable(self, period: float | None, start: float = 0.0) -> Turntable | None:
        """Orbit the camera about the vertical through its target once every ``period``
        seconds from ``start`` (over camera tracks, which move what it orbits); ``None``
        stops it. Frames ``start + i * period / n`` for i in 0..n-1 are an n-frame loop."""
        self.turntable = None if period is None else Turntable(period, start)
        return self.turntable

    def camera_at(self, time: float) -> Camera:
        """The camera at ``time``: the scene's camera with the camera tracks' values at
        ``time`` over it, orbited by the turntable; checked as a scene file's camera is
        (``InputError`` naming the track and the time)."""
        camera = self.camera
        if camera is not self._camera_applied or self._camera_base is None:
            self._camera_base = camera  # set by hand since the tracks set it: the base now
        base = self._camera_base
        values: dict[str, Any] = {}
        where = "camera"
        for track in self.tracks:
            if track.kind == "camera":
                values.update(track.at(time))
                where = track.where
        if self.turntable is not None:
            values["position"] = self.turntable.orbit(values.get("position", base.position),
                                                      values.get("target", base.target), time)
            where = where if where != "camera" else "turntable"
        if not values:
            return base
        moved = replace(base, **values)
        try:
            validate_params(CameraModel, asdict(moved), None)
        except InputError as exc:
            raise InputError(f"the camera at t = {time:g} s: {exc}", where) from None
        return moved

    def light_params_at(self, light: Light, time: float) -> Any:
        """``light``'s parameters at ``time``: its own with its tracks' values at ``time``
        over them, validated (``InputError`` naming the track and the time)."""
        base = self._light_base(light)
        values: dict[str, Any] = {}
        where = None
        for track in self.tracks:
            if track.subject is light:
                values.update(track.at(time))
                where = track.where
        if not values:
            return base
        try:
            return validate_params(type(base), {**base.model_dump(), **values}, None)
        except InputError as exc:
            raise InputError(f"the light at t = {time:g} s: {exc}", where) from None

    def _light_base(self, light: Light) -> Any:
        kept = self._light_bases.get(id(light))
        if kept is None or (light.params is not kept[1] and light.params is not kept[0]):
            kept = (light.params, None)  # set by hand since the tracks set them: the base
            self._light_bases[id(light)] = kept
        return kept[0]

    def check_tracks(self, times: Sequence[float]) -> None:
        """The camera's and the lights' tracks at each of ``times``, checked before any frame
        is drawn (a camera passing through its target between keys, a light's direction
        through zero): ``InputError`` naming the track and the time."""
        moving_camera = self.turntable is not None or \
            any(t.kind == "camera" for t in self.tracks)
        lights = {id(t.subject): t.subject for t in self.tracks if t.kind == "light"}
        if not (moving_camera or lights):
            return
        for time in times:
            if moving_camera:
                self.camera_at(time)
            for light in lights.values():
                self.light_params_at(light, time)

    def _apply_tracks(self, time: float) -> None:
        """The camera's and the lights' tracks (and the turntable) at ``time``."""
        if self.turntable is not None or any(t.kind == "camera" for t in self.tracks):
            self.camera = self._camera_applied = self.camera_at(time)
        elif self._camera_applied is not None:
            if self.camera is self._camera_applied:  # what moved it is gone: back to its base
                self.camera = self._camera_base
            self._camera_applied = None
        lights = {id(t.subject): t.subject for t in self.tracks if t.kind == "light"}
        for light in lights.values():
            params = self.light_params_at(light, time)
            self._light_bases[id(light)] = (self._light_bases[id(light)][0], params)
            light.params = params

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
                          model_matrix(place.position, place.rotation, place.scale),
                          transform=place)
        self.objects.append(obj)
        return obj

    add = add_object  # the shorter name of earlier versions

    def add_light(self, type: str, name: str | None = None, **params: Any) -> Light:
        """Add a light of a registered ``type`` (``point``, ``spot``, ``directional``,
        ``ambient``, a plugin's) with its parameters, validated as a scene file's are
        (``InputError`` naming the light and the key); ``name`` lets tracks say
        ``light:NAME``. A renderer drawing the scene lights with it from its next frame."""
        if name is not None:
            check_light_name(name, self.light_names, "name")
        light = registry.lights.get(type, "type").from_dict(
            params, f"light[{len(self.lights)}] ({type})")
        self.lights.append(light)
        if name is not None:
            self.light_names[name] = light
        return light

    def remove(self, item: SceneObject | Light | Effect | str) -> None:
        """Remove an object (itself or its label), a light or an effect; ``InputError`` when
        the scene does not hold it. A renderer drawing the scene leaves it out from its next
        frame."""
        if isinstance(item, str):
            found = [o for o in self.objects if o.label == item]
            if not found:
                names = ", ".join(o.label for o in self.objects[:10]) or "none"
                raise InputError(f"no object named {item[:80]!r} (objects: {names})", "item")
            item = found[0]
        for collection in (self.objects, self.lights, self.effects):
            for index, held in enumerate(collection):
                if held is item:
                    del collection[index]
                    if isinstance(item, Light):  # its tracks and name go with it
                        self.tracks = [t for t in self.tracks if t.subject is not item]
                        self.light_names = {n: light for n, light in self.light_names.items()
                                            if light is not item}
                    return
        raise InputError(f"the scene holds no {type(item).__name__} {item!r:.80}", "item")


def check_light_name(name: Any, taken: Mapping[str, Any], where: str) -> None:
    """A light's name: printable text, not a number (``light:0`` is the first light's
    index), not taken."""
    if not isinstance(name, str) or not name or name.isdigit() or \
            any(ord(c) < 32 or ord(c) == 127 for c in name) or len(name) > 1000:
        raise InputError(f"a light's name is printable text and not a number (light:0 is the "
                         f"first light), got {name!r:.80}", where)
    if name in taken:
        raise InputError(f"a light is named '{name[:80]}' already", where)


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
