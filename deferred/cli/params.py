"""``deferred params`` and ``deferred materials``: the registered types and their parameters
(the data is :mod:`deferred.interfaces.catalogue`'s), as JSON, as a table per type on a
terminal, or as plain lines at full width to a pipe or a file."""

from __future__ import annotations

import json
from typing import Any

import click
from rich.console import Console
from rich.table import Table

from deferred.interfaces.catalogue import BOUNDS, catalogue

JSON_HELP = "The listing as JSON on stdout."
COLUMNS = ("parameter", "type", "default", "range", "description")


@click.command("params")
@click.argument("kind", required=False)
@click.argument("name", required=False)
@click.option("--json", "as_json", is_flag=True, help=JSON_HELP)
def params_command(kind: str | None, name: str | None, as_json: bool) -> None:
    """List the parameters of every registered type: name, type, default, range, choices and
    description. KIND is material, light, effect or shading_model; NAME one type of it
    (`deferred params light point`). Plugins are listed too."""
    print_params(catalogue(kind, name), as_json)


@click.command()
@click.option("--json", "as_json", is_flag=True, help=JSON_HELP)
def materials(as_json: bool) -> None:
    """List registered materials and their parameters (`deferred params material`)."""
    print_params(catalogue("material"), as_json)


def print_params(entries: list[dict[str, Any]], as_json: bool) -> None:
    """A rich table per type on a terminal; plain lines at full width to a pipe or a file
    (a table squeezed to 80 columns cuts cells and drops descriptions)."""
    if as_json:
        click.echo(json.dumps(entries, indent=2))
        return
    console = Console(markup=False, highlight=False)
    if not console.is_terminal:
        click.echo("\n".join(plain_lines(entries)))
        return
    for entry in entries:
        title = heading(entry) + (f"\n{entry['summary']}" if entry["summary"] else "")
        table = Table(title=title, title_justify="left")
        table.add_column(COLUMNS[0], no_wrap=True)
        for column in COLUMNS[1:4]:
            table.add_column(column, overflow="fold")
        table.add_column(COLUMNS[4], ratio=1, overflow="fold")
        for row in entry["params"]:
            table.add_row(*cells(row))
        console.print(table if entry["params"] else f"{title}\n  (no parameters)")
        for line in data_lines(entry):
            console.print(line)


def plain_lines(entries: list[dict[str, Any]]) -> list[str]:
    """The listing as plain text at full width: a heading per type, then one line per
    parameter in aligned columns, the description last and whole (nothing cut, whatever the
    terminal: for pipes and files)."""
    lines: list[str] = []
    for entry in entries:
        if lines:
            lines.append("")
        lines.append(heading(entry))
        if entry["summary"]:
            lines.append(f"  {entry['summary']}")
        if not entry["params"]:
            lines.append("  (no parameters)")
        else:
            rows = [cells(row) for row in entry["params"]]
            widths = [max(len(r[i]) for r in [COLUMNS, *rows]) for i in range(4)]
            for row in [COLUMNS, *rows]:
                aligned = [cell.ljust(width) for cell, width in zip(row[:4], widths,
                                                                     strict=True)]
                lines.append(("  " + "  ".join([*aligned, row[4]])).rstrip())
        lines += data_lines(entry)
    return lines


def data_lines(entry: dict[str, Any]) -> list[str]:
    """A light type's own data (``Light.data``): a line per vec4 after the record's four."""
    data = entry.get("data") or []
    if not data:
        return []
    width = max(len(datum["name"]) for datum in data)
    return ["  record data (a vec4 each, after color, position, direction, extra):",
            *(f"    {datum['name'].ljust(width)}  {datum['description']}" for datum in data)]


def cells(row: dict[str, Any]) -> tuple[str, str, str, str, str]:
    """A parameter's row of the listing, in the order of :data:`COLUMNS`."""
    return row["name"], row["type"], default_text(row), range_text(row), row["description"]


def heading(entry: dict[str, Any]) -> str:
    """``material standard (id 1, shading model blinn_phong, deferred.materials.standard)``."""
    details = [f"id {entry['id']}"] if entry.get("id") else []
    if entry.get("shading_model"):
        details.append(f"shading model {entry['shading_model']}")
    if entry.get("volume"):
        details.append(f"volume {entry['volume']}")
    if entry.get("pipelines") is not None and len(entry["pipelines"]) == 1:
        forward = "; forward with forward = true" if entry.get("reads_gbuffer") else " only"
        details.append(f"{entry['pipelines'][0]} pipeline{forward}")
    if entry.get("glsl_file"):
        details.append(entry["glsl_file"])
    if "materials" in entry:
        details.append(f"used by {', '.join(entry['materials']) or 'no material'}")
    details.append(entry["module"])
    return f"{entry['kind']} {entry['name']}  ({', '.join(details)})"


def range_text(row: dict[str, Any]) -> str:
    """``>= 0, <= 1`` (``each >= 0, <= 1`` for every item of a list)."""
    text = ", ".join(f"{symbol} {_number(row['range'][key])}" for key, symbol in BOUNDS
                     if key in row["range"])
    return f"each {text}" if text and row["each"] else text


def default_text(row: dict[str, Any]) -> str:
    """The default as a scene file writes it (``[0.8, 0.8, 0.8]``, ``"aces"``, ``true``);
    ``required`` where there is none, ``none`` for ``None`` (leave the key out)."""
    if row["required"]:
        return "required"
    if row["default"] is None:
        return "none"
    return json.dumps(row["default"])


def _number(value: Any) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)
