"""Scenes: camera, objects (mesh + transform + material), lights; loaded from TOML files.

The file format is DESIGN.md's. Validation names the file, the key and the problem in one line
(``demo.toml: object[1].params.shells: Input should be greater than or equal to 0 (got -3)``).

A scene may carry a timeline: ``[[event]]`` tables (``time``, ``object``, ``params``) that change
an object's material parameters from their time on. :meth:`SceneObject.params_at` gives an
object's parameters at a time and :meth:`Scene.apply_timeline` sets them on every object with
events (the renderer does so before each frame).
"""

from __future__ import annotations

import math
import sys
from bisect import bisect_right
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from deferred.core.passes import Phase
from deferred.errors import InputError
from deferred.gbuffer.layout import GBufferLayout
from deferred.gl.meshes import MeshData
from deferred.interfaces import registry
from deferred.interfaces.effect import Effect
from deferred.interfaces.light import Light
from deferred.interfaces.material import Material, MaterialParams, compose_layout
from deferred.interfaces.shading import ShadingModel
from deferred.names import LightPath
from deferred.params import validate_params
from deferred.scene.camera import Camera, model_matrix
from deferred.scene.meshes import load_mesh
from deferred.validation import (
    Radiance,
    StrictValues,
    format_validation_error,
    require_regular_file,
)

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

Vec3 = tuple[float, float, float]
MAX_SIZE = 16384
MAX_DEPTH_RANGE = 1e7  # far / near
DEMO_SCENE = "demo.toml"


class _Strict(StrictValues):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class CameraModel(_Strict):
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
        return self


class EventModel(_Strict):
    """An ``[[event]]`` table: from ``time`` on, ``object``'s material takes ``params``."""

    time: float = Field(ge=0.0, allow_inf_nan=False, description="seconds")
    object: str = Field(description="the name (label) of a scene object")
    params: dict[str, Any] = Field(description="material parameters, merged over the object's")


class TypedModel(BaseModel):
    """A ``[[light]]`` or ``[[effect]]`` table: its type, then that type's parameters."""

    model_config = ConfigDict(extra="allow")
    type: str


