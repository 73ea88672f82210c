"""Scene files: TOML (DESIGN.md's format) or a dict, validated into a
:class:`~deferred.scene.model.Scene`; ``deferred render`` with no scene loads the built-in demo.

Validation names the file, the key and the problem in one line
(``demo.toml: object[1].params.shells: Input should be greater than or equal to 0 (got -3)``).
"""
from __future__ import annotations

import sys
from importlib import resources
from pathlib import Path
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

from deferred.errors import InputError
from deferred.gl.meshes import MeshData
from deferred.interfaces import registry
from deferred.names import LightPath
from deferred.scene.camera import Camera, model_matrix
from deferred.scene.meshes import load_mesh
from deferred.scene.model import Scene, SceneObject, check_size, unique_label
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
MIN_SCALE = 1e-6  # an object smaller is a mistake of units; 1/scale must fit float32
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
        if np.any(np.abs(scale) < MIN_SCALE):  # its normal matrix would overflow float32
            raise ValueError(f"scale must be at least {MIN_SCALE:g} in size")
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
        None, description="how lights reach the pixels (deferred.lighting.paths); default the "
                          "fastest the context allows")
    camera: CameraModel = Field(default_factory=CameraModel)
    ssao: dict[str, Any] | None = Field(
        None, description="screen-space ambient occlusion (the same as [[effect]] type 'ssao')")
    object: list[ObjectModel] = Field(default_factory=list)
    light: list[TypedModel] = Field(default_factory=list)
    effect: list[TypedModel] = Field(default_factory=list)
    event: list[EventModel] = Field(default_factory=list)


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
    """A scene from a scene file's tables as a dict (what :func:`scene_from_toml` parses);
    validated the same way, errors naming ``name`` and the key."""
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
    labels: set[str] = set()
    next_index: dict[str, int] = {}  # unique_label's, for every unnamed object
    for index, obj in enumerate(model.object):
        where = f"{name}: object[{index}]"
        material_cls = registry.materials.get(obj.material, f"{where}.material")
        material = material_cls.from_dict(obj.params, base_dir, f"{where}.params")
        if obj.mesh not in meshes:
            meshes[obj.mesh] = load_mesh(obj.mesh, base_dir, f"{where}.mesh")
        mesh = meshes[obj.mesh]
        label = obj.name or unique_label(labels, mesh.name, next_index)
        if label in labels:
            raise InputError(f"duplicate object name '{label}'", f"{where}.name")
        labels.add(label)
        scene.objects.append(SceneObject(label, mesh, material,
                                         model_matrix(obj.position, obj.rotation, obj.scale),
                                         where=where))
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
    # each object's events added at once (in the file's order: it breaks ties of time)
    by_label = {obj.label: obj for obj in scene.objects}
    grouped: dict[str, list[tuple[float, dict[str, Any], str]]] = {}
    for index, event in enumerate(model.event):
        where = f"{name}: event[{index}]"
        if event.object not in by_label:
            scene.add_event(event.object, event.time, event.params, where)  # names the choices
        grouped.setdefault(event.object, []).append((event.time, event.params, where))
    for label, events in grouped.items():
        by_label[label].add_events(events)
    return scene
