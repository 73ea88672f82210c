"""The site's generated pages (docs/hooks.py adds them to the mkdocs build; the tests call the
same functions): the scene file reference from the JSON Schema ``deferred schema`` writes, the
materials gallery from the parameter catalogue ``deferred params`` lists, the command reference
from the commands' own help, and the benchmarks page from benchmarks/README.md. Nothing here is
edited by hand in the built site: a new material, parameter or option shows at the next build."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
MATERIAL_FIGURES = DOCS / "figures" / "materials"
EXAMPLE_PARAMS = 3  # an example sets the required keys and this many more, at their defaults


# -- values and types as the reference writes them -----------------------------------------------
def toml_value(value: Any) -> str:
    """A default as TOML writes it (strings, numbers, booleans and arrays of them)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        pairs = ", ".join(f"{k} = {toml_value(v)}" for k, v in value.items())
        return f"{{ {pairs} }}" if pairs else "{}"
    return json.dumps(value)


def type_name(node: dict[str, Any]) -> str:
    """A property's type in words: ``number``, ``[3 numbers]``, ``"pcf" | "soft"``..."""
    if "$ref" in node:
        return node["$ref"].rsplit("/", 1)[1]
    if "const" in node:
        return json.dumps(node["const"])
    if "enum" in node:
        return " | ".join(json.dumps(v) for v in node["enum"])
    if "anyOf" in node:
        kinds = [type_name(n) for n in node["anyOf"] if n.get("type") != "null"]
        optional = any(n.get("type") == "null" for n in node["anyOf"])
        return " or ".join(kinds) + (" (optional)" if optional else "")
    kind = node.get("type")
    if kind == "array":
        items = node.get("items")
        if isinstance(items, list):
            kinds = {type_name(i) for i in items}
            return f"[{len(items)} {kinds.pop()}s]" if len(kinds) == 1 else \
                "[" + ", ".join(type_name(i) for i in items) + "]"
        return f"array of {type_name(items)}" if isinstance(items, dict) else "array"
    if kind == "object":
        return "table"
    return str(kind or "any")


def value_range(node: dict[str, Any]) -> str:
    """``0 <= x <= 1``, ``> 0``, or of each element of an array; '' where unbounded."""
    parts = []
    for key, sign in (("minimum", ">="), ("exclusiveMinimum", ">"), ("maximum", "<="),
                      ("exclusiveMaximum", "<")):
        if key in node:
            parts.append(f"{sign} {node[key]:g}" if isinstance(node[key], int | float)
                         else f"{sign} {node[key]}")
    if parts:
        return ", ".join(parts)
    items = node.get("items")
    if isinstance(items, list) and items:
        each = value_range(items[0])
        return f"each {each}" if each else ""
    if isinstance(items, dict):
        each = value_range(items)
        return f"each {each}" if each else ""
    for option in node.get("anyOf", []):
        found = value_range(option)
        if found:
            return found
    return ""


ROLE = re.compile(r":(?:class|func|meth|mod|attr|data|exc|obj):`~?([^`]+)`")


def plain(text: str) -> str:
    """A docstring's reStructuredText as Markdown: roles and double backticks as code."""
    return ROLE.sub(r"`\1`", text or "").replace("``", "`")


def _cell(text: str) -> str:
    return plain(text).replace("|", "\\|").replace("\n", " ")


def _table_type(node: dict[str, Any]) -> str:
    """A key's type, a table of its own named as the section below that lists it."""
    items = node.get("items")
    if "$ref" in node:
        return "table (its section below)"
    if node.get("type") == "array" and isinstance(items, dict) and "$ref" in items:
        return "array of tables (its section below)"
    return type_name(node)


def property_table(definition: dict[str, Any], skip: tuple[str, ...] = ()) -> list[str]:
    """A Markdown table of a table's keys: key, type, default, range, description."""
    required = set(definition.get("required", []))
    rows = ["| key | type | default | range | description |", "|---|---|---|---|---|"]
    for name, node in definition.get("properties", {}).items():
        if name in skip:
            continue
        default = "required" if name in required else \
            ("" if node.get("default") is None else f"`{toml_value(node['default'])}`")
        rows.append(f"| `{name}` | {_cell(_table_type(node))} | {_cell(default)} | "
                    f"{_cell(value_range(node))} | {_cell(node.get('description', ''))} |")
    return rows if len(rows) > 2 else ["(no keys)"]


def _example_value(name: str, node: dict[str, Any]) -> Any:
    """A value for a required key without a default: its first choice, or one of its type."""
    if "enum" in node:
        return node["enum"][0]
    kind = node.get("type")
    return {"number": 1.0, "integer": 1, "boolean": False, "object": {}}.get(kind, f"my_{name}")


