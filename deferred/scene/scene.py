"""The scene: camera, objects, groups, lights and effects, their timeline, and the Python API
that edits them.

The scene is the user's: it changes only by the user's edits (a scene file, this API, the
viewer), each of which gives the edited object a new revision (:mod:`deferred.revision`). A
frame evaluates it (:class:`deferred.scene.timeline.SceneEvaluator`) into an immutable frame
state and never writes to it, so two renderers at different times over one scene do not
disturb each other.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from deferred.errors import InputError
from deferred.gl.meshes import MeshData
from deferred.interfaces import registry
from deferred.interfaces.effect import Effect
from deferred.interfaces.light import Light
from deferred.interfaces.material import Material
from deferred.params import validate_params
from deferred.revision import Revisioned
from deferred.scene import timeline
from deferred.scene.camera import Camera
from deferred.scene.graph import Hierarchy
from deferred.scene.meshes import load_mesh
from deferred.scene.nodes import SceneNode
from deferred.scene.objects import SceneObject, TimelineEvent
from deferred.scene.shadow_budget import ShadowBudget
from deferred.scene.state import SceneContents
from deferred.scene.tracks import Track, Turntable, make_track
from deferred.scene.transform import Transform
from deferred.validation import join_where


@dataclass(eq=False)
class Scene(SceneContents, Revisioned):
    """A scene ready to render (meshes loaded, materials and lights validated).

    ``groups`` are nodes without a mesh that objects, lights and the camera may hang from
    (``parent``); ``tracks`` the camera's and the lights' keyframe tracks (objects and groups
    keep theirs); ``light_names`` the lights by name (``light:NAME`` in a track's target).
    """

    camera: Camera = field(default_factory=Camera)
    objects: list[SceneObject] = field(default_factory=list)
    lights: list[Light] = field(default_factory=list)
    size: tuple[int, int] = (1280, 720)
    background: tuple[float, float, float] | str = (0.02, 0.02, 0.025)  # or "environment"
    exposure: float = 1.0
    tonemap: str = "aces"
    light_path: str | None = None
    shadow_budget: ShadowBudget = field(default_factory=ShadowBudget)
    effects: list[Effect] = field(default_factory=list)
    source: str = "<memory>"
    tracks: list[Track] = field(default_factory=list)
    turntable: Turntable | None = None
    light_names: dict[str, Light] = field(default_factory=dict)
    groups: list[SceneNode] = field(default_factory=list)

    # -- evaluation ----------------------------------------------------------------------------
    def camera_at(self, time: float) -> Camera:
        """The camera at ``time`` in the world: the scene's camera with the camera tracks'
        values at ``time`` over it, orbited by the turntable, placed by its parent; checked as
        a scene file's camera is (``InputError`` naming the track and the time)."""
        return timeline.camera_at(self, time)

    def light_params_at(self, light: Light, time: float) -> Any:
        """``light``'s parameters at ``time`` (its tracks' values over its own, validated),
        in its parent's space."""
        return timeline.light_params_at(self, light, time)

    def check_tracks(self, times: Sequence[float]) -> None:
        """The camera's and the lights' tracks at each of ``times``, checked before any frame
        is drawn: ``InputError`` naming the track and the time."""
        timeline.check_tracks(self, times)

    def world_at(self, node: SceneNode, time: float) -> np.ndarray:
        """``node``'s world matrix at ``time``: its ancestors' local matrices times its own,
        each with its tracks' values at ``time`` (``InputError`` for an unknown parent or a
        cycle)."""
        return timeline.world_at(self, node, time)

    def find(self, label: str) -> SceneNode:
        """The object or group labelled ``label`` (``InputError`` where none is)."""
        for node in (*self.objects, *self.groups):
            if node.label == label:
                return node
        raise InputError(_no_node(label, self.nodes()), "label")

    def nodes(self) -> list[SceneNode]:
        """Every node of the scene graph: the objects, then the groups."""
        return [*self.objects, *self.groups]

    # -- the timeline --------------------------------------------------------------------------
    def add_event(self, obj: SceneObject | str, time: float, params: Mapping[str, Any],
                  where: str | None = None) -> TimelineEvent:
        """:meth:`SceneObject.add_event` for the object ``obj`` or the one labelled so."""
        if isinstance(obj, str):
            found = [o for o in self.objects if o.label == obj]
            if not found:
                raise InputError(_no_node(obj, self.objects, "object"),
                                 f"{where}.object" if where else "object")
            obj = found[0]
        return obj.add_event(time, params, where)

    def add_track(self, target: str | SceneNode | Light, keys: Sequence[Mapping[str, Any]],
                  interpolation: str = "linear", where: str | None = None) -> Track:
        """Add a keyframe track (:mod:`deferred.scene.tracks`): ``target`` is ``"camera"``,
        ``"object:NAME"`` (an object or a group), ``"light:INDEX"`` or ``"light:NAME"`` (or
        the node or light itself); ``keys`` a list of ``{"time": t, property: value, ...}``
        in rising time; ``interpolation`` ``step``, ``linear`` or ``smooth``. Checked at once
        (``InputError`` naming ``where``, default ``<source>: track[N]``, and the key): the
        keys, the properties the target has (a light's type), a property already moved by
        another track, and the camera and a light at every key's time. A renderer drawing
        the scene moves the target from its next frame."""
        where = where or f"{self.source}: track[{self._track_count()}]"
        subject, target = self._track_target(target, where)
        track = make_track(target, keys, interpolation, where)
        if subject is None and track.kind != "camera":
            subject = self._track_subject(track, join_where(where, "target"))
        if isinstance(subject, SceneNode):
            _check_free(track, subject.tracks)
            subject.tracks = (*subject.tracks, track)
            try:
                for time in track.key_times:
                    timeline.local_matrix_at(subject, time)
            except BaseException:
                subject.tracks = subject.tracks[:-1]
                raise
            return track
        track = replace(track, subject=subject)
        if isinstance(subject, Light):
            _check_light_keys(subject, track, where)
        _check_free(track, [t for t in self.tracks if t.subject is subject])
        self.tracks = [*self.tracks, track]
        try:  # the camera and the light as each key leaves them
            for time in track.key_times:
                if subject is None:
                    self.camera_at(time)
                else:
                    self.light_params_at(subject, time)
        except BaseException:
            self.tracks = [t for t in self.tracks if t is not track]
            raise
        return track

    def _track_target(self, target: str | SceneNode | Light,
                      where: str) -> tuple[SceneNode | Light | None, str]:
        if isinstance(target, SceneNode):
            if not any(node is target for node in self.nodes()):
                raise InputError(f"the object {target.label!r} is not in the scene", "target")
            return target, f"object:{target.label}"
        if isinstance(target, Light):
            index = next((i for i, light in enumerate(self.lights) if light is target), None)
            if index is None:
                raise InputError("the scene holds no such light", join_where(where, "target"))
            return target, f"light:{index}"
        return None, target

    def _track_count(self) -> int:
        return len(self.tracks) + sum(len(node.tracks) for node in self.nodes())

    def _track_subject(self, track: Track, where: str) -> SceneNode | Light:
        """The node or light ``track.name`` names."""
        name = track.name
        if track.kind == "object":
            found = [node for node in self.nodes() if node.label == name]
            if not found:
                raise InputError(_no_node(name, self.nodes(), "object"), where)
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

    def set_turntable(self, period: float | None, start: float = 0.0) -> Turntable | None:
        """Orbit the camera about the vertical through its target once every ``period``
        seconds from ``start`` (over camera tracks, which move what it orbits); ``None``
        stops it. Frames ``start + i * period / n`` for i in 0..n-1 are an n-frame loop."""
        self.turntable = None if period is None else Turntable(period, start)
        return self.turntable

    # -- editing -------------------------------------------------------------------------------
    def add_object(self, mesh: MeshData | str, material: Material | str = "standard",
                   position=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0), scale=1.0,
                   label: str | None = None, params: Mapping[str, Any] | None = None,
                   base_dir: str | Path | None = None, parent: SceneNode | str | None = None,
                   quaternion=None, rotation_order: str = "XYZ") -> SceneObject:
        """Add an object: ``mesh`` a :class:`MeshData` or a name as a scene file gives it
        (``builtin:torus?segments=78``, a file relative to ``base_dir``); ``material`` a
        registered name with ``params`` (validated as a scene file's are) or an instance;
        position, rotation (degrees, in ``rotation_order``) or ``quaternion`` ([x, y, z, w]),
        scale (a number or one per axis) and ``parent`` (a node or its label) as in a scene
        file. Errors are ``InputError``s naming the argument (``mesh``, ``material``,
        ``ball: params.shells``). A renderer drawing the scene draws the object from its next
        frame."""
        label = self._new_label(label)
        folder = None if base_dir is None else Path(base_dir)
        if isinstance(mesh, str):
            mesh = load_mesh(mesh, folder, "mesh")
        elif not isinstance(mesh, MeshData):
            raise InputError(f"expected a MeshData or a mesh name, got {type(mesh).__name__}",
                             "mesh")
        label = label or unique_label({node.label for node in self.nodes()}, mesh.name)
        if isinstance(material, str):
            material = registry.materials.get(material, "material").from_dict(
                dict(params or {}), folder, f"{label}: params")
        elif not isinstance(material, Material):
            raise InputError(f"expected a Material or a material name, got "
                             f"{type(material).__name__}", "material")
        elif params:
            raise InputError("give params with a material name; an instance has its own",
                             "params")
        place = _placement(position, rotation, scale, quaternion, rotation_order)
        obj = SceneObject(label, mesh, material, transform=place, parent=parent)
        self._check_parent(obj)
        self.objects.append(obj)
        self.touch()
        return obj

    add = add_object  # the shorter name of earlier versions

    def add_group(self, label: str, position=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0),
                  scale=1.0, parent: SceneNode | str | None = None, quaternion=None,
                  rotation_order: str = "XYZ") -> SceneNode:
        """Add a group: a node without a mesh, placed as an object is, that objects, lights,
        the camera and other groups may name as their ``parent``."""
        label = self._new_label(label)
        if label is None:
            raise InputError("a group needs a label", "label")
        node = SceneNode(label, _placement(position, rotation, scale, quaternion,
                                           rotation_order), parent=parent)
        self._check_parent(node)
        self.groups.append(node)
        self.touch()
        return node

    def _new_label(self, label: str | None) -> str | None:
        if label is not None and not (isinstance(label, str) and label.strip()):
            raise InputError(f"must be a name, got {label!r}", "label")
        for node in self.nodes():
            if node.label == label:
                what = "an object" if isinstance(node, SceneObject) else "a group"
                raise InputError(f"{what} is named '{label}' already", "label")
        return label

    def _check_parent(self, node: SceneNode) -> None:
        if node.parent is not None:
            Hierarchy([*self.nodes(), node], self.source)

    def add_light(self, type: str, name: str | None = None,
                  parent: SceneNode | str | None = None, **params: Any) -> Light:
        """Add a light of a registered ``type`` (``point``, ``spot``, ``directional``,
        ``ambient``, a plugin's) with its parameters, validated as a scene file's are
        (``InputError`` naming the light and the key); ``name`` lets tracks say
        ``light:NAME``; ``parent`` places its position and direction in a node's space. A
        renderer drawing the scene lights with it from its next frame."""
        if name is not None:
            check_light_name(name, self.light_names, "name")
        light = registry.lights.get(type, "type").from_dict(
            params, f"light[{len(self.lights)}] ({type})")
        light.parent = parent
        if parent is not None:
            Hierarchy(self.nodes(), self.source).resolve(parent, "parent")
        self.lights.append(light)
        if name is not None:
            self.light_names[name] = light
        self.touch()
        return light

    def remove(self, item: SceneNode | Light | Effect | str) -> None:
        """Remove an object or group (itself or its label), a light or an effect;
        ``InputError`` when the scene does not hold it. A renderer drawing the scene leaves
        it out from its next frame."""
        if isinstance(item, str):
            found = [node for node in self.nodes() if node.label == item]
            if not found:
                raise InputError(_no_node(item, self.nodes(), "object"), "item")
            item = found[0]
        for collection in (self.objects, self.groups, self.lights, self.effects):
            for index, held in enumerate(collection):
                if held is item:
                    del collection[index]
                    if isinstance(item, Light):  # its tracks and name go with it
                        self.tracks = [t for t in self.tracks if t.subject is not item]
                        self.light_names = {n: light for n, light in self.light_names.items()
                                            if light is not item}
                    self.touch()
                    return
        raise InputError(f"the scene holds no {type(item).__name__} {item!r:.80}", "item")