class SceneModel(_Strict):
    size: tuple[int, int] = (1280, 720)
    background: Radiance = Field((0.02, 0.02, 0.025),
                                 description="linear RGB behind everything, each >= 0")
    exposure: float = Field(1.0, gt=0.0)
    tonemap: Literal["reinhard", "aces", "none"] = "aces"
    light_path: LightPath | None = Field(
        None, description="how lights reach the pixels (deferred.lighting.lists); default the "
                          "fastest the context allows")
    camera: CameraModel = Field(default_factory=CameraModel)
    ssao: dict[str, Any] | None = Field(
        None, description="screen-space ambient occlusion (the same as [[effect]] type 'ssao')")
    object: list[ObjectModel] = Field(default_factory=list)
    light: list[TypedModel] = Field(default_factory=list)
    effect: list[TypedModel] = Field(default_factory=list)
    event: list[EventModel] = Field(default_factory=list)


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
    _states: dict[int, MaterialParams] = field(default_factory=dict, init=False, repr=False)

    def __post_init__(self) -> None:
        if self.base_params is None:
            self.base_params = self.material.params
        self.events = tuple(sorted(self.events, key=lambda event: event.time))  # stable

    @property
    def event_times(self) -> tuple[float, ...]:
        """The times of this object's events, sorted."""
        return tuple(event.time for event in self.events)

    def params_at(self, time: float) -> MaterialParams:
        """The material parameters at ``time``: ``base_params`` updated by every event with
        ``event.time <= time``, in time order (ties: the order given). Validated once per
        distinct set of events applied, then cached."""
        count = bisect_right(self.event_times, time)
        if count == 0:
            return self.base_params
        state = self._states.get(count)
        if state is None:
            values = self.base_params.model_dump()
            for event in self.events[:count]:
                values.update(event.params)
            where = self.events[count - 1].where
            state = validate_params(type(self.base_params), values,
                                    f"{where}.params" if where else f"{self.label}: params")
            self._states[count] = state
        return state

    def add_event(self, time: float, params: Mapping[str, Any],
                  where: str | None = None) -> TimelineEvent:
        """Add an event: from ``time`` (seconds, finite, >= 0) on, the material takes
        ``params``. ``params`` are checked over ``base_params`` at once, and so is the
        object's state at every event time from this one on; errors name ``where``."""
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
        event = TimelineEvent(float(time), MappingProxyType(dict(params)), where)
        previous = self.events
        self.events = tuple(sorted((*previous, event), key=lambda e: e.time))
        self._states.clear()
        try:  # the merged states from its time on (the parameters' own cross-checks)
            for later in sorted({t for t in self.event_times if t >= event.time}):
                self.params_at(later)
        except InputError:
            self.events = previous
            self._states.clear()
            raise
        return event

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

    camera: Camera
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
        with events only; the others keep theirs."""
        for obj in self.objects:
            if obj.events:
                obj.material.params = obj.params_at(time)

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

    def add(self, mesh: MeshData | str, material: Material | str = "standard",
            position=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0), scale=1.0,
            label: str | None = None, params: dict[str, Any] | None = None) -> SceneObject:
        """Add an object from Python (scene files go through :func:`load_scene`)."""
        if isinstance(mesh, str):
            mesh = load_mesh(mesh)
        if isinstance(material, str):
            material = registry.materials.get(material).from_dict(params or {})
        obj = SceneObject(label or _unique_label(self, mesh.name), mesh, material,
                          model_matrix(position, rotation, scale))
        self.objects.append(obj)
        return obj


def _unique_label(scene: Scene, mesh_name: str) -> str:
    stem = mesh_name.removeprefix("builtin:").rsplit(".", 1)[0] or "object"
    taken = {obj.label for obj in scene.objects}
    index = 0
    while f"{stem}{index}" in taken:
        index += 1
    return f"{stem}{index}"


def parse_size(text: str, where: str = "--size") -> tuple[int, int]:
    parts = text.lower().split("x")
    try:
        width, height = (int(p) for p in parts)
    except ValueError:
        raise InputError(f"expected WIDTHxHEIGHT such as 1280x720, got '{text}'", where) from None
    return check_size((width, height), where)


def check_size(size: tuple[int, int], where: str) -> tuple[int, int]:
    width, height = size
    if not (1 <= width <= MAX_SIZE and 1 <= height <= MAX_SIZE):
        raise InputError(f"size {width}x{height} is impossible (each side 1..{MAX_SIZE})", where)
    return width, height


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
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"malformed TOML: {exc}", name) from None
    except RecursionError:
        raise InputError("malformed TOML: arrays or tables nested too deep", name) from None
    return scene_from_dict(data, name, base_dir)


def scene_from_dict(data: dict[str, Any], name: str = "<dict>",
                    base_dir: Path | None = None) -> Scene:
    try:
        model = SceneModel(**data)
    except ValidationError as exc:
        raise InputError(*format_validation_error(exc, name)) from None
    check_size(model.size, f"{name}: size")
    c = model.camera
    scene = Scene(camera=Camera(c.position, c.target, c.up, c.fov, c.near, c.far),
                  size=model.size, background=model.background, exposure=model.exposure,
                  tonemap=model.tonemap, light_path=model.light_path, source=name)
    meshes: dict[str, MeshData] = {}
    for index, obj in enumerate(model.object):
        where = f"{name}: object[{index}]"
        material_cls = registry.materials.get(obj.material, f"{where}.material")
        material = material_cls.from_dict(obj.params, base_dir, f"{where}.params")
        if obj.mesh not in meshes:
            meshes[obj.mesh] = load_mesh(obj.mesh, base_dir, f"{where}.mesh")
        mesh = meshes[obj.mesh]
        label = obj.name or _unique_label(scene, mesh.name)
        if any(o.label == label for o in scene.objects):
            raise InputError(f"duplicate object name '{label}'", f"{where}.name")
        scene.objects.append(SceneObject(label, mesh, material,
                                         model_matrix(obj.position, obj.rotation, obj.scale)))
    for index, light in enumerate(model.light):
        where = f"{name}: light[{index}]"
        light_cls = registry.lights.get(light.type, f"{where}.type")
        scene.lights.append(light_cls.from_dict(light.model_extra or {}, where))
    effects = [(f"{name}: effect[{index}]", e.type, e.model_extra or {})
               for index, e in enumerate(model.effect)]
    if model.ssao is not None:  # the [ssao] table of earlier scene files
        if any(kind == "ssao" for _, kind, _ in effects):
            raise InputError("ssao is given both as [ssao] and as an [[effect]]; keep one",
                             f"{name}: ssao")
        effects.insert(0, (f"{name}: ssao", "ssao", model.ssao))
    seen: set[str] = set()
    for where, kind, values in effects:
        if kind in seen:
            raise InputError(f"effect '{kind}' is given twice (one of each type)", f"{where}.type")
        seen.add(kind)
        effect_cls = registry.effects.get(kind, f"{where}.type")
        scene.effects.append(effect_cls.from_dict(values, where))
    for index, event in enumerate(model.event):
        scene.add_event(event.object, event.time, event.params, f"{name}: event[{index}]")
    return scene
