"""Scene files for editors and people: the JSON Schema ``deferred schema`` writes accepts every
scene the project ships and refuses the typos the loader refuses; a scene's problems are all
reported at once, each on its line, with the closest known name for an unknown one."""

from __future__ import annotations

import json
import sys
from importlib import resources

import jsonschema
import pytest
from locations import ROOT

from deferred.cli import main
from deferred.cli.exits import MAX_PROBLEM_LINES
from deferred.errors import InputError, InputErrors
from deferred.interfaces import registry
from deferred.scene.loader import builtin_scenes, scene_from_dict, scene_from_toml
from deferred.scene.schema import scene_schema

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

PLUGIN = ROOT / "examples" / "plugins" / "deferred-velvet"
# the plugins' scenes name types only their packages register
EXAMPLES = sorted(path for path in (ROOT / "examples").rglob("*.toml")
                  if path.name != "pyproject.toml" and PLUGIN.parent not in path.parents)


@pytest.fixture(scope="module")
def validator():
    schema = scene_schema()
    jsonschema.Draft7Validator.check_schema(schema)
    return jsonschema.Draft7Validator(schema)


def errors(validator, scene: dict) -> list[str]:
    return [f"{'/'.join(map(str, e.absolute_path))}: {e.message}"
            for e in validator.iter_errors(scene)]


def builtin(name: str) -> dict:
    return tomllib.loads(resources.files("deferred").joinpath("scenes", f"{name}.toml")
                         .read_text("utf-8"))


def test_the_examples_are_found():
    names = {path.name for path in EXAMPLES}
    assert {"fig2_21_final.toml", "wet_wind.toml"} <= names and len(EXAMPLES) >= 10


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.name for p in EXAMPLES])
def test_every_example_scene_is_valid(validator, path):
    assert errors(validator, tomllib.loads(path.read_text("utf-8"))) == []


@pytest.mark.parametrize("name", builtin_scenes())
def test_the_builtin_scenes_are_valid(validator, name):
    assert errors(validator, builtin(name)) == []


SCENE = {
    "size": [64, 48],
    "camera": {"position": [0.0, 1.0, 3.0], "target": [0.0, 0.0, 0.0]},
    "object": [{"name": "ball", "mesh": "builtin:sphere", "material": "standard",
                "params": {"specular_exponent": 16.0}},
               {"name": "fur", "mesh": "builtin:torus", "material": "revie_fur",
                "params": {"shells": 4, "pattern": "coarse"}},
               {"name": "floor", "mesh": "builtin:plane", "params": {"color": [0.3, 0.3, 0.3]}}],
    "light": [{"type": "point", "position": [0.0, 2.0, 1.0], "radius": 5.0},
              {"type": "directional", "direction": [0.0, -1.0, 0.0]}],
    "effect": [{"type": "ssao", "radius": 0.3}],
    "event": [{"time": 1.0, "object": "ball", "params": {"specular_intensity": 0.2}}],
}


def edited(path: str, value) -> dict:
    """SCENE with ``path`` (``object.0.params.x``) set to ``value``."""
    scene = json.loads(json.dumps(SCENE))
    *parents, last = [int(p) if p.isdigit() else p for p in path.split(".")]
    node = scene
    for part in parents:
        node = node[part]
    node[last] = value
    return scene


def test_the_scene_of_these_tests_is_valid(validator):
    assert errors(validator, SCENE) == []
    assert len(scene_from_dict(SCENE, "s.toml").objects) == 3


# (what is set, its value, where the schema says it, what the message holds)
TYPOS = [
    ("object.0.params.specular_exponant", 3.0, "object/0/params", "'specular_exponant'"),
    ("light.0.type", "pointt", "light/0/type", "'pointt' is not one of"),
    ("object.1.params.shells", "many", "object/1/params/shells", "not of type 'integer'"),
    ("object.1.params.pattern", "curly", "object/1/params/pattern", "'curly' is not one of"),
    ("object.0.params.shells", 4, "object/0/params", "'shells'"),  # revie_fur's, not standard's
    ("object.2.params.shells", 4, "object/2/params", "'shells'"),  # no material: standard's
    ("object.0.params.color", [2.0, 0.5, 0.5], "object/0/params/color/0", "maximum of 1"),
    ("object.0.params.color", [0.5, 0.5], "object/0/params/color", "too short"),
    ("object.0.material", "chrome", "object/0/material", "'chrome' is not one of"),
    ("object.0.mesh", 3, "object/0/mesh", "not of type 'string'"),
    ("light.1.radius", 5.0, "light/1", "'radius'"),  # a point light's, not a directional's
    ("light.0.radius", -1.0, "light/0/radius", "minimum of 0"),
    ("effect.0.type", "bloom", "effect/0/type", "'bloom' is not one of"),
    ("effect.0.samples", 2.5, "effect/0/samples", "not of type 'integer'"),
    ("camera.zoom", 2.0, "camera", "'zoom'"),
    ("backgroud", [0.0, 0.0, 0.0], "", "'backgroud'"),
    ("tonemap", "filmic", "tonemap", "'filmic' is not one of"),
    ("event.0.when", 1.0, "event/0", "'when'"),
]


