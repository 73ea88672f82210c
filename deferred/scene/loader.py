"""Scene files: TOML (docs/reference/scene-files.md) or a dict, validated into a
:class:`~deferred.scene.scene.Scene`; ``deferred render`` with no scene loads the built-in demo.

Validation names the file, the key and the problem in one line
(``demo.toml: object[1].params.shells: Input should be greater than or equal to 0 (got -3)``).
Every problem of a file is found before one is raised. The tables' models are
:mod:`deferred.scene.tables`; :class:`SceneBuilder` makes the scene from them, a table kind at a
time: objects and groups (the scene graph's nodes), lights, effects, then the timeline (events
and tracks), and last the parents (every node, light and the camera naming one that exists,
with no cycle).
"""
from __future__ import annotations

import re
import warnings
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from deferred.errors import InputError, input_error
from deferred.gl.meshes import MeshData
from deferred.interfaces import registry
from deferred.interfaces.material import Material
from deferred.scene.camera import Camera
from deferred.scene.census import BeforeMeshes, object_materials, weigh_objects
from deferred.scene.gltf import GLTF_SUFFIXES, add_gltf, fill_scene, read_gltf
from deferred.scene.gltf.building import animate, choose_animation
from deferred.scene.graph import Hierarchy
from deferred.scene.meshes import load_mesh
from deferred.scene.nodes import SceneNode
from deferred.scene.objects import SceneObject
from deferred.scene.scene import Scene, ShadowBudget, check_light_name, unique_label
from deferred.scene.size import check_size
from deferred.scene.tables import (
    LISTS,
    EventModel,
    GroupModel,
    ObjectModel,
    SceneModel,
    TrackModel,
    TypedModel,
)
from deferred.scene.tracks import make_track, parse_target
from deferred.validation import closest, parse_toml, require_regular_file, validation_problems

DEMO_SCENE = "demo.toml"
T = TypeVar("T")
M = TypeVar("M", bound=BaseModel)


def builtin_scenes() -> list[str]:
    """Names of the scenes shipped with the package (``builtin:<name>``)."""
    folder = resources.files("deferred").joinpath("scenes")
    return sorted(entry.name.removesuffix(".toml") for entry in folder.iterdir()
                  if entry.name.endswith(".toml"))


def load_scene(path: str | Path | None = None, camera: str | None = None,
               animation: str | None = None, before_meshes: BeforeMeshes | None = None) -> Scene:
    """Load a scene file; ``None`` loads the built-in demo scene, ``builtin:<name>`` another
    scene shipped with the package (``builtin:overdraw``, the bench scene with overdraw). A
    glTF file (.gltf, .glb) is a scene of its own (:func:`deferred.scene.gltf.fill_scene`):
    ``camera`` names one of its cameras, ``animation`` one of its animations (or ``none``);
    either with another file is an error. ``before_meshes``: :class:`SceneBuilder`'s."""
    if path is not None and Path(path).suffix.lower() in GLTF_SUFFIXES:
        return fill_scene(Scene(source=Path(path).name), Path(path), camera, animation)
    for value, option in ((camera, "--camera"), (animation, "--animation")):
        if value is not None:
            raise InputError(f"{option} chooses among a glTF file's; {path or 'the demo'} is "
                             "a scene file", option)
    if path is None:
        path = f"builtin:{DEMO_SCENE.removesuffix('.toml')}"
    if isinstance(path, str) and path.startswith("builtin:"):
        name = path.removeprefix("builtin:").removesuffix(".toml")
        if name not in builtin_scenes():
            raise InputError(f"no built-in scene '{name}' (choose from "
                             f"{', '.join(builtin_scenes())})", path)
        text = resources.files("deferred").joinpath("scenes", f"{name}.toml").read_text("utf-8")
        return scene_from_toml(text, f"builtin:{name}.toml", None, before_meshes)
    path = Path(path)
    require_regular_file(path, "scene file", str(path))
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read scene file: {exc}", str(path)) from None
    scene = scene_from_toml(text, path.name, path.parent, before_meshes)
    if not scene.objects:  # valid, but most likely an emptied or the wrong file
        warnings.warn(f"{path.name}: the scene has no [[object]]: the image is its background "
                      "alone", stacklevel=2)
    return scene


