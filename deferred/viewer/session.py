"""What the viewer edits, without GL: the scene (loaded from its file), the edits of its
objects', lights' and effects' parameters (validated as a scene file's are; a refused value is
kept with its error for the panel, never applied), the camera controller, and saving it all
back to the scene file.

Saving goes through tomlkit, which keeps the file's comments, order and formatting: only the
edited values (and the camera, when asked) are written over.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from deferred.errors import DeferredError, InputError, one_line
from deferred.interfaces.catalogue import describe_fields
from deferred.params import validate_params
from deferred.scene.loader import load_scene
from deferred.scene.objects import SceneObject
from deferred.scene.scene import Scene
from deferred.viewer.camera import CameraController

OBJECT_WHERE = re.compile(r": object\[(\d+)\]$")


@dataclass
class Refused:
    """A value the panel was given and validation refused: shown with its error, not applied."""

    value: Any
    error: str


@dataclass
class Edits:
    """Values changed in the viewer since the scene was loaded, by where they go in the file."""

    objects: dict[int, dict[str, Any]] = field(default_factory=dict)  # scene.objects index
    lights: dict[int, dict[str, Any]] = field(default_factory=dict)  # [[light]] index
    effects: dict[int, dict[str, Any]] = field(default_factory=dict)  # scene.effects index

    def __bool__(self) -> bool:
        return bool(self.objects or self.lights or self.effects)


class Session:
    """The scene the viewer shows and everything edited in it."""

    def __init__(self, path: str | Path | None = None, scene: Scene | None = None):
        self.path = Path(path) if path is not None and not str(path).startswith("builtin:") \
            else None
        self.source = str(path) if path is not None else None
        self.scene = scene if scene is not None else load_scene(path)
        self.controller = CameraController(self.scene.camera)
        self.edits = Edits()
        self.refused: dict[tuple[str, int, str], Refused] = {}  # (kind, index, key)
        self.scene_error: str | None = None  # the scene file as last read, refused
        self.version = 0  # counts changes that need a new frame

    # -- the scene's parts -------------------------------------------------------------------
    def fields(self, kind: str, index: int) -> list[dict[str, Any]]:
        """Each parameter of an object's material, a light or an effect: name, type, range,
        choices, description (as ``deferred params`` lists them)."""
        return describe_fields(type(self._params(kind, index)))

    def value(self, kind: str, index: int, key: str) -> Any:
        """The value the panel shows: a refused one while it stands, else the current one."""
        refused = self.refused.get((kind, index, key))
        return refused.value if refused is not None else getattr(self._params(kind, index), key)

    def _params(self, kind: str, index: int):
        if kind == "object":
            return self.scene.objects[index].base_params
        if kind == "light":
            return self.scene.lights[index].params
        return self.scene.effects[index].params

    def edit(self, kind: str, index: int, key: str, value: Any) -> str | None:
        """Set one parameter of object, light or effect ``index`` (``kind``), validated as a
        scene file's value is. Returns None when applied, else the error (one line naming the
        key), kept for the panel while the value stands; the scene keeps its last good value."""
        where = (kind, index, key)
        try:
            if kind == "object":
                self.scene.objects[index].set_params(**{key: value})
                target = self.edits.objects.setdefault(index, {})
            elif kind == "light":
                light = self.scene.lights[index]
                light.params = validate_params(type(light.params),
                                               {**light.params.model_dump(), key: value},
                                               f"{self.scene.source}: light[{index}]")
                target = self.edits.lights.setdefault(index, {})
            elif kind == "effect":
                effect = self.scene.effects[index]
                effect.params = validate_params(type(effect.params),
                                                {**effect.params.model_dump(), key: value},
                                                f"{self.scene.source}: effect {effect.name}")
                target = self.edits.effects.setdefault(index, {})
            else:
                raise ValueError(f"unknown kind {kind!r}")
        except DeferredError as exc:
            self.refused[where] = Refused(value, one_line(str(exc)))
            return self.refused[where].error
        except (TypeError, ValueError) as exc:  # a plugin's own check, not an InputError
            self.refused[where] = Refused(value, one_line(f"{kind}[{index}].{key}: {exc}"))
            return self.refused[where].error
        self.refused.pop(where, None)
        target[key] = value
        self.version += 1
        return None

    def errors(self) -> list[str]:
        """Every error the panels show now."""
        shown = [refused.error for refused in self.refused.values()]
        return ([self.scene_error] if self.scene_error else []) + shown

    @staticmethod
    def _file_index(obj: SceneObject) -> int:
        match = OBJECT_WHERE.search(obj.where or "")
        if match is None:
            raise InputError(f"object {obj.label!r} is not from the scene file", "save")
        return int(match.group(1))

    # -- the scene file ----------------------------------------------------------------------
    def reload(self) -> str | None:
        """Read the scene file again. On success the scene is replaced (edits not saved are
        dropped; the camera stays where it was moved unless the file's camera changed);
        otherwise the error is kept and returned and the scene stays as it was."""
        try:
            scene = load_scene(self.path if self.path is not None else self.source)
        except DeferredError as exc:
            self.scene_error = one_line(str(exc))
            return self.scene_error
        same_camera = scene.camera == self.controller.home
        self.scene = scene
        if same_camera:
            self.controller.home = scene.camera
        else:
            self.controller.reset(scene.camera)
        self.edits = Edits()
        self.refused.clear()
        self.scene_error = None
        self.version += 1
        return None

    def save(self, path: str | Path | None = None, camera: bool = False) -> Path:
        """Write the edits (and the camera, with ``camera``) into the scene file, or a copy of
        it at ``path``; comments and layout stay. Returns the path written."""
        import tomlkit

        from deferred.io.images import write_text

        source = self.path
        target = Path(path) if path is not None else source
        if target is None:
            raise InputError("the built-in scene has no file: save to a path", "save")
        if source is not None:
            document = tomlkit.parse(source.read_text(encoding="utf-8"))
        else:
            from importlib import resources

            name = (self.source or "builtin:demo").removeprefix("builtin:")
            document = tomlkit.parse(resources.files("deferred").joinpath(
                "scenes", f"{name.removesuffix('.toml')}.toml").read_text("utf-8"))
        for index, values in self.edits.objects.items():
            table = document["object"][self._file_index(self.scene.objects[index])]
            if "params" not in table:
                table["params"] = tomlkit.table()
            _set_values(table["params"], values)
        for index, values in self.edits.lights.items():
            _set_values(document["light"][index], values)
        for index, values in self.edits.effects.items():
            _set_values(self._effect_table(document, index), values)
        if camera:
            cam = self.controller.camera()
            if "camera" not in document:
                document["camera"] = tomlkit.table()
            for key in ("position", "target", "up"):
                document["camera"][key] = [float(v) for v in getattr(cam, key)]
            document["camera"]["fov"] = float(cam.fov)
        write_text(target, tomlkit.dumps(document))
        return target

    def _effect_table(self, document, index: int):
        """The table of scene.effects[index] in the file: ``[ssao]`` first, then the
        ``[[effect]]`` tables in order (as the loader made them)."""
        tables = ([document["ssao"]] if "ssao" in document else []) + \
            list(document.get("effect", []))
        return tables[index]


def _set_values(table, values: dict[str, Any]) -> None:
    """Write ``values`` into a TOML table; None (TOML has none) leaves the key out."""
    for key, value in values.items():
        if value is None:
            table.pop(key, None)
        else:
            table[key] = _toml_value(value)


def _toml_value(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_toml_value(v) for v in value]
    return value
