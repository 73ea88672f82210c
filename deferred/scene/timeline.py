"""Evaluating the scene at a time: the frame state a frame reads, made without writing to the
scene.

- :func:`local_matrix_at`: a node's local matrix with its tracks' values at a time;
- :func:`camera_at`, :func:`light_params_at`, :func:`light_at`: the camera and a light with
  their tracks (and the turntable) at a time, checked, placed in the world by their parents;
- :class:`SceneEvaluator`: the whole scene at a time as a :class:`~deferred.scene.state.
  FrameState`, keeping from one evaluation to the next what did not change (an object whose
  revision, parameters and world matrix are the same keeps its state and its version, so
  caches keyed on the version keep what they made).

A frame at time t depends only on the scene and t.
"""

from __future__ import annotations

import copy
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from deferred.errors import InputError
from deferred.params import validate_params
from deferred.revision import next_revision
from deferred.scene.camera import Camera, CameraModel, camera_values
from deferred.scene.graph import Hierarchy, place_direction, place_point, world_matrix
from deferred.scene.state import FrameState, ObjectState
from deferred.scene.transform import read_only

if TYPE_CHECKING:
    from deferred.interfaces.light import Light
    from deferred.interfaces.material import Material
    from deferred.scene.nodes import SceneNode
    from deferred.scene.objects import SceneObject

# The user's scene (deferred.scene.scene.Scene, which calls these functions: named here, not
# imported, so that the two modules do not import each other)
Scene = Any


def local_matrix_at(node: SceneNode, time: float) -> np.ndarray:
    """``node``'s local matrix at ``time`` (:meth:`SceneNode.local_at`)."""
    return node.local_at(time)


def hierarchy_of(scene: Scene) -> Hierarchy:
    return Hierarchy(scene.nodes(), scene.source)


def world_at(scene: Scene, node: SceneNode, time: float,
             hierarchy: Hierarchy | None = None) -> np.ndarray:
    """``node``'s world matrix at ``time`` (its tracks and its ancestors')."""
    hierarchy = hierarchy or hierarchy_of(scene)
    return world_matrix(node, hierarchy, lambda n: local_matrix_at(n, time))


def _parent_world(scene: Scene, parent: Any, time: float, where: str,
                  hierarchy: Hierarchy | None = None) -> np.ndarray | None:
    """The world matrix of the node ``parent`` names at ``time`` (None: no parent)."""
    if parent is None:
        return None
    hierarchy = hierarchy or hierarchy_of(scene)
    node = hierarchy.resolve(parent, where)
    return world_at(scene, node, time, hierarchy)


def camera_at(scene: Scene, time: float, hierarchy: Hierarchy | None = None) -> Camera:
    """The camera at ``time`` in the world: the scene's camera with the camera tracks'
    values at ``time`` over it, orbited by the turntable, then placed by its parent; checked
    as a scene file's camera is (``InputError`` naming the track and the time)."""
    base = scene.camera
    values: dict[str, Any] = {}
    where = "camera"
    for track in scene.tracks:
        if track.kind == "camera":
            values.update(track.at(time))
            where = track.where
    if scene.turntable is not None:
        values["position"] = scene.turntable.orbit(values.get("position", base.position),
                                                   values.get("target", base.target), time)
        where = where if where != "camera" else "turntable"
    camera = replace(base, **values) if values else base
    if base.parent is not None:
        world = _parent_world(scene, base.parent, time, "camera.parent", hierarchy)
        camera = replace(camera, position=place_point(world, camera.position),
                         target=place_point(world, camera.target),
                         up=place_direction(world, camera.up), parent=None)
    if camera is base:
        return base
    try:
        validate_params(CameraModel, camera_values(camera), None)
    except InputError as exc:
        raise InputError(f"the camera at t = {time:g} s: {exc}", where) from None
    return camera


def light_params_at(scene: Scene, light: Light, time: float) -> Any:
    """``light``'s parameters at ``time``: its own with its tracks' values at ``time`` over
    them, validated (``InputError`` naming the track and the time), in its parent's space."""
    values: dict[str, Any] = {}
    where = None
    for track in scene.tracks:
        if track.subject is light:
            values.update(track.at(time))
            where = track.where
    if not values:
        return light.params
    try:
        return validate_params(type(light.params), {**light.params.model_dump(), **values},
                               None)
    except InputError as exc:
        raise InputError(f"the light at t = {time:g} s: {exc}", where) from None


