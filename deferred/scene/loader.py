"""Scene files: TOML (README.md, "Scene files") or a dict, validated into a
:class:`~deferred.scene.model.Scene`; ``deferred render`` with no scene loads the built-in demo.

Validation names the file, the key and the problem in one line
(``demo.toml: object[1].params.shells: Input should be greater than or equal to 0 (got -3)``).
"""
from __future__ import annotations

import re
import sys
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any, Literal, TypeVar

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from deferred.errors import InputError, input_error
from deferred.gl.meshes import MeshData
from deferred.interfaces import registry
from deferred.interfaces.material import Material
from deferred.names import LightPath
from deferred.scene.camera import Camera, model_matrix
from deferred.scene.meshes import load_mesh
from deferred.scene.model import (
    OPACITY_SCALES,
    CameraModel,
    Scene,
    SceneObject,
    ShadowBudget,
    Transform,
    check_light_name,
    check_size,
    unique_label,
)
from deferred.scene.tracks import (
    INTERPOLATIONS,
    MIN_SCALE,
    make_track,
    parse_target,
    scale_too_small,
)
from deferred.validation import (
    Radiance,
    StrictValues,
    closest,
    require_regular_file,
    validation_problems,
)

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

Vec3 = tuple[float, float, float]
DEMO_SCENE = "demo.toml"
T = TypeVar("T")
M = TypeVar("M", bound=BaseModel)


class _Strict(StrictValues):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class ObjectModel(_Strict):
    name: str | None = Field(None, max_length=1000,
                             description="label: printable, no control characters")
    mesh: str
    material: str = "standard"
    position: Vec3 = (0.0, 0.0, 0.0)
    rotation: Vec3 = Field((0.0, 0.0, 0.0), description="degrees, applied X, then Y, then Z")
    scale: float | Vec3 = 1.0
    params: dict[str, Any] = Field(default_factory=dict)

    @field_validator("name")
    @classmethod
    def _printable(cls, name: str | None) -> str | None:
        # a label goes into file names, messages and contact sheets
        if name is not None and (not name or any(ord(c) < 32 or ord(c) == 127 for c in name)):
            raise ValueError("must be printable text: no control characters (newline, tab, "
                             "NUL) and not empty")
        return name

    @model_validator(mode="after")
    def _check_scale(self) -> ObjectModel:
        scale = np.broadcast_to(np.asarray(self.scale, dtype=float), (3,))
        if np.any(scale == 0.0):
            raise ValueError("scale must not be zero")
        if scale_too_small(scale):  # its normal matrix would overflow float32
            raise ValueError(f"scale must be at least {MIN_SCALE:g} in size")
        return self


class EventModel(_Strict):
    """An ``[[event]]`` table: from ``time`` on, ``object``'s material takes ``params``."""

    time: float = Field(ge=0.0, allow_inf_nan=False, description="seconds")
    object: str = Field(description="the name (label) of a scene object")
    params: dict[str, Any] = Field(description="material parameters, merged over the object's")


class TrackModel(_Strict):
    """A ``[[track]]`` table: keys moving the camera, a light or an object
    (:mod:`deferred.scene.tracks`)."""

    target: str = Field(description="what moves: 'camera', 'object:NAME', 'light:INDEX' (0 is "
                                    "the first [[light]]) or 'light:NAME'")
    interpolation: Literal[INTERPOLATIONS] = Field(
        "linear", description="between keys: step (hold), linear, or smooth (cubic Hermite, "
                              "Catmull-Rom tangents, zero at the first and last keys)")
    keys: list[dict[str, Any]] = Field(
        min_length=1, description="{ time = seconds, and the properties set then }, in rising "
                                  "time")


class TypedModel(BaseModel):
    """A ``[[light]]`` or ``[[effect]]`` table: its type, then that type's parameters."""

    model_config = ConfigDict(extra="allow")
    type: str