@pytest.mark.parametrize("path, value, at, fragment", TYPOS,
                         ids=[f"{path}={value!r}" for path, value, _, _ in TYPOS])
def test_a_typo_is_refused_by_the_schema_and_the_loader(validator, path, value, at, fragment):
    found = errors(validator, edited(path, value))
    assert any(e.startswith(f"{at}: ") and fragment in e for e in found), found
    with pytest.raises(InputError):  # the schema refuses only what the loader refuses
        scene_from_dict(edited(path, value), "s.toml")


def test_the_schema_describes_and_completes(validator):
    schema = validator.schema
    objects = schema["definitions"]["ObjectModel"]
    assert objects["properties"]["material"]["enum"] == list(registry.materials)
    standard = schema["definitions"]["StandardParams"]["properties"]
    assert standard["specular_exponent"]["description"] == "Blinn-Phong exponent"
    assert standard["specular_exponent"]["default"] == 32.0
    point = schema["definitions"]["light.point"]
    assert point["properties"]["type"] == {"const": "point"}
    assert point["additionalProperties"] is False
    assert "prefixItems" not in json.dumps(schema)  # draft-07: tuples as items arrays


@pytest.fixture
def velvet(monkeypatch):
    """The example plugin's classes registered in this process, then removed."""
    monkeypatch.syspath_prepend(str(PLUGIN))
    from deferred_velvet.effect import Vignette
    from deferred_velvet.light import RimLight
    from deferred_velvet.material import VelvetMaterial
    from deferred_velvet.shading import VelvetModel

    added = [(registry.shading_models, VelvetModel), (registry.materials, VelvetMaterial),
             (registry.lights, RimLight), (registry.effects, Vignette)]
    for reg, cls in added:
        reg.register(cls)
    yield
    for reg, cls in added:
        reg.unregister(cls.name)
    for module in [m for m in sys.modules if m.startswith("deferred_velvet")]:
        monkeypatch.delitem(sys.modules, module)


def test_a_plugins_types_are_in_the_schema(velvet):
    plugin_scene = tomllib.loads((PLUGIN / "scene.toml").read_text("utf-8"))
    validator = jsonschema.Draft7Validator(scene_schema())
    assert errors(validator, plugin_scene) == []
    plugin_scene["object"][1]["params"]["sheen_colour"] = [1.0, 1.0, 1.0]
    plugin_scene["light"][1]["power"] = "strong"
    found = errors(validator, plugin_scene)
    assert any("object/1/params" in e and "'sheen_colour'" in e for e in found), found
    assert any(e.startswith("light/1/power: ") for e in found), found