def light_at(scene: Scene, light: Light, time: float,
             hierarchy: Hierarchy | None = None) -> Light:
    """``light`` at ``time`` in the world: itself where it has no track and no parent, else a
    copy with its parameters at ``time`` and its ``position`` and ``direction`` (where its
    type has them) placed by its parent."""
    params = light_params_at(scene, light, time)
    parent = getattr(light, "parent", None)
    if parent is not None:
        world = _parent_world(scene, parent, time, "light.parent", hierarchy)
        placed = {}
        if "position" in type(params).model_fields:
            placed["position"] = place_point(world, params.position)
        if "direction" in type(params).model_fields:
            placed["direction"] = place_direction(world, params.direction)
        if placed:
            params = params.model_copy(update=placed)
    if params is light.params:
        return light
    evaluated = copy.copy(light)
    evaluated.params = params
    evaluated.parent = None
    return evaluated


def check_tracks(scene: Scene, times: list[float] | tuple[float, ...]) -> None:
    """The camera's and the lights' tracks at each of ``times``, checked before any frame is
    drawn (a camera passing through its target between keys, a light's direction through
    zero): ``InputError`` naming the track and the time."""
    moving_camera = scene.turntable is not None or scene.camera.parent is not None or \
        any(t.kind == "camera" for t in scene.tracks)
    lights = list(dict.fromkeys(t.subject for t in scene.tracks if t.kind == "light"))
    if not (moving_camera or lights):
        return
    hierarchy = hierarchy_of(scene)
    for time in times:
        if moving_camera:
            camera_at(scene, time, hierarchy)
        for light in lights:
            light_params_at(scene, light, time)