class ShadowsModel(_Strict):
    """The ``[shadows]`` table: the shadow atlas and its budget (:class:`ShadowBudget`)."""

    atlas_size: int = Field(4096, description="texels on a side of the shadow atlas (a power "
                                              "of two, 256..16384)")
    max_shadowed_lights: int = Field(16, ge=1, le=64, description="lights given shadow maps, "
                                     "in scene order; the rest are unshadowed")
    opacity_scale: float = Field(0.25, description="texels on a side of the fur's deep "
                                 "opacity maps per shadow-map texel (1, 0.5, .. 1/16)")

    @field_validator("opacity_scale")
    @classmethod
    def _fraction(cls, value: float) -> float:
        if value not in OPACITY_SCALES:
            raise ValueError("must be 1, 0.5, 0.25, 0.125 or 0.0625")
        return value

    @field_validator("atlas_size")
    @classmethod
    def _power_of_two(cls, value: int) -> int:
        if not 256 <= value <= 16384 or value & (value - 1):
            raise ValueError("must be a power of two in 256..16384")
        return value


class SceneModel(_Strict):
    size: tuple[int, int] = (1280, 720)
    background: Radiance = Field((0.02, 0.02, 0.025),
                                 description="linear RGB behind everything, each >= 0")
    exposure: float = Field(1.0, gt=0.0)
    tonemap: Literal["reinhard", "aces", "none"] = "aces"
    light_path: LightPath | None = Field(
        None, description="how lights reach the pixels (deferred.lighting.paths); default the "
                          "fastest the context allows")
    camera: CameraModel = Field(default_factory=CameraModel)
    shadows: ShadowsModel = Field(default_factory=ShadowsModel)
    ssao: dict[str, Any] | None = Field(
        None, description="screen-space ambient occlusion (the same as [[effect]] type 'ssao')")
    object: list[ObjectModel] = Field(default_factory=list)
    light: list[TypedModel] = Field(default_factory=list)
    effect: list[TypedModel] = Field(default_factory=list)
    event: list[EventModel] = Field(default_factory=list)
    track: list[TrackModel] = Field(default_factory=list)


def builtin_scenes() -> list[str]:
    """Names of the scenes shipped with the package (``builtin:<name>``)."""
    folder = resources.files("deferred").joinpath("scenes")
    return sorted(entry.name.removesuffix(".toml") for entry in folder.iterdir()
                  if entry.name.endswith(".toml"))


def load_scene(path: str | Path | None = None) -> Scene:
    """Load a scene file; ``None`` loads the built-in demo scene, ``builtin:<name>`` another
    scene shipped with the package (``builtin:overdraw``, the bench scene with overdraw)."""
    if path is None:
        path = f"builtin:{DEMO_SCENE.removesuffix('.toml')}"
    if isinstance(path, str) and path.startswith("builtin:"):
        name = path.removeprefix("builtin:").removesuffix(".toml")
        if name not in builtin_scenes():
            raise InputError(f"no built-in scene '{name}' (choose from "
                             f"{', '.join(builtin_scenes())})", path)
        text = resources.files("deferred").joinpath("scenes", f"{name}.toml").read_text("utf-8")
        return scene_from_toml(text, name=f"builtin:{name}.toml", base_dir=None)
    path = Path(path)
    require_regular_file(path, "scene file", str(path))
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read scene file: {exc}", str(path)) from None
    return scene_from_toml(text, name=path.name, base_dir=path.parent)