def example_keys(definition: dict[str, Any], skip: tuple[str, ...] = ()) -> list[str]:
    """``key = value`` lines for an example: the required keys (their first choice) and the
    first few with defaults, at their defaults."""
    lines, extra = [], 0
    required = set(definition.get("required", []))
    for name, node in definition.get("properties", {}).items():
        if name in skip:
            continue
        if name in required and "const" in node:
            lines.append(f"{name} = {toml_value(node['const'])}")
        elif name in required:
            lines.append(f"{name} = {toml_value(_example_value(name, node))}")
        elif node.get("default") is not None and extra < EXAMPLE_PARAMS:
            lines.append(f"{name} = {toml_value(node['default'])}")
            extra += 1
    return lines


# -- the scene file reference --------------------------------------------------------------------
def _definition(schema: dict[str, Any], node: dict[str, Any]) -> dict[str, Any]:
    node = node.get("items", node) if node.get("type") == "array" and \
        isinstance(node.get("items"), dict) else node
    if "$ref" in node:
        return schema["definitions"][node["$ref"].rsplit("/", 1)[1]]
    return node


def _typed(schema: dict[str, Any], kind: str) -> list[tuple[str, dict[str, Any]]]:
    names = schema["definitions"][kind]["properties"]["type"]["enum"]
    return [(name, schema["definitions"][f"{kind}.{name}"]) for name in names]


def _material_params(schema: dict[str, Any]) -> list[tuple[str, dict[str, Any]]]:
    objects = schema["definitions"]["ObjectModel"]
    found = []
    for branch in objects.get("allOf", []):
        name = branch["if"]["properties"]["material"]["const"]
        ref = branch["then"]["properties"]["params"]["$ref"]
        found.append((name, schema["definitions"][ref.rsplit("/", 1)[1]]))
    return found


def scene_reference(schema: dict[str, Any]) -> str:
    """The scene file reference: every table and type of ``schema`` (``deferred schema``'s),
    each key's type, default, range and description, and an example of each type."""
    out = ["# Scene file reference", "",
           "Generated from the JSON Schema that `deferred schema` writes, for the materials, "
           "lights and effects registered where the site was built (plugins add theirs). "
           "Every key of every table, its type, default, range and description; each type with "
           "an example that loads (tested). The [scene files guide](scene-files.md) explains "
           "them with longer examples; `deferred params KIND NAME` prints the same "
           "parameters.", "", "## The file's top level", "",
           *property_table(schema), ""]
    tables = [("camera", "[camera]"), ("shadows", "[shadows]"), ("ssao", "[ssao]"),
              ("group", "[[group]]"), ("event", "[[event]]")]
    for key, header in tables:
        node = schema["properties"].get(key)
        if node is None:
            continue
        definition = _definition(schema, node)
        out += [f"## `{header}`", "",
                plain(definition.get("description", node.get("description", ""))),
                "", *property_table(definition), "", "```toml", header,
                *example_keys(definition, skip=("parent",)), "```", ""]
    objects = schema["definitions"]["ObjectModel"]
    out += ["## `[[object]]`", "", plain(objects.get("description", "")), "",
            *property_table(objects), "",
            "Its `params` are the material's: one section per material below.", ""]
    for name, params in _material_params(schema):
        out += [f"### `material = \"{name}\"`", "", plain(params.get("description", "")), "",
                *property_table(params), "", "```toml", "[[object]]",
                'mesh = "builtin:sphere"', f'material = "{name}"', "[object.params]",
                *example_keys(params), "```", ""]
    for kind, header in (("light", "[[light]]"), ("effect", "[[effect]]")):
        out += [f"## `{header}`", "",
                schema["definitions"][kind]["properties"]["type"].get("description", ""), ""]
        for name, params in _typed(schema, kind):
            out += [f"### `type = \"{name}\"`", "", plain(params.get("description", "")), "",
                    *property_table(params), "", "```toml", header,
                    *example_keys(params, skip=("name", "parent")), "```", ""]
    tracks = _definition(schema, schema["properties"]["track"])
    out += ["## `[[track]]`", "", plain(tracks.get("description", "")), "",
            *property_table(tracks), ""]
    for branch in tracks.get("allOf", []):
        pattern = branch["if"]["properties"]["target"]["pattern"]
        ref = branch["then"]["properties"]["keys"]["items"]["$ref"].rsplit("/", 1)[1]
        target = {"^camera$": "camera", "^object:": "object:NAME",
                  "^light:": "light:NAME or light:INDEX"}.get(pattern, pattern)
        out += [f"### keys of `target = \"{target}\"`", "",
                *property_table(schema["definitions"][ref]), ""]
    shown = {"CameraTable", "ShadowsModel", "SSAOParams", "GroupModel", "EventModel",
             "ObjectModel", "TrackModel", "light", "effect",
             *(n.rsplit("/", 1)[1] for n in re.findall(r'"\$ref": "([^"]+)"',
                                                       json.dumps(tracks)))}
    shown |= {name for name in schema["definitions"] if name.startswith(("light.", "effect."))}
    shown |= {params.get("title", "") for _, params in _material_params(schema)}
    referenced = set(re.findall(r'"#/definitions/([^"]+)"', json.dumps(schema)))
    nested = sorted(referenced - shown)
    if nested:
        out += ["## Tables and values inside others", "",
                "The types the tables above name for some of their keys.", ""]
    for name in nested:
        definition = schema["definitions"][name]
        out += [f"### {name}", "", plain(definition.get("description", "")), ""]
        if "enum" in definition:
            out += ["One of " + ", ".join(f"`{toml_value(v)}`" for v in definition["enum"]),
                    ""]
        else:
            out += [*property_table(definition), ""]
    return "\n".join(out).rstrip() + "\n"