def scene_from_toml(text: str, name: str = "<string>", base_dir: Path | None = None,
                    before_meshes: BeforeMeshes | None = None) -> Scene:
    """A scene from the text of a scene file; ``name`` is what errors call it, ``base_dir``
    where relative mesh and texture paths are found."""
    return scene_from_dict(parse_toml(text, name), name, base_dir, before_meshes)


def scene_from_dict(data: dict[str, Any], name: str = "<dict>", base_dir: Path | None = None,
                    before_meshes: BeforeMeshes | None = None) -> Scene:
    """The scene ``data`` describes (a scene file's tables). Every problem is found before one
    is raised: an :class:`InputError` for one, :class:`InputErrors` naming each (in the file's
    order) for several; unknown keys and names say the closest known one."""
    builder = SceneBuilder(data, name, base_dir, before_meshes)
    builder.build()
    if builder.problems:
        order = {key: position for position, key in enumerate(data)}
        each = [one for problem in builder.problems for one in problem.problems]
        raise input_error(sorted(each, key=lambda p: _file_order(p.where, name, order)))
    return builder.scene


class SceneBuilder:
    """Makes a scene from a scene file's tables, collecting every problem (:meth:`build`);
    ``before_meshes``: :func:`deferred.scene.census.weigh_objects`."""

    def __init__(self, data: dict[str, Any], name: str, base_dir: Path | None,
                 before_meshes: BeforeMeshes | None = None):
        self.name = name
        self.before_meshes = before_meshes
        self.base_dir = base_dir
        self.problems: list[InputError] = []
        try:
            model = SceneModel(**data)
            self.tables = {key: [(item, set()) for item in getattr(model, key)]
                           for key in LISTS}
        except ValidationError as exc:
            self.problems += validation_problems(exc, name, SceneModel)
            # the parts valid alone are checked further: all problems are said at once
            bad = {error["loc"][0] for error in exc.errors() if error["loc"]}
            model = _valid_alone(SceneModel, {k: v for k, v in data.items()
                                              if k not in bad and k not in LISTS})[0]
            kinds = {"object": ObjectModel, "group": GroupModel, "light": TypedModel,
                     "effect": TypedModel, "event": EventModel, "track": TrackModel}
            self.tables = {key: _each(kinds[key], data.get(key)) for key in LISTS}
        self.model = model
        # label -> (the node, or None where it is not made; its material class, where known)
        self.labels: dict[str, tuple[SceneNode | None, type[Material] | None]] = {}
        self.unlabelled = False  # a node whose label is not known (its name is refused)
        self.file_lights: list = []  # each [[light]] by its index in the file (None: refused)
        self.light_names: set[str] = set()
        self.group_labels: set[str] = set()
        # what names a parent, with where it said so: checked once every node is made
        self.children: list[tuple[Any, str]] = []

    def collect(self, function: Callable[..., T], *args: Any) -> T | None:
        return _collect(self.problems, function, *args)

    def build(self) -> None:
        model, name = self.model, self.name
        self.collect(check_size, model.size, f"{name}: size")
        c = model.camera
        self.scene = Scene(
            camera=Camera(c.position, c.target, c.up, c.fov, c.near, c.far, parent=c.parent),
            size=model.size, background=model.background, exposure=model.exposure,
            tonemap=model.tonemap, light_path=model.light_path, source=name,
            shadow_budget=ShadowBudget(model.shadows.atlas_size,
                                       model.shadows.max_shadowed_lights,
                                       model.shadows.opacity_scale,
                                       str(model.shadows.allocation),
                                       model.shadows.cascade_updates))
        if c.parent is not None:
            self.children.append((self.scene.camera, f"{name}: camera.parent"))
        self.lights()  # lights and effects first: the objects are weighed with them
        self.effects()
        self.objects()
        self.groups()
        self.events()
        self.tracks()
        self.parents()

    def _label(self, table: Any, bad: set[str], where: str, mesh_name: str | None,
               taken: set[str], next_index: dict[str, int]) -> str | None:
        """The node's label (its name, or one made from its mesh's), or None where it has
        none or another node has it (said)."""
        if "name" in bad or (table.name is None and mesh_name is None):
            self.unlabelled = True
            return None
        label = table.name or unique_label(taken, mesh_name, next_index)
        if label in self.labels:
            self.problems.append(InputError(f"duplicate object name '{label}'",
                                            f"{where}.name"))
            return None
        taken.add(label)
        return label

    def _made(self, label: str, node: SceneNode | None, material_cls: type[Material] | None,
              where: str) -> None:
        """A node of the file, made (or None where refused): named, and its parent checked
        once every node is made."""
        self.labels[label] = (node, material_cls)
        if node is not None and node.parent is not None:
            self.children.append((node, f"{where}.parent"))

    def objects(self) -> None:
        materials = object_materials(self)
        weigh_objects(self, materials)  # before any mesh: a refusal there is final
        meshes: dict[str, MeshData | None] = {}
        taken: set[str] = set()  # the labels, for unique_label
        next_index: dict[str, int] = {}  # unique_label's, for every unnamed object
        self._taken, self._next_index = taken, next_index
        for index, (obj, bad) in enumerate(self.tables["object"]):
            where = f"{self.name}: object[{index}]"
            if obj is None:
                continue
            material_cls, material = materials[index]
            if "mesh" not in bad and Path(obj.mesh).suffix.lower() in GLTF_SUFFIXES:
                self._gltf_object(obj, bad, where, material, material_cls)
                continue
            for key in ("node", "animation"):
                if getattr(obj, key, None) is not None and key not in bad:
                    self.problems.append(InputError(f"{key} picks from a glTF mesh (.gltf, "
                                                    ".glb)", f"{where}.{key}"))
            mesh = None
            if "mesh" not in bad:
                if obj.mesh not in meshes:
                    meshes[obj.mesh] = self.collect(load_mesh, obj.mesh, self.base_dir,
                                                    f"{where}.mesh")
                mesh = meshes[obj.mesh]
            # a mesh that failed to load is named as it would be, for the events naming it
            mesh_name = None if "mesh" in bad else \
                mesh.name if mesh is not None else _mesh_name(obj.mesh)
            label = self._label(obj, bad, where, mesh_name, taken, next_index)
            if label is None:
                continue
            made = None
            if not bad and material is not None and mesh is not None:
                made = SceneObject(label, mesh, material, where=where,
                                   transform=obj.transform(), parent=obj.parent)
                self.scene.objects.append(made)
            self._made(label, made, material_cls, where)

    def _gltf_object(self, obj: Any, bad: set[str], where: str, material: Material | None,
                     material_cls: type[Material] | None) -> None:
        """An object whose mesh is a glTF file: a group placed as the object is, holding the
        file's nodes (or ``node``'s subtree) with their materials, or with the object's
        ``material`` where it gives one; the file's first animation (or ``animation``)."""
        path = Path(obj.mesh)
        if not path.is_absolute() and self.base_dir is not None:
            path = self.base_dir / path
        assets = self.__dict__.setdefault("_assets", {})
        if path not in assets:
            assets[path] = self.collect(read_gltf, path, f"{where}.mesh")
        asset = assets[path]
        label = self._label(obj, bad, where, path.name, self._taken, self._next_index)
        if label is None:
            return
        overrides = bool({"material", "params"} & obj.model_fields_set)
        made = None
        if not bad and asset is not None and (material is not None or not overrides):
            made = SceneNode(label, obj.transform(), parent=obj.parent, where=where)
            self.scene.groups.append(made)
            placed = self.collect(add_gltf, self.scene, asset, made,
                                  material if overrides else None, obj.node, f"{where}.node",
                                  f"{label}/")
            if placed is None:
                made = None
            else:
                animate(placed, self.collect(choose_animation, asset, obj.animation,
                                             f"{where}.animation"))
                for node in placed.nodes.values():
                    self._taken.add(node.label)
                    kind = type(node.material) if isinstance(node, SceneObject) else None
                    self._made(node.label, node, kind, where)
        self._made(label, made, material_cls if overrides else None, where)

    def groups(self) -> None:
        for index, (group, bad) in enumerate(self.tables["group"]):
            where = f"{self.name}: group[{index}]"
            if group is None:
                continue
            label = self._label(group, bad, where, None, self._taken, self._next_index)
            if label is None:
                continue
            self.group_labels.add(label)
            made = None
            if not bad:
                made = SceneNode(label, group.transform(), parent=group.parent, where=where)
                self.scene.groups.append(made)
            self._made(label, made, None, where)

    def lights(self) -> None:
        for index, (light, bad) in enumerate(self.tables["light"]):
            where = f"{self.name}: light[{index}]"
            self.file_lights.append(None)
            values = dict(light.model_extra or {}) if light is not None else {}
            light_name = values.pop("name", None)
            parent = values.pop("parent", None)
            if light_name is not None:
                try:
                    check_light_name(light_name, self.light_names, f"{where}.name")
                    self.light_names.add(light_name)
                except InputError as exc:
                    self.problems.append(exc)
                    light_name = None
            if light is None or "type" in bad:
                continue
            light_cls = self.collect(registry.lights.get, light.type, f"{where}.type")
            made = None if light_cls is None else self.collect(light_cls.from_dict, values,
                                                               where, self.base_dir)
            if made is None:
                continue
            self.scene.lights.append(made)
            self.file_lights[index] = made
            if light_name is not None:
                self.scene.light_names[light_name] = made
            if parent is not None:
                made.parent = parent
                self.children.append((made, f"{where}.parent"))

    def effects(self) -> None:
        name = self.name
        effects = [(f"{name}: effect[{index}]", e.type, e.model_extra or {})
                   for index, (e, bad) in enumerate(self.tables["effect"])
                   if e is not None and "type" not in bad]
        if self.model.ssao is not None:  # the [ssao] table of earlier scene files
            if any(kind == "ssao" for _, kind, _ in effects):
                self.problems.append(InputError("ssao is given both as [ssao] and as an "
                                                "[[effect]]; keep one", f"{name}: ssao"))
            else:
                effects.insert(0, (f"{name}: ssao", "ssao", self.model.ssao))
        seen: set[str] = set()
        for where, kind, values in effects:
            if kind in seen:
                self.problems.append(InputError(f"effect '{kind}' is given twice (one of each "
                                                "type)", f"{where}.type"))
                continue
            seen.add(kind)
            effect_cls = self.collect(registry.effects.get, kind, f"{where}.type")
            if effect_cls is not None:
                made = self.collect(effect_cls.from_dict, values, where)
                if made is not None:
                    self.scene.effects.append(made)

    def events(self) -> None:
        """Each object's events added at once (in the file's order: it breaks ties of time)."""
        grouped: dict[str, list[tuple[float, dict[str, Any], str]]] = {}
        for index, (event, bad) in enumerate(self.tables["event"]):
            where = f"{self.name}: event[{index}]"
            if event is None or "object" in bad:
                continue
            target, material_cls = self.labels.get(event.object, (None, None))
            if event.object not in self.labels or event.object in self.group_labels:
                if not self.unlabelled:
                    self.problems.append(InputError(_no_object(event.object, self._objects()),
                                                    f"{where}.object"))
                continue
            if target is not None and not bad:
                grouped.setdefault(event.object, []).append((event.time, event.params, where))
            elif material_cls is not None and "params" not in bad:
                # the object is refused: the event's own keys and values are still checked
                self.problems += _params_problems(material_cls.Params, event.params,
                                                  f"{where}.params")
        for label, timeline in grouped.items():
            target = self.labels[label][0]
            try:
                target.add_events(timeline)
            except InputError as exc:
                # the timeline stops at its first problem: every event's keys and values are
                # checked too, so each of their problems is said
                found = [problem for _, params, where in timeline
                         for problem in _params_problems(
                             type(target.base_params),
                             {**target.base_params.model_dump(), **params}, f"{where}.params")]
                wheres = {problem.where for problem in found}
                self.problems += [p for p in exc.problems if p.where not in wheres] + found

    def _objects(self) -> list[str]:
        """The labels of the file's objects (made or not), not its groups'."""
        return [label for label in self.labels if label not in self.group_labels]

    def tracks(self) -> None:
        """Each ``[[track]]`` checked and added to what it moves (its keys checked alone where
        that node or light was refused)."""
        for index, (track, bad) in enumerate(self.tables["track"]):
            where = f"{self.name}: track[{index}]"
            if track is None or bad & {"target", "interpolation", "keys", ""}:
                continue
            kind, target = self.collect(parse_target, track.target, f"{where}.target") or \
                (None, None)
            subject = self._track_subject(kind, target, f"{where}.target")
            if subject is None:  # nothing to move: the keys are still checked
                if kind is not None:
                    self.collect(make_track, track.target, track.keys, track.interpolation,
                                 where)
                continue
            self.collect(self.scene.add_track,
                         track.target if subject == "camera" else subject, track.keys,
                         track.interpolation, where)

    def _track_subject(self, kind: str | None, target: str | None, where: str) -> Any:
        """What a track's target names: "camera", a node, a light; None where it names
        nothing made (said, unless it was refused itself)."""
        if kind == "camera":
            return "camera"
        if kind == "object":
            if target in self.labels:
                return self.labels[target][0]
            if not self.unlabelled:
                self.problems.append(InputError(_no_object(target, list(self.labels)), where))
        elif kind == "light":
            lights, names = self.file_lights, self.light_names
            if target in names:  # None where that light was refused
                return self.scene.light_names.get(target)
            if target.isdigit() and int(target) < len(lights):
                return lights[int(target)]
            have = f"light:0 to light:{len(lights) - 1}" if lights else "none"
            named = f", or by name: {', '.join(sorted(names)[:10])}" if names else ""
            self.problems.append(InputError(f"no light {target[:80]!r} (lights: "
                                            f"{have}{named})", where))
        return None

    def parents(self) -> None:
        """Every parent named exists and none is its own ancestor (checked once all the
        scene's nodes are made; not where a node was refused, which is said already)."""
        if not self.children or self.unlabelled or \
                any(node is None for node, _ in self.labels.values()):
            return
        try:
            hierarchy = Hierarchy(self.scene.nodes(), self.name)
        except InputError as exc:
            self.problems.append(exc)
            return
        for child, where in self.children:
            if not isinstance(child, SceneNode):  # the camera, a light
                self.collect(hierarchy.resolve, child.parent, where)