def scene_from_toml(text: str, name: str = "<string>", base_dir: Path | None = None) -> Scene:
    """A scene from the text of a scene file; ``name`` is what errors call it, ``base_dir``
    where relative mesh and texture paths are found."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"malformed TOML: {exc}", name) from None
    except RecursionError:
        raise InputError("malformed TOML: arrays or tables nested too deep", name) from None
    return scene_from_dict(data, name, base_dir)


def scene_from_dict(data: dict[str, Any], name: str = "<dict>",
                    base_dir: Path | None = None) -> Scene:
    """The scene ``data`` describes (a scene file's tables). Every problem is found before one
    is raised: an :class:`InputError` for one, :class:`InputErrors` naming each (in the file's
    order) for several; unknown keys and names say the closest known one."""
    problems: list[InputError] = []
    try:
        model = SceneModel(**data)
        objects, lights, effects_, events, tracks = (
            [(item, set()) for item in items] for items in (
                model.object, model.light, model.effect, model.event, model.track))
    except ValidationError as exc:
        problems += validation_problems(exc, name, SceneModel)
        # the parts valid alone are checked further: all problems are said at once
        bad = {error["loc"][0] for error in exc.errors() if error["loc"]}
        model = _valid_alone(SceneModel, {k: v for k, v in data.items()
                                          if k not in bad and k not in _LISTS})[0]
        objects, lights, effects_, events, tracks = (
            _each(cls, data.get(key)) for key, cls in (
                ("object", ObjectModel), ("light", TypedModel), ("effect", TypedModel),
                ("event", EventModel), ("track", TrackModel)))
    _collect(problems, check_size, model.size, f"{name}: size")
    c = model.camera
    scene = Scene(camera=Camera(c.position, c.target, c.up, c.fov, c.near, c.far),
                  size=model.size, background=model.background, exposure=model.exposure,
                  tonemap=model.tonemap, light_path=model.light_path, source=name,
                  shadow_budget=ShadowBudget(model.shadows.atlas_size,
                                             model.shadows.max_shadowed_lights,
                                             model.shadows.opacity_scale))
    meshes: dict[str, MeshData | None] = {}
    # label -> (the object, or None where it is not made; its material class, where known)
    labels: dict[str, tuple[SceneObject | None, type[Material] | None]] = {}
    taken: set[str] = set()  # the labels, for unique_label
    unlabelled = False  # an object whose label is not known (its name is refused)
    next_index: dict[str, int] = {}  # unique_label's, for every unnamed object
    for index, (obj, bad) in enumerate(objects):
        where = f"{name}: object[{index}]"
        if obj is None:
            continue
        material = material_cls = None
        if "material" not in bad:
            material_cls = _collect(problems, registry.materials.get, obj.material,
                                    f"{where}.material")
            if material_cls is not None and "params" not in bad:
                material = _collect(problems, material_cls.from_dict, obj.params, base_dir,
                                    f"{where}.params")
        mesh = None
        if "mesh" not in bad:
            if obj.mesh not in meshes:
                meshes[obj.mesh] = _collect(problems, load_mesh, obj.mesh, base_dir,
                                            f"{where}.mesh")
            mesh = meshes[obj.mesh]
        if "name" in bad or (obj.name is None and "mesh" in bad):
            unlabelled = True
            continue
        # a mesh that failed to load is named as it would be, for the events naming it
        label = obj.name or unique_label(taken, mesh.name if mesh is not None else
                                         _mesh_name(obj.mesh), next_index)
        if label in labels:
            problems.append(InputError(f"duplicate object name '{label}'", f"{where}.name"))
            continue
        made = None
        if not bad and material is not None and mesh is not None:
            made = SceneObject(label, mesh, material,
                               model_matrix(obj.position, obj.rotation, obj.scale), where=where,
                               transform=Transform.model_construct(
                                   position=obj.position, rotation=obj.rotation,
                                   scale=obj.scale))
            scene.objects.append(made)
        labels[label] = (made, material_cls)
        taken.add(label)
    # each [[light]] by its index in the file (None where refused), and its name
    file_lights: list = []
    light_names: set[str] = set()
    for index, (light, bad) in enumerate(lights):
        where = f"{name}: light[{index}]"
        file_lights.append(None)
        values = dict(light.model_extra or {}) if light is not None else {}
        light_name = values.pop("name", None)
        if light_name is not None:
            try:
                check_light_name(light_name, light_names, f"{where}.name")
                light_names.add(light_name)
            except InputError as exc:
                problems.append(exc)
                light_name = None
        if light is None or "type" in bad:
            continue
        light_cls = _collect(problems, registry.lights.get, light.type, f"{where}.type")
        if light_cls is not None:
            made = _collect(problems, light_cls.from_dict, values, where)
            if made is not None:
                scene.lights.append(made)
                file_lights[index] = made
                if light_name is not None:
                    scene.light_names[light_name] = made
    effects = [(f"{name}: effect[{index}]", e.type, e.model_extra or {})
               for index, (e, bad) in enumerate(effects_) if e is not None and "type" not in bad]
    if model.ssao is not None:  # the [ssao] table of earlier scene files
        if any(kind == "ssao" for _, kind, _ in effects):
            problems.append(InputError("ssao is given both as [ssao] and as an [[effect]]; "
                                       "keep one", f"{name}: ssao"))
        else:
            effects.insert(0, (f"{name}: ssao", "ssao", model.ssao))
    seen: set[str] = set()
    for where, kind, values in effects:
        if kind in seen:
            problems.append(InputError(f"effect '{kind}' is given twice (one of each type)",
                                       f"{where}.type"))
            continue
        seen.add(kind)
        effect_cls = _collect(problems, registry.effects.get, kind, f"{where}.type")
        if effect_cls is not None:
            made = _collect(problems, effect_cls.from_dict, values, where)
            if made is not None:
                scene.effects.append(made)
    # each object's events added at once (in the file's order: it breaks ties of time)
    grouped: dict[str, list[tuple[float, dict[str, Any], str]]] = {}
    for index, (event, bad) in enumerate(events):
        where = f"{name}: event[{index}]"
        if event is None or "object" in bad:
            continue
        if event.object not in labels:
            if not unlabelled:
                problems.append(InputError(_no_object(event.object, list(labels)),
                                           f"{where}.object"))
            continue
        target, material_cls = labels[event.object]
        if target is not None and not bad:
            grouped.setdefault(event.object, []).append((event.time, event.params, where))
        elif material_cls is not None and "params" not in bad:
            # the object is refused: the event's own keys and values are still checked
            problems += _params_problems(material_cls.Params, event.params, f"{where}.params")
    for label, timeline in grouped.items():
        target = labels[label][0]
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
            problems += [p for p in exc.problems if p.where not in wheres] + found
    _load_tracks(scene, name, tracks, labels, unlabelled, file_lights, light_names, problems)
    if problems:
        order = {key: position for position, key in enumerate(data)}
        each = [one for problem in problems for one in problem.problems]
        raise input_error(sorted(each, key=lambda p: _file_order(p.where, name, order)))
    return scene


def _load_tracks(scene: Scene, name: str, tracks: list, labels: dict, unlabelled: bool,
                 file_lights: list, light_names: set[str], problems: list[InputError]) -> None:
    """Each ``[[track]]`` checked and added to what it moves (its keys checked alone where that
    object or light was refused)."""
    for index, (track, bad) in enumerate(tracks):
        where = f"{name}: track[{index}]"
        if track is None or bad & {"target", "interpolation", "keys", ""}:
            continue
        target_where = f"{where}.target"
        kind, target = _collect(problems, parse_target, track.target, target_where) or \
            (None, None)
        subject: Any = "camera" if kind == "camera" else None
        if kind == "object":
            if target in labels:
                subject = labels[target][0]
            elif not unlabelled:
                problems.append(InputError(_no_object(target, list(labels)), target_where))
        elif kind == "light":
            if target in light_names:  # None where that light was refused
                subject = scene.light_names.get(target)
            elif target.isdigit() and int(target) < len(file_lights):
                subject = file_lights[int(target)]
            else:
                have = f"light:0 to light:{len(file_lights) - 1}" if file_lights else "none"
                named = f", or by name: {', '.join(sorted(light_names)[:10])}" \
                    if light_names else ""
                problems.append(InputError(f"no light {target[:80]!r} (lights: {have}{named})",
                                           target_where))
        if subject is None:  # nothing to move: the keys are still checked
            if kind is not None:
                _collect(problems, make_track, track.target, track.keys, track.interpolation,
                         where)
            continue
        _collect(problems, scene.add_track, track.target if subject == "camera" else subject,
                 track.keys, track.interpolation, where)


_LISTS = ("object", "light", "effect", "event", "track")  # lists of tables, checked item by item


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
