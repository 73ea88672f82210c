"""``deferred params``: every registered type's parameters with their type, default, range,
choices and description, whole when piped, as JSON with ``--json``; a kind or name it does not
know is one line naming the choices and the closest one."""

from __future__ import annotations

import json

import pytest
from pydantic_core import PydanticUndefined

from deferred.cli import main
from deferred.interfaces import registry
from deferred.interfaces.catalogue import KINDS, type_text


def run(capsys, *args):
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_every_kind_and_type_is_listed_with_its_parameters(capsys):
    code, out, err = run(capsys, "params")
    assert code == 0, err
    for kind, reg in KINDS.items():
        for name, cls in reg.items():
            assert f"\n{kind} {name}  (" in f"\n{out}", (kind, name)
            fields = () if kind == "shading_model" else cls.Params.model_fields
            for field in fields:
                assert f"\n  {field} " in out, (name, field)


def test_piped_lines_are_whole_however_long(capsys):
    """At 80 columns rich cut cells and dropped the descriptions: piped, nothing is cut."""
    code, out, _ = run(capsys, "params", "material", "shell_fur")
    assert code == 0
    lines = out.splitlines()
    fields = registry.materials.get("shell_fur").Params.model_fields
    for name, field in fields.items():
        line = next(line for line in lines if line.startswith(f"  {name} "))
        assert line.endswith(field.description), line  # the whole description, last
    assert max(len(line) for line in lines) > 120  # not squeezed to a terminal's width
    assert "…" not in out


def test_a_literal_shows_its_values_and_a_range_its_bounds(capsys):
    code, out, _ = run(capsys, "params", "material", "revie_fur")
    assert code == 0
    pattern = next(line for line in out.splitlines() if line.startswith("  pattern "))
    assert '"fine" | "coarse" | "patchy"' in pattern and "Literal" not in out
    shells = next(line for line in out.splitlines() if line.startswith("  shells "))
    assert shells.split()[1:5] == ["int", "16", ">=", "0,"] and "<= 256" in shells
    albedo = next(line for line in out.splitlines() if line.startswith("  albedo_tip "))
    assert "each >= 0, <= 1" in albedo


def test_json_lists_what_the_models_say(capsys):
    code, out, _ = run(capsys, "params", "--json")
    assert code == 0
    entries = json.loads(out)
    listed = {(e["kind"], e["name"]) for e in entries}
    assert listed == {(kind, name) for kind, reg in KINDS.items() for name in reg}
    for entry in entries:
        if entry["kind"] == "shading_model":
            assert entry["params"] == [] and isinstance(entry["materials"], list)
            continue
        model = KINDS[entry["kind"]].get(entry["name"]).Params
        assert [row["name"] for row in entry["params"]] == list(model.model_fields)
        for row in entry["params"]:
            field = model.model_fields[row["name"]]
            assert row["required"] == (field.default is PydanticUndefined and
                                       field.default_factory is None)
            if not row["required"]:  # the default, as JSON
                assert row["default"] == json.loads(json.dumps(
                    list(field.default) if isinstance(field.default, tuple)
                    else field.default))
            assert row["description"] == (field.description or "")
            assert row["type"] == type_text(field.annotation)
    standard = next(e for e in entries if e["name"] == "standard")
    exponent = next(r for r in standard["params"] if r["name"] == "specular_exponent")
    assert exponent["range"] == {"ge": 1.0, "le": 2048.0} and exponent["each"] is False
    glass = next(e for e in entries if e["name"] == "stipple_glass")
    assert next(r for r in glass["params"] if r["name"] == "pattern")["choices"] == [2, 4]
    fur = next(e for e in entries if e["name"] == "revie_fur")
    assert next(r for r in fur["params"] if r["name"] == "pattern")["choices"] == \
        ["fine", "coarse", "patchy"]


@pytest.mark.parametrize("args, listed", [
    (["light", "point"], [("light", "point")]),
    (["lights", "point"], [("light", "point")]),
    (["effect"], [("effect", name) for name in registry.effects]),
    (["shading-model"], [("shading_model", name) for name in registry.shading_models]),
    (["ssao"], [("effect", "ssao")]),  # a type's name alone
])
def test_a_kind_or_a_type_alone(capsys, args, listed):
    code, out, _ = run(capsys, "params", "--json", *args)
    assert code == 0
    assert [(e["kind"], e["name"]) for e in json.loads(out)] == listed


@pytest.mark.parametrize("args, expected", [
    (["lihgt"], "error: unknown kind 'lihgt' (did you mean 'light'? choose from material, "
                "light, effect, shading_model)"),
    (["light", "pointt"],
     "error: NAME: unknown light 'pointt' (did you mean 'point'? choose from "),
    (["material", "velvett"], "error: NAME: unknown material 'velvett' (choose from "),
    (["teapot"], "error: unknown kind 'teapot' (choose from material, light, effect, "
                 "shading_model)"),
])
def test_an_unknown_kind_or_name_is_one_line(capsys, args, expected):
    code, out, err = run(capsys, "params", *args)
    assert code == 2 and out == ""
    assert err.startswith(expected) and len(err.splitlines()) == 1, err


def test_materials_is_params_material(capsys):
    _, listed, _ = run(capsys, "params", "material")
    code, out, _ = run(capsys, "materials")
    assert code == 0 and out == listed


def test_on_a_terminal_the_listing_is_a_table(capsys, monkeypatch):
    monkeypatch.setenv("FORCE_COLOR", "1")
    monkeypatch.setenv("COLUMNS", "200")
    code, out, _ = run(capsys, "params", "light", "spot")
    assert code == 0
    assert "│ outer_angle" in out and "zero beyond, degrees" in out  # rich's table
