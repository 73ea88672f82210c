"""Every registered type (material, light, effect, shading model) and its parameters, as data
read from the pydantic ``Params`` models: name, type, default, range, choices and description.
``deferred params`` prints it (``--json`` as it is here; :mod:`deferred.cli.params` formats
it as text); ``deferred schema`` builds on the same registries.
"""

from __future__ import annotations

import inspect
import json
import types
import typing
from enum import Enum
from pathlib import PurePath
from typing import Annotated, Any, Literal

from pydantic import BaseModel
from pydantic_core import PydanticUndefined, to_jsonable_python

from deferred.errors import InputError
from deferred.interfaces import registry
from deferred.validation import closest

# kind -> registry; the kind is what `deferred params KIND` takes
KINDS: dict[str, registry.Registry] = {
    "material": registry.materials,
    "light": registry.lights,
    "effect": registry.effects,
    "shading_model": registry.shading_models,
}
BOUNDS = (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<"))


def resolve_kind(kind: str, where: str | None = None) -> str:
    """``kind`` as a key of :data:`KINDS` (``materials`` and ``shading-model`` are taken too);
    ``InputError`` naming the choices and the closest one."""
    key = kind.strip().lower().replace("-", "_")
    for candidate in (key, key.removesuffix("s")):
        if candidate in KINDS:
            return candidate
    match = closest(key, KINDS)
    hint = f"did you mean '{match}'? " if match else ""
    raise InputError(f"unknown kind '{kind[:80]}' ({hint}choose from {', '.join(KINDS)})", where)


def selected(kind: str | None = None, name: str | None = None
             ) -> list[tuple[str, str, type]]:
    """``(kind, name, class)`` of every registered type, of one kind, or the one named (plugins
    included). A ``kind`` that is no kind but a type's name selects that type."""
    if kind is not None and name is None and kind.strip().lower().replace("-", "_") not in \
            KINDS and kind.strip().lower().removesuffix("s") not in KINDS:
        owners = [k for k, reg in KINDS.items() if kind in reg]
        if len(owners) == 1:
            return selected(owners[0], kind)
    kinds = [resolve_kind(kind)] if kind is not None else list(KINDS)
    if name is not None:
        known = KINDS[kinds[0]]
        if name not in known:
            raise InputError(known.unknown(name), "NAME")
        return [(kinds[0], name, known.get(name))]
    return [(k, n, cls) for k in kinds for n, cls in KINDS[k].items()]


def describe_type(kind: str, name: str, cls: type) -> dict[str, Any]:
    """A type as data (JSON-ready): what it is, where it comes from, and its parameters."""
    entry: dict[str, Any] = {"kind": kind, "name": name, "module": cls.__module__,
                             "summary": _summary(cls) or _summary(getattr(cls, "Params", None)),
                             "id": getattr(cls, "type_id", None)}
    if kind == "material":
        entry["shading_model"] = getattr(cls, "shading_model", None)
    if kind == "light":
        volume = getattr(cls, "volume", None)
        entry["volume"] = volume.value if isinstance(volume, Enum) else volume
        # the type's own vec4s after its record's four (Light.data)
        entry["data"] = [{"name": datum.name, "description": datum.description}
                         for datum in getattr(cls, "data", ())]
    if kind == "effect":
        entry["pipelines"] = [str(getattr(p, "value", p)) for p in getattr(cls, "pipelines", ())]
        entry["reads_gbuffer"] = bool(getattr(cls, "reads_gbuffer", False))
    if kind == "shading_model":
        entry["glsl_file"] = getattr(cls, "glsl_file", None)
        entry["materials"] = [material for material, owner in registry.materials.items()
                              if getattr(owner, "shading_model", None) == name]
    params = getattr(cls, "Params", None)
    entry["params"] = describe_fields(params) if isinstance(params, type) and \
        issubclass(params, BaseModel) else []
    return entry


def catalogue(kind: str | None = None, name: str | None = None) -> list[dict[str, Any]]:
    """:func:`describe_type` of each type :func:`selected` picks."""
    return [describe_type(*chosen) for chosen in selected(kind, name)]


def describe_fields(model: type[BaseModel]) -> list[dict[str, Any]]:
    """Each field of ``model``: name, type (as written in Python), default (JSON), whether it
    is required, range (``ge``/``gt``/``le``/``lt``; ``each`` when it bounds every item of a
    list), choices (a ``Literal``'s or an ``Enum``'s values) and description."""
    rows = []
    for name, field in model.model_fields.items():
        bounds = _bounds(field.metadata)
        each = False
        if not bounds:  # a vector of bounded numbers (an albedo: each in [0, 1])
            items = _item_types(field.annotation)
            item_bounds = [_bounds(_metadata(item)) for item in items]
            if items and item_bounds[0] and all(b == item_bounds[0] for b in item_bounds):
                bounds, each = item_bounds[0], True
        required = field.is_required()
        rows.append({
            "name": name,
            "type": type_text(field.annotation),
            "default": None if required else _jsonable(_default(field)),
            "required": required,
            "range": bounds,
            "each": each,
            "choices": choices(field.annotation),
            "description": field.description or "",
        })
    return rows


def type_text(annotation: Any) -> str:
    """``annotation`` as a reader writes it: ``float``, ``tuple[float, float, float]``,
    ``'reinhard' | 'aces'`` (a ``Literal`` shows its values), ``str | None``."""
    origin = typing.get_origin(annotation)
    arguments = typing.get_args(annotation)
    if origin is Annotated:
        return type_text(arguments[0])
    if origin is Literal:
        return " | ".join(_value_text(value) for value in arguments)
    if isinstance(annotation, type) and issubclass(annotation, Enum):
        return " | ".join(_value_text(member.value) for member in annotation)
    if origin in (typing.Union, types.UnionType):
        return " | ".join(type_text(member) for member in arguments)
    if annotation is type(None):
        return "None"
    if annotation is Any:
        return "any"
    if origin is not None:
        inner = ", ".join("..." if a is Ellipsis else type_text(a) for a in arguments)
        base = getattr(origin, "__name__", str(origin))
        return f"{base}[{inner}]" if inner else base
    if isinstance(annotation, type):
        return "path" if issubclass(annotation, PurePath) else annotation.__name__
    return str(annotation).replace("typing.", "")


def choices(annotation: Any) -> list[Any] | None:
    """The values a ``Literal`` or an ``Enum`` (alone or with ``None``) allows, else ``None``."""
    origin = typing.get_origin(annotation)
    if origin is Annotated:
        return choices(typing.get_args(annotation)[0])
    if origin is Literal:
        return [_jsonable(value) for value in typing.get_args(annotation)]
    if isinstance(annotation, type) and issubclass(annotation, Enum):
        return [_jsonable(member.value) for member in annotation]
    if origin in (typing.Union, types.UnionType):
        found = [choices(member) for member in typing.get_args(annotation)
                 if member is not type(None)]
        if len(found) == 1:
            return found[0]
    return None


def _summary(cls: type | None) -> str:
    """The first sentence of the class's own docstring (not one it inherits)."""
    doc = cls.__dict__.get("__doc__") if cls is not None else None
    if not doc:
        return ""
    paragraph = inspect.cleandoc(doc).split("\n\n")[0].replace("\n", " ")
    return paragraph.split(". ")[0].removesuffix(".") + "."


def _metadata(annotation: Any) -> list[Any]:
    if typing.get_origin(annotation) is Annotated:
        return list(typing.get_args(annotation)[1:])
    return []


def _bounds(metadata: list[Any]) -> dict[str, Any]:
    """The ``ge``/``gt``/``le``/``lt`` of a field's metadata (``Field(...)`` or annotated-types
    constraints, nested ``FieldInfo``s included)."""
    found: dict[str, Any] = {}
    for meta in metadata:
        nested = getattr(meta, "metadata", None)
        if isinstance(nested, list):
            found.update(_bounds(nested))
        for key, _ in BOUNDS:
            value = getattr(meta, key, None)
            if value is not None:
                found[key] = value
    return found


def _item_types(annotation: Any) -> list[Any]:
    """The item types of a tuple or list field (``[]`` for anything else)."""
    if typing.get_origin(annotation) is Annotated:
        annotation = typing.get_args(annotation)[0]
    if typing.get_origin(annotation) in (tuple, list):
        return [a for a in typing.get_args(annotation) if a is not Ellipsis]
    return []


def _default(field: Any) -> Any:
    if field.default is not PydanticUndefined:
        return field.default
    try:
        return field.get_default(call_default_factory=True, validated_data={})
    except Exception:  # noqa: BLE001 - a factory that needs other fields: none to show
        return None


def _jsonable(value: Any) -> Any:
    try:
        return to_jsonable_python(value)
    except Exception:  # noqa: BLE001 - a plugin's own default type: shown as text
        return str(value)


def _value_text(value: Any) -> str:
    return json.dumps(_jsonable(value))