def _placement(position, rotation, scale, quaternion, rotation_order) -> Transform:
    values = {"position": position, "rotation": rotation, "scale": scale,
              "rotation_order": rotation_order}
    if quaternion is not None:
        values["quaternion"] = quaternion
    return validate_params(Transform, values, None)


def _check_free(track: Track, others: Sequence[Track]) -> None:
    """No property of ``track`` is moved by another track of its target already."""
    for other in others:
        for prop in track.curves:
            if prop in other.curves:
                raise InputError(f"{track.target}'s {prop} is moved by {other.where} "
                                 "already (one track a property)",
                                 join_where(track.where,
                                            f"keys[{track.curves[prop].keys[0]}].{prop}"))


def _check_light_keys(light: Light, track: Track, where: str) -> None:
    fields = type(light.params).model_fields
    for prop, curve in track.curves.items():
        if prop not in fields:
            have = [p for p in ("position", "direction", "color", "intensity") if p in fields]
            raise InputError(f"a {type(light).name} light has no {prop} (its keys may "
                             f"set {', '.join(have)})",
                             join_where(where, f"keys[{curve.keys[0]}].{prop}"))


def _no_node(label: str, nodes: Sequence[SceneNode], what: str = "object or group") -> str:
    names = ", ".join(node.label[:40] for node in nodes[:10]) or "none"
    if len(nodes) > 10:
        names += f", ... ({len(nodes)} in all)"
    return f"no {what} named {label[:80]!r} ({what}s: {names})"


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
