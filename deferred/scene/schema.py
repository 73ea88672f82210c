"""A JSON Schema of scene files, for editors (Taplo, VS Code's Even Better TOML): completion,
descriptions and checks as a scene is written. ``deferred schema`` writes it.

It is built from the scene model (:class:`~deferred.scene.loader.SceneModel`) and the registries
(plugins included): each ``[[object]]``'s ``material`` selects its ``params`` model, each
``[[light]]``'s and ``[[effect]]``'s ``type`` its parameters, through ``if``/``then`` on a
``const`` (an editor's message names the one type that failed, not every alternative); each
``[[track]]``'s ``target`` (camera, ``object:``, ``light:``) its keys' properties. Keys the
loader refuses are refused here too (``additionalProperties: false``). The loader stays the
authority: what a schema cannot say (a file that must exist, checks across keys, an event's
parameters, which depend on its object's material) it checks when the scene loads.

JSON Schema draft-07, which editors' TOML support reads (tuples as ``items`` arrays).
"""

from __future__ import annotations

import copy
import warnings
from typing import Any

from pydantic import BaseModel
from pydantic.json_schema import GenerateJsonSchema, models_json_schema

from deferred.interfaces import registry
from deferred.scene.tables import ObjectModel, SceneModel
from deferred.scene.tracks import KEY_MODELS

DRAFT = "http://json-schema.org/draft-07/schema#"
DEFAULT_MATERIAL = ObjectModel.model_fields["material"].default


class _Generator(GenerateJsonSchema):
    """Pydantic's generator; a type with no JSON form (a plugin's own validator) is any
    value, not an error: the loader checks it."""

    def handle_invalid_for_json_schema(self, schema: Any, error_info: str) -> dict[str, Any]:
        return {}


class _Definitions:
    """Pydantic's JSON Schema of the scene model and of every registered type's parameters:
    the definitions by name, and each model's reference among them."""

    def __init__(self, models: list[type[BaseModel]]):
        with warnings.catch_warnings():  # a default with no JSON form is left out, said here
            warnings.simplefilter("ignore")
            self.refs, top = models_json_schema([(model, "validation") for model in models],
                                                ref_template="#/definitions/{model}",
                                                schema_generator=_Generator)
        self.by_name: dict[str, Any] = top.get("$defs", {})

    def ref(self, model: type[BaseModel]) -> str:
        return self.refs[(model, "validation")]["$ref"]

    def of(self, model: type[BaseModel]) -> dict[str, Any]:
        return self.by_name[self.ref(model).rsplit("/", 1)[1]]

    def of_items(self, table: dict[str, Any]) -> dict[str, Any]:
        """The definition of an array of tables' items (``[[object]]``, ``[[track]]``)."""
        return self.by_name[table["items"]["$ref"].rsplit("/", 1)[1]]


def scene_schema() -> dict[str, Any]:
    """The JSON Schema (draft-07) of a scene file, for every registered material, light and
    effect."""
    kinds = {"material": registry.materials.items(), "light": registry.lights.items(),
             "effect": registry.effects.items()}
    models: list[type[BaseModel]] = [SceneModel, *KEY_MODELS.values()]
    for types in kinds.values():
        for _, cls in types:
            if cls.Params not in models:
                models.append(cls.Params)
    definitions = _Definitions(models)
    root = definitions.by_name.pop(definitions.ref(SceneModel).rsplit("/", 1)[1])
    properties = root["properties"]
    _object_materials(definitions, properties, kinds["material"])
    typed = properties["light"]["items"]["$ref"].rsplit("/", 1)[1]
    for kind in ("light", "effect"):
        _typed_tables(definitions, properties, kind, kinds[kind])
    definitions.by_name.pop(typed, None)
    ssao = dict(kinds["effect"]).get("ssao")
    if ssao is not None:  # the [ssao] table: the ssao effect's parameters
        properties["ssao"] = {"$ref": definitions.ref(ssao.Params),
                              "description": properties["ssao"].get("description", "")}
    events = definitions.of_items(properties["event"])
    events["properties"]["params"] = {
        "type": "object",
        "description": "parameters of the object's material, merged over the object's"}
    _track_keys(definitions, properties)
    schema = {"$schema": DRAFT, "title": "deferred scene file",
              "description": "A scene for deferred (TOML); written by `deferred schema` for the "
                             "materials, lights and effects registered where it ran.",
              **root, "definitions": definitions.by_name}
    return _draft_07(schema)