def reference_examples(schema: dict[str, Any]) -> list[str]:
    """The reference's TOML examples, as written on the page."""
    return re.findall(r"```toml\n(.*?)```", scene_reference(schema), re.S)


# -- the materials gallery -----------------------------------------------------------------------
def materials_gallery(entries: list[dict[str, Any]]) -> str:
    """Each material of ``entries`` (``deferred params material --json``): its figure
    (docs/material_figures.py), summary, shading model and parameters."""
    out = ["# Materials gallery", "",
           "Every registered material on the same scene (a ball over a floor, a key light, a "
           "fill and an ambient, deferred, 320x200), rendered by "
           "`python docs/material_figures.py`, and its parameters as "
           "`deferred params material NAME` lists them. The papers' pages show the materials "
           "at work.", ""]
    for entry in entries:
        name = entry["name"]
        out += [f"## {name}", ""]
        if (MATERIAL_FIGURES / f"{name}.png").is_file():
            out += [f"![{name} on the gallery's ball](../figures/materials/{name}.png)", ""]
        else:
            out += [f"(No figure yet: `python docs/material_figures.py {name}` renders it.)", ""]
        if entry.get("summary"):
            out += [plain(entry["summary"]), ""]
        out += [f"Shading model: `{entry.get('shading_model')}`; Python: "
                f"`{entry.get('module')}`.", "",
                "| parameter | type | default | range | description |", "|---|---|---|---|---|"]
        for p in entry["params"]:
            signs = {"ge": ">=", "gt": ">", "le": "<=", "lt": "<"}
            bounds = ", ".join(f"{signs.get(k, k)} {v:g}" for k, v in p["range"].items()
                               if isinstance(v, int | float))
            if p.get("choices"):
                bounds = " | ".join(map(str, p["choices"]))
            default = "required" if p["required"] else \
                ("" if p["default"] is None else f"`{toml_value(p['default'])}`")
            out.append(f"| `{p['name']}` | {_cell(str(p['type']))} | {_cell(default)} | "
                       f"{_cell(bounds)} | {_cell(p.get('description') or '')} |")
        out.append("")
    return "\n".join(out).rstrip() + "\n"


# -- the command reference -----------------------------------------------------------------------
def command_reference() -> str:
    """``deferred COMMAND --help`` of every command, as the command line prints it."""
    import click

    from deferred.cli import cli

    out = ["# Command reference", "",
           "Each command's `--help`, generated from the commands themselves. The guide pages "
           "explain them with examples.", ""]
    for name, command in cli.commands.items():
        with click.Context(command, info_name=f"deferred {name}", terminal_width=100,
                           max_content_width=100) as context:
            text = command.get_help(context)
        out += [f"## deferred {name}", "", "```text", text.rstrip(), "```", ""]
    return "\n".join(out).rstrip() + "\n"


# -- benchmarks/README.md as a page --------------------------------------------------------------
LINK = re.compile(r"(!?)\[((?:[^\]\[]|\[[^\]]*\])*)\]\(([^)\s]+)\)", re.S)


def site_links(text: str, page_dir: Path, site_files: set[str], site_page_dir: str) -> str:
    """Links of a Markdown file from ``page_dir`` (in the repository) placed in the site at
    ``site_page_dir``: those reaching a site file are kept, others become their text (and
    the file's path), as the site has no copy of the repository's other files."""
    import posixpath

    def sub(match: re.Match) -> str:
        bang, label, target = match.groups()
        if re.match(r"^(https?:|mailto:|#)", target):
            return match.group(0)
        path, _, anchor = target.partition("#")
        in_site = posixpath.normpath(posixpath.join(site_page_dir, path))
        if in_site in site_files:
            return match.group(0)
        repo = (page_dir / path).resolve()
        named = repo.relative_to(ROOT).as_posix() if repo.is_relative_to(ROOT) else path
        return label if label.strip("`") == named else f"{label} (`{named}`)"

    return LINK.sub(sub, text)
