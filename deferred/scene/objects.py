"""Scene objects: a mesh drawn with a material at a node of the scene graph, and the object's
timeline of material parameters (``[[event]]`` tables: from a time on, some parameters change).

The object's material holds its parameters as the user set them (the *base*); an event never
writes them: :meth:`SceneObject.params_at` gives the parameters at a time, and each frame's
state (``deferred.scene.timeline``) carries a material with those.
"""

from __future__ import annotations

import copy
import math
from bisect import bisect_right
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from deferred.core.passes import Phase
from deferred.errors import InputError
from deferred.gl.meshes import MeshData
from deferred.interfaces.material import Material, MaterialParams
from deferred.params import validate_params
from deferred.scene.nodes import SceneNode
from deferred.scene.skin import Skin
from deferred.scene.transform import Transform


@dataclass(frozen=True)
class TimelineEvent:
    """From ``time`` (seconds) on, an object's material takes ``params`` (validated, as given);
    ``where`` names the event in errors (``scene.toml: event[2]``)."""

    time: float
    params: Mapping[str, Any]
    where: str | None = None


class SceneObject(SceneNode):
    """A mesh drawn with a material, placed at a node of the scene graph.

    ``material.params`` are the object's parameters before any event (its base: what the
    user set); ``events`` its timeline, kept sorted by time (ties in the order given).
    ``model`` is the local matrix (the world's for an object without a parent).
    """

    def __init__(self, label: str, mesh: MeshData, material: Material,
                 model: np.ndarray | None = None, events: Sequence[TimelineEvent] = (),
                 where: str | None = None, transform: Transform | None = None,
                 tracks: tuple = (), parent: SceneNode | str | None = None):
        self._states: dict[int, MaterialParams] = {}  # params_at's, by count of events applied
        self._values: dict[int, dict[str, Any]] = {}  # the merged values they came from
        self._states_base: MaterialParams | None = None  # the base those were made over
        self._times: tuple[float, ...] = ()
        super().__init__(label, transform, parent, where, tracks, model)
        self.skin: Skin | None = None  # joints deforming the mesh (deferred.scene.skin)
        self.mesh = mesh
        self.material = material
        self._set_events(events)

    @property
    def base_params(self) -> MaterialParams:
        """The material's parameters before any event: ``material.params``."""
        return self.material.params

    @property
    def params(self) -> MaterialParams:
        """The base parameters (:attr:`base_params`); the parameters at a time are
        :meth:`params_at`'s. Change them with :meth:`set_params`."""
        return self.material.params

    # -- the timeline of parameters -----------------------------------------------------------
    def _set_events(self, events: Sequence[TimelineEvent]) -> None:
        self.events = tuple(sorted(events, key=lambda event: event.time))  # stable
        self._times = tuple(event.time for event in self.events)
        self._forget_states()

    def _forget_states(self) -> None:
        self._states.clear()
        self._values.clear()
        self._states_base = self.material.params if hasattr(self, "material") else None

    @property
    def event_times(self) -> tuple[float, ...]:
        """The times of this object's events, sorted."""
        return self._times

    def params_at(self, time: float) -> MaterialParams:
        """The material parameters at ``time``: the base updated by every event with
        ``event.time <= time``, in time order (ties: the order given). Validated once per
        distinct set of events applied, then kept while the base is the same; the merged
        values are made from the nearest earlier set's, so asking every event time in turn
        costs each event once."""
        count = bisect_right(self._times, time)
        base = self.material.params
        if count == 0:
            return base
        if base is not self._states_base:  # the base was replaced: the states are over it
            self._forget_states()
        state = self._states.get(count)
        if state is None:
            where = self.events[count - 1].where
            state = validate_params(type(base), self._merged(count),
                                    f"{where}.params" if where else f"{self.label}: params")
            self._states[count] = state
        return state

    def _merged(self, count: int) -> dict[str, Any]:
        """The base with the first ``count`` events' params over it."""
        known = count
        while known > 0 and known not in self._values:
            known -= 1
        values = self._values[known] if known else self.material.params.model_dump()
        for index in range(known, count):
            values = {**values, **self.events[index].params}
            self._values[index + 1] = values
        return values

    def add_event(self, time: float, params: Mapping[str, Any],
                  where: str | None = None) -> TimelineEvent:
        """Add an event: from ``time`` (seconds, finite, >= 0) on, the material takes
        ``params``. ``params`` are checked over the base at once, and so is the object's state
        at every event time from this one on; errors name ``where``."""
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
        before = self.material.params
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
        base = self.material.params
        for key in material_cls.timeline_fixed:
            if key in params and params[key] != getattr(base, key, None):
                raise InputError(f"{material_cls.name} reads {key} once, at t = 0: a timeline "
                                 "cannot change it", f"{params_where}.{key}")
        # Every key checked against the material's model over the base (files, too)
        changed = material_cls.from_dict({**base.model_dump(), **params},
                                         self.material.base_dir, params_where)
        self._check_same_passes(changed, params, params_where)
        return TimelineEvent(float(time), MappingProxyType(dict(params)), where)

    def _check_same_passes(self, changed: Material, params: Mapping[str, Any],
                           where: str) -> None:
        """The pass graph is built once, from the parameters at t = 0: an event whose
        parameters would add or remove passes (fins on, shells from 0) cannot take effect."""
        def names(material: Material) -> list[str]:
            return [p.name for phase in Phase for p in material.passes(phase, self)]

        base = self.material.params
        before = names(type(self.material)(base, self.material.base_dir))
        after = names(changed)
        if before != after:
            keys = [k for k in params if params[k] != getattr(base, k, None)]
            added = sorted(set(after) - set(before))
            removed = sorted(set(before) - set(after))
            change = ", ".join([*(f"+{n}" for n in added), *(f"-{n}" for n in removed)])
            raise InputError(f"changing {', '.join(keys) or 'these parameters'} on a timeline "
                             f"would change the object's passes ({change}), which are built "
                             "once from t = 0; set it in the object's own params",
                             f"{where}.{keys[0]}" if len(keys) == 1 else where)

    def set_params(self, **values: Any) -> MaterialParams:
        """Change material parameters from Python, validated as a scene file's are
        (``InputError`` naming the object and the key: ``ball: params.shells: ...``); returns
        the new parameters. They become the object's base: a timeline's events apply over
        them from their times on, and every state of the timeline is checked again. The object
        gets a material instance of its own, so objects that shared one keep theirs. A
        renderer drawing the object picks the change up at its next frame (and rebuilds its
        passes where the change adds or removes some)."""
        where = f"{self.where}.params" if self.where else f"{self.label}: params"
        material = self.material
        changed = type(material).from_dict({**material.params.model_dump(), **values},
                                           material.base_dir, where)
        own = copy.copy(material)
        own.params = changed.params
        previous = self.material
        self.material = own
        self._forget_states()
        try:
            # each event again over the new base: what a timeline may not change
            # (timeline_fixed, the passes), then every state and what may only rise
            for event in self.events:
                self._checked_event(event.time, event.params, event.where)
            for time in sorted(set(self._times)):
                self.params_at(time)
            self._check_growing()
        except InputError:
            self.material = previous
            self._forget_states()
            raise
        self._values.clear()
        return own.params

    def with_material(self, material: Material,
                      overrides: Mapping[str, Any] | None = None) -> SceneObject:
        """A copy of this object drawn with ``material``, whose parameters become the base;
        ``overrides`` (the parameters that made them) join every event too, so they hold at
        every time of the timeline (bench sweeps, debug views)."""
        events = tuple(TimelineEvent(event.time, MappingProxyType({**event.params, **overrides}),
                                     event.where)
                       for event in self.events) if overrides else self.events
        copied = SceneObject(self.label, self.mesh, material, events=events, where=self.where,
                             transform=self.transform, tracks=self.tracks, parent=self.parent)
        if self._matrix is not None:
            copied._matrix = self._matrix
        copied.skin = self.skin
        return copied