def test_deferred_schema_writes_the_schema(tmp_path, capsys):
    out = tmp_path / "scene.schema.json"
    assert main(["schema", "-o", str(out)]) == 0
    assert json.loads(out.read_text()) == scene_schema()
    assert f"wrote {out}" in capsys.readouterr().err
    assert main(["schema"]) == 0
    assert json.loads(capsys.readouterr().out) == scene_schema()
    assert main(["schema", "-o", str(tmp_path / "scene.schema.txt")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: -o: output must end in .json") and len(err.splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.schema.json"]


# -- every problem at once ---------------------------------------------------------------------

MANY_PROBLEMS = """\
size = [64, 48]
backgroud = [0.0, 0.0, 0.0]
[camera]
fov = 500.0
[[object]]
mesh = "builtin:sphere"
params = { specular_exponant = 3.0, color = [2.0, 0.0, 0.0] }
[[object]]
name = "fur"
mesh = "builtin:torus"
material = "revie_fur"
params = { shells = "many" }
[[object]]
mesh = "nope.obj"
material = "shel_fur"
[[light]]
type = "pointt"
[[light]]
type = "point"
radius = -1.0
intensity = "x"
[[effect]]
type = "ssoa"
[[event]]
time = 1.0
object = "fir"
params = {}
[[event]]
time = 1.0
object = "fur"
params = { shels = 3 }
"""

EXPECTED = [
    "s.toml: backgroud: unknown parameter (did you mean 'background'?)",
    "s.toml: camera.fov: Input should be less than 179 (got 500.0)",
    "s.toml: object[0].params.color[0]: Input should be less than or equal to 1 (got 2.0)",
    "s.toml: object[0].params.specular_exponant: unknown parameter "
    "(did you mean 'specular_exponent'?)",
    "s.toml: object[1].params.shells: expected a number, not a string (got 'many')",
    "s.toml: object[2].material: unknown material 'shel_fur' (did you mean 'shell_fur'? choose "
    "from ",
    "s.toml: object[2].mesh: mesh file not found: nope.obj",
    "s.toml: light[0].type: unknown light 'pointt' (did you mean 'point'? choose from ",
    "s.toml: light[1].intensity: expected a number, not a string (got 'x')",
    "s.toml: light[1].radius: Input should be greater than 0 (got -1.0)",
    "s.toml: effect[0].type: unknown effect 'ssoa' (did you mean 'ssao'? choose from ",
    "s.toml: event[0].object: no object named 'fir' (did you mean 'fur'? objects: sphere0, fur, "
    "nope0)",
    "s.toml: event[1].params.shels: unknown parameter (did you mean 'shells'?)",
]


def test_every_problem_of_a_scene_is_said_at_once_in_the_files_order():
    with pytest.raises(InputErrors) as info:
        scene_from_toml(MANY_PROBLEMS, name="s.toml")
    lines = [str(problem) for problem in info.value.problems]
    assert len(lines) == len(EXPECTED), "\n".join(lines)
    for line, expected in zip(lines, EXPECTED, strict=True):
        assert line.startswith(expected), (line, expected)
    assert str(info.value).splitlines() == lines


def test_the_command_line_says_each_problem_on_its_line(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(MANY_PROBLEMS)
    assert main(["render", "s.toml", "-o", "out.png"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == len(EXPECTED)
    assert all(line.startswith(f"error: {expected}")
               for line, expected in zip(lines, EXPECTED, strict=True)), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_one_problem_is_one_line_and_the_problems_of_one_table_each_a_line(tmp_path, capsys):
    one = dict(SCENE, object=[dict(SCENE["object"][0], params={"specular_exponant": 3.0})])
    with pytest.raises(InputError) as info:
        scene_from_dict(one, "s.toml")
    assert type(info.value) is InputError
    assert str(info.value) == ("s.toml: object[0].params.specular_exponant: unknown parameter "
                               "(did you mean 'specular_exponent'?)")
    two = dict(SCENE, light=[{"type": "spot", "inner_angle": "wide", "outer_angle": 100.0}])
    with pytest.raises(InputErrors) as info:
        scene_from_dict(two, "s.toml")
    assert [p.where for p in info.value.problems] == ["s.toml: light[0].inner_angle",
                                                     "s.toml: light[0].outer_angle"]


def test_a_union_is_one_problem_not_one_per_member():
    scene = dict(SCENE, object=[dict(SCENE["object"][0], scale=[1.0, 2.0])])
    with pytest.raises(InputError) as info:
        scene_from_dict(scene, "s.toml")
    assert str(info.value) == ("s.toml: object[0].scale: expected more than the 2 values given "
                               "(got [1.0, 2.0])")


def test_past_the_most_lines_the_rest_are_counted(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    count = MAX_PROBLEM_LINES + 7
    (tmp_path / "s.toml").write_text("".join(
        f'[[object]]\nmesh = "builtin:sphere"\nparams = {{ specular_intensity = {k + 2} }}\n'
        for k in range(count)))
    assert main(["render", "s.toml", "-o", "out.png"]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == MAX_PROBLEM_LINES + 1
    assert lines[0].startswith("error: s.toml: object[0].params.specular_intensity: ")
    assert lines[-1] == "error: ... and 7 more problems"


def test_a_newline_in_a_problem_stays_on_its_line(capsys):
    problems = InputErrors([InputError("bad\nvalue", "a.toml: x"), InputError("worse", "b")])
    # the error itself is one line, from Python as from the command line
    assert [str(p) for p in problems.problems] == ["a.toml: x: bad\\nvalue", "b: worse"]
    assert str(problems).splitlines() == ["a.toml: x: bad\\nvalue", "b: worse"]
    from deferred.cli.exits import fail
    fail(*(f"error: {p}" for p in problems.problems))
    assert capsys.readouterr().err.splitlines() == ["error: a.toml: x: bad\\nvalue",
                                                    "error: b: worse"]


def test_each_event_of_a_timeline_says_its_problems():
    scene = dict(SCENE, event=[
        {"time": 1.0, "object": "ball", "params": {"specular_intensty": 0.2}},
        {"time": 2.0, "object": "ball", "params": {"specular_intensity": 5.0}},
        {"time": 2.0, "object": "fur", "params": {"shells": 2, "colour": [1.0, 1.0, 1.0]}}])
    with pytest.raises(InputErrors) as info:
        scene_from_dict(scene, "s.toml")
    assert [str(p) for p in info.value.problems] == [
        "s.toml: event[0].params.specular_intensty: unknown parameter "
        "(did you mean 'specular_intensity'?)",
        "s.toml: event[1].params.specular_intensity: Input should be less than or equal to 1 "
        "(got 5.0)",
        "s.toml: event[2].params.colour: unknown parameter"]


def test_python_from_dict_says_every_problem_too():
    material = registry.materials.get("standard")
    with pytest.raises(InputErrors) as info:
        material.from_dict({"colour": [1.0, 1.0, 1.0], "specular_exponent": 0.0}, None, "ball")
    assert [str(p) for p in info.value.problems] == [
        "ball: specular_exponent: Input should be greater than or equal to 1 (got 0.0)",
        "ball: colour: unknown parameter (did you mean 'color'?)"]