class SceneEvaluator:
    """Evaluates one scene at the times a renderer draws (see the module documentation).

    What it keeps between evaluations is its own: each renderer has one, so renderers at
    different times over one scene share nothing but the scene."""

    def __init__(self, scene: Scene):
        self.scene = scene
        # by the user's object or light (hashed by identity): the last state of each object,
        # the revisions it was evaluated at, the last evaluated copy of each light and of each
        # object's material
        self._objects: dict[SceneObject, ObjectState] = {}
        self._keys: dict[SceneObject, tuple[int, int]] = {}
        self._lights: dict[Light, tuple[int, Light]] = {}
        self._materials: dict[SceneObject, tuple[Material, int, Any, Material]] = {}
        self._hierarchy: tuple[tuple, Hierarchy] | None = None

    def hierarchy(self) -> Hierarchy:
        """The scene graph's parents, resolved again when a node or a parent changed."""
        scene = self.scene
        key = tuple((node, node.revision) for node in scene.nodes())
        if self._hierarchy is None or self._hierarchy[0] != key:
            self._hierarchy = (key, hierarchy_of(scene))
        return self._hierarchy[1]

    def check_simulation_times(self, latest: float, where: str) -> None:
        """Every simulated object's ``Simulation.check_time`` for ``latest``, the latest time
        a render asks for (``InputError`` naming ``where`` for one it cannot reach)."""
        simulated = [obj for obj in self.scene.objects if obj.material.simulation is not None]
        if not simulated:  # most materials have no simulation
            return
        state = self.evaluate(latest)
        for obj in simulated:
            evaluated = state.object_state(obj)
            evaluated.material.simulation.check_time(evaluated, latest, where)

    def evaluate(self, time: float) -> FrameState:
        """The scene at ``time``."""
        scene = self.scene
        hierarchy = self.hierarchy()
        worlds: dict[SceneNode, np.ndarray] = {}
        objects = tuple(self._object(obj, time, hierarchy, worlds) for obj in scene.objects)
        if len(self._objects) > 2 * len(objects) + 16:  # objects removed from the scene
            present = set(scene.objects)
            self._objects = {k: v for k, v in self._objects.items() if k in present}
            self._materials = {k: v for k, v in self._materials.items() if k in present}
            self._keys = {k: v for k, v in self._keys.items() if k in present}
        return FrameState(
            time=time, camera=camera_at(scene, time, hierarchy), objects=objects,
            lights=tuple(self._light(light, time, hierarchy) for light in scene.lights),
            effects=tuple(scene.effects), size=scene.size, background=scene.background,
            exposure=scene.exposure, tonemap=scene.tonemap, light_path=scene.light_path,
            shadow_budget=scene.shadow_budget, source=scene.source, scene=scene,
            revision=scene.revision)

    def _object(self, obj: SceneObject, time: float, hierarchy: Hierarchy,
                worlds: dict[SceneNode, np.ndarray]) -> ObjectState:
        previous = self._objects.get(obj)
        key = (obj.revision, obj.material.revision)
        parent = hierarchy.parent_of(obj)
        static = not obj.tracks and not obj.events and parent is None and obj.skin is None
        if static and previous is not None and self._keys.get(obj) == key:
            return previous  # nothing to evaluate: the object as the user left it
        model = world_matrix(obj, hierarchy, lambda n: local_matrix_at(n, time), worlds)
        if previous is not None and model is not previous.model and \
                np.array_equal(model, previous.model):
            model = previous.model  # the same world: the same array, for the caches
        elif model is not obj.model:
            model = read_only(model)
        skin = self._skin_at(obj, model, previous, time, hierarchy, worlds)
        material = self._material_at(obj, time)
        self._keys[obj] = key
        if previous is not None and previous.model is model and \
                previous.material is material and previous.mesh is obj.mesh and \
                previous.label == obj.label and previous.skin_matrices is skin:
            return previous
        tracks = obj.tracks if parent is None else \
            (*obj.tracks, *(t for node in hierarchy.ancestors(obj) for t in node.tracks))
        state = ObjectState(node=obj, label=obj.label, mesh=obj.mesh, material=material,
                            model=model, version=next_revision(), world_at=self._world_at(obj),
                            tracks=tuple(tracks), skin_matrices=skin)
        self._objects[obj] = state
        return state

    @staticmethod
    def _skin_at(obj: SceneObject, model: np.ndarray, previous: ObjectState | None,
                 time: float, hierarchy: Hierarchy,
                 worlds: dict[SceneNode, np.ndarray]) -> np.ndarray | None:
        """A skinned object's joint matrices at ``time`` (the previous state's array where
        they are the same)."""
        if obj.skin is None:
            return None
        joint_worlds = [world_matrix(joint, hierarchy, lambda n: local_matrix_at(n, time),
                                     worlds) for joint in obj.skin.joints]
        matrices = obj.skin.matrices(model, joint_worlds)
        kept = previous.skin_matrices if previous is not None else None
        if kept is not None and np.array_equal(kept, matrices):
            return kept
        return matrices

    def _light(self, light: Light, time: float, hierarchy: Hierarchy) -> Light:
        """:func:`light_at`, the same copy while its evaluated parameters are equal (the light
        buffer and the shadow atlas keep what they made for a light object)."""
        if light.parent is None and not self._light_tracks(light):
            return light
        evaluated = light_at(self.scene, light, time, hierarchy)
        kept = self._lights.get(light)
        if kept is not None and kept[0] == light.revision and evaluated is not light and \
                kept[1].params == evaluated.params:
            return kept[1]
        self._lights[light] = (light.revision, evaluated)
        return evaluated

    def _light_tracks(self, light: Light) -> bool:
        return any(track.subject is light for track in self.scene.tracks)

    def _world_at(self, obj: SceneObject):
        scene = self.scene

        def at(time: float) -> np.ndarray:
            return world_at(scene, obj, time, self.hierarchy())
        return at

    def _material_at(self, obj: SceneObject, time: float) -> Material:
        """The object's material with its parameters at ``time``: the object's own where no
        event applies, else a copy with those (one a set of parameters, kept while they and
        the material are the same)."""
        material = obj.material
        params = obj.params_at(time)
        if params is material.params:
            return material
        kept = self._materials.get(obj)
        if kept is not None and kept[0] is material and kept[1] == material.revision and \
                kept[2] is params:
            return kept[3]
        evaluated = copy.copy(material)
        evaluated.params = params
        self._materials[obj] = (material, material.revision, params, evaluated)
        return evaluated