def _collect(problems: list[InputError], function: Callable[..., T], *args: Any) -> T | None:
    """``function(*args)``, or ``None`` with its ``InputError`` added to ``problems``."""
    try:
        return function(*args)
    except InputError as exc:
        problems.append(exc)
        return None


def _params_problems(model: type[BaseModel], values: dict[str, Any],
                     where: str) -> list[InputError]:
    """Each problem ``model`` finds in ``values`` (none: ``[]``)."""
    try:
        model(**values)
    except ValidationError as error:
        return validation_problems(error, where, model)
    return []


def _mesh_name(spec: str) -> str:
    """The name :func:`load_mesh` gives the mesh of ``spec`` (a label's stem)."""
    return spec.split("?", 1)[0] if spec.startswith("builtin:") else Path(spec).name


def _valid_alone(cls: type[M], values: dict[str, Any]) -> tuple[M, set[str]]:
    """``cls(**values)``, or, where that fails, a ``cls`` of the fields that are valid alone
    and the names of those that are not ("" for the whole table)."""
    try:
        return cls(**values), set()
    except ValidationError as exc:
        bad = {str(error["loc"][0]) if error["loc"] else "" for error in exc.errors()}
        kept = {k: v for k, v in values.items() if k not in bad and
                (k in cls.model_fields or cls.model_config.get("extra") == "allow")}
        try:
            return cls(**kept), bad
        except ValidationError:  # a check across fields: the fields it needs stay unknown
            return cls.model_construct(**kept), bad | {""}


def _each(cls: type[M], items: Any) -> list[tuple[M | None, set[str]]]:
    """Each table of a list validated alone: (the table's valid part, its invalid fields), or
    ``(None, ...)`` for an item that is not a table (the scene's validation said so)."""
    if not isinstance(items, list):
        return []
    return [_valid_alone(cls, item) if isinstance(item, dict) else (None, {""})
            for item in items]


def _no_object(label: str, labels: list[str]) -> str:
    match = closest(label, labels)
    hint = f"did you mean '{match[:80]}'? " if match is not None else ""
    names = ", ".join(name[:40] for name in labels[:10]) or "none"
    if len(labels) > 10:
        names += f", ... ({len(labels)} in all)"
    return f"no object named {label[:80]!r} ({hint}objects: {names})"


def _file_order(where: str | None, name: str, order: dict[str, int]) -> tuple[int, int]:
    """Where a problem's key comes in the file: its table's place among the file's keys,
    then the item's index (``object[2]``)."""
    key = (where or "").removeprefix(f"{name}: ")
    match = re.match(r"([^.\[]*)(?:\[(\d+)\])?", key)
    top, index = match.group(1), match.group(2)
    return order.get(top, len(order)), int(index) if index is not None else -1