def _object_materials(definitions: _Definitions, properties: dict[str, Any],
                      materials: list[tuple[str, Any]]) -> None:
    """[[object]]: the material names, and each material's params."""
    objects = definitions.of_items(properties["object"])
    names = [name for name, _ in materials]
    objects["properties"]["material"] = {
        "enum": names, "default": DEFAULT_MATERIAL,
        "description": "the material (deferred params material lists them)"}
    objects["properties"]["params"] = {
        "type": "object", "description": "the material's parameters"}
    objects["allOf"] = [
        {"if": {"properties": {"material": {"const": name}},
                **({} if name == DEFAULT_MATERIAL else {"required": ["material"]})},
         "then": {"properties": {"params": {"$ref": definitions.ref(cls.Params)}}}}
        for name, cls in materials]


def _typed_tables(definitions: _Definitions, properties: dict[str, Any], kind: str,
                  types: list[tuple[str, Any]]) -> None:
    """[[light]] or [[effect]]: the type names, and each type's parameters beside it."""
    names = [name for name, _ in types]
    branches = []
    for name, cls in types:
        params = copy.deepcopy(definitions.of(cls.Params))
        params["properties"] = {"type": {"const": name}, **params.get("properties", {})}
        if kind == "light":  # what tracks may call it (light:NAME)
            params["properties"]["name"] = {
                "type": "string", "minLength": 1, "pattern": "^.*[^0-9].*$",
                "description": "a name for tracks (target = 'light:NAME'); not a number"}
            params["properties"]["parent"] = {
                "type": "string", "minLength": 1,
                "description": "the name of an object or group its position and "
                               "direction are in"}
        params["required"] = ["type", *params.get("required", [])]
        params["additionalProperties"] = False
        definitions.by_name[f"{kind}.{name}"] = params
        branches.append({"if": {"properties": {"type": {"const": name}},
                                "required": ["type"]},
                         "then": {"$ref": f"#/definitions/{kind}.{name}"}})
    definitions.by_name[kind] = {
        "type": "object", "required": ["type"],
        "properties": {"type": {"enum": names,
                                "description": f"the {kind} type (deferred params "
                                               f"{kind} lists them)"}},
        "allOf": branches}
    properties[kind]["items"] = {"$ref": f"#/definitions/{kind}"}


def _track_keys(definitions: _Definitions, properties: dict[str, Any]) -> None:
    """[[track]]: the target's form, and its kind's key properties."""
    tracks = definitions.of_items(properties["track"])
    tracks["properties"]["target"]["pattern"] = "^(camera|object:.+|light:.+)$"
    tracks["properties"]["keys"]["items"] = {"type": "object", "required": ["time"]}
    tracks["allOf"] = [
        {"if": {"properties": {"target": {"pattern": pattern}}, "required": ["target"]},
         "then": {"properties": {"keys": {"items": {"$ref": definitions.ref(KEY_MODELS[kind])}}}}}
        for kind, pattern in (("camera", "^camera$"), ("object", "^object:"),
                              ("light", "^light:"))]


def _draft_07(node: Any) -> Any:
    """Pydantic's draft 2020-12 tuples (``prefixItems``) as draft-07's ``items`` arrays."""
    if isinstance(node, list):
        return [_draft_07(item) for item in node]
    if not isinstance(node, dict):
        return node
    out = {key: _draft_07(value) for key, value in node.items()}
    if "prefixItems" in out:
        out["items"] = out.pop("prefixItems")
        out.setdefault("additionalItems", False)
    return out
