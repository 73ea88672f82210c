"""Issue #11, scene values: every non-finite, out-of-range or mistyped value in a scene file is
refused with exit 2 and one line naming the file and key, before any output is touched.

Each case edits one value of a small good scene (written as TOML, where ``nan`` and ``inf`` are
literals); the test renders it through the CLI over an existing output file and checks the exit
code, the line, that there is no traceback, and that the output and the folder are unchanged.
"""

from __future__ import annotations

import copy
import math

import pytest

from deferred.cli import main

GOOD = {
    "size": [48, 32],
    "exposure": 1.0,
    "background": [0.02, 0.02, 0.03],
    "camera": {"position": [0.0, 1.0, 3.0], "target": [0.0, 0.0, 0.0], "fov": 45.0},
    "object": [
        {"name": "ball", "mesh": "builtin:sphere", "material": "standard",
         "position": [0.0, 0.0, 0.0], "params": {"color": [0.8, 0.5, 0.3]}},
        {"name": "fur", "mesh": "builtin:torus", "material": "revie_fur",
         "position": [1.0, 0.0, 0.0], "params": {"shells": 4}},
        {"name": "shell", "mesh": "builtin:sphere", "material": "shell_fur",
         "position": [-1.0, 0.0, 0.0], "params": {"shells": 4}},
    ],
    "light": [
        {"type": "ambient", "color": [0.1, 0.1, 0.1], "ground": [0.05, 0.04, 0.03]},
        {"type": "directional", "direction": [-0.5, -1.0, -0.3], "intensity": 1.0},
        {"type": "point", "position": [0.5, 1.0, 1.0], "radius": 4.0, "intensity": 3.0},
        {"type": "spot", "position": [0.0, 2.0, 1.0], "direction": [0.0, -1.0, -0.2],
         "outer_angle": 30.0},
    ],
    "effect": [{"type": "ssao", "radius": 0.3}],
    "event": [{"time": 0.5, "object": "ball", "params": {"specular_intensity": 0.2}}],
}


def toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, int | float):
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace('"', '\\"') + '"'
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {toml_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(value)


def toml_document(scene: dict) -> str:
    """The scene as TOML: plain keys, then tables, then arrays of tables (inline sub-tables)."""
    lines = [f"{k} = {toml_value(v)}" for k, v in scene.items()
             if not isinstance(v, dict | list) or (isinstance(v, list) and
                                                     not any(isinstance(i, dict) for i in v))]
    for key, value in scene.items():
        if isinstance(value, dict):
            lines += [f"[{key}]", *(f"{k} = {toml_value(v)}" for k, v in value.items())]
        elif isinstance(value, list) and any(isinstance(i, dict) for i in value):
            for item in value:
                lines += [f"[[{key}]]", *(f"{k} = {toml_value(v)}" for k, v in item.items())]
    return "\n".join(lines) + "\n"


NAN, INF = float("nan"), float("inf")


def set_key(path: str, value):
    """An edit setting ``path`` (``object[0].params.color``) to ``value``."""
    def edit(scene: dict) -> dict:
        scene = copy.deepcopy(scene)
        parts = path.replace("[", ".").replace("]", "").split(".")
        node = scene
        for part in parts[:-1]:
            node = node[int(part)] if part.isdigit() else node[part]
        last = parts[-1]
        node[int(last) if last.isdigit() else last] = value
        return scene
    return edit


# Checks across keys name the table they belong to.
NAMED_BY_TABLE = {"camera.up": "camera", "camera.far": "camera", "object[0].scale": "object[0]"}

# (key, value, fragment of the message after "s.toml: <key>")
CASES = [
    ("size", [True, 32], "expected a number, not true or false"),
    ("size", ["48", 32], "expected a number, not a string"),
    ("size", [0, 32], "impossible"),
    ("size", [20000, 32], "impossible"),
    ("size", [16384, 16384], "GiB of render targets"),
    ("exposure", NAN, "finite"),
    ("exposure", INF, "finite"),
    ("exposure", -1.0, "greater than 0"),
    ("exposure", 1e300, "within"),
    ("exposure", True, "expected a number"),
    ("background", [NAN, 0.0, 0.0], "finite"),
    ("background", [-1.0, 0.0, 0.0], "greater than or equal to 0"),
    ("background", [INF, 0.0, 0.0], "finite"),
    ("background", [0.1, 0.1], "expected more than the 2 values given"),
    ("tonemap", 3, "expected one of 'reinhard', 'aces', 'none'"),
    ("light_path", "warp", "expected one of"),
    ("light[0].type", 3, "expected a string (got 3)"),  # not the whole list of tables
    ("camera.position", [NAN, 0.0, 0.0], "finite"),
    ("camera.position", ["1", 0.0, 0.0], "expected a number, not a string"),
    ("camera.target", [0.0, INF, 0.0], "finite"),
    ("camera.up", [0.0, 0.0, 0.0], "up is parallel"),
    ("camera.fov", NAN, "finite"),
    ("camera.fov", INF, "finite"),
    ("camera.fov", 0.0, "greater than 1"),
    ("camera.near", NAN, "finite"),
    ("camera.far", INF, "finite"),
    ("camera.far", 0.01, "far must be greater than near"),
    ("object[0].position", [NAN, 0.0, 0.0], "finite"),
    ("object[0].position", [1e20, 0.0, 0.0], "within"),
    ("object[0].rotation", [0.0, INF, 0.0], "finite"),
    ("object[0].scale", NAN, "finite"),
    ("object[0].scale", 0.0, "scale must not be zero"),
    ("object[0].scale", 1e-300, "scale must be at least 1e-06 in size"),
    ("object[0].scale", [1.0, -1e-9, 1.0], "scale must be at least 1e-06 in size"),
    ("object[0].scale", [1.0, INF, 1.0], "finite"),
    ("object[0].scale", True, "expected a number"),
    ("object[0].material", "chrome", "chrome"),
    ("object[0].params.color", [NAN, 0.5, 0.5], "finite"),
    ("object[0].params.color", [2.0, 0.5, 0.5], "less than or equal to 1"),
    ("object[0].params.color", [-0.1, 0.5, 0.5], "greater than or equal to 0"),
    ("object[0].params.specular_exponent", INF, "finite"),
    ("object[0].params.specular_intensity", "high", "expected a number, not a string"),
    ("object[0].params.shininess", 3.0, "unknown parameter"),
    ("object[1].params.shells", True, "expected a number, not true or false"),
    ("object[1].params.shells", 2.5, "integer"),
    ("object[1].params.shells", 1e12, "within"),
    ("object[1].params.albedo_tip", [0.5, NAN, 0.5], "finite"),
    ("object[2].params.wind", [INF, 0.0, 0.0], "finite"),
    ("object[2].params.curl_radius", NAN, "finite"),
    ("object[2].params.fins", 1, "expected true or false"),
    ("object[2].params.droplets", -1, "greater than or equal to 0"),
    ("object[2].params.color", [1.5, 0.2, 0.1], "less than or equal to 1"),
    ("light[0].color", [0.1, INF, 0.1], "finite"),
    ("light[0].ground", [-0.1, 0.0, 0.0], "greater than or equal to 0"),
    ("light[1].direction", [0.0, 0.0, 0.0], "zero vector"),
    ("light[1].direction", [0.0, -1e-300, 0.0], "too short to give a direction"),
    ("object[1].params.comb", [0.0, 1e-300, 0.0], "too short to give a direction"),
    ("light[1].direction", [NAN, -1.0, 0.0], "finite"),
    ("light[1].intensity", "bright", "expected a number, not a string"),
    ("light[2].intensity", NAN, "finite"),
    ("light[2].intensity", INF, "finite"),
    ("light[2].position", [0.0, NAN, 0.0], "finite"),
    ("light[2].radius", NAN, "finite"),
    ("light[2].color", [-1.0, 1.0, 1.0], "greater than or equal to 0"),
    ("light[3].outer_angle", NAN, "finite"),
    ("light[3].type", "laser", "laser"),
    ("effect[0].radius", NAN, "finite"),
    ("effect[0].samples", True, "expected a number"),
    ("effect[0].type", "bloom", "bloom"),
    ("event[0].time", NAN, "finite"),
    ("event[0].time", INF, "finite"),
    ("event[0].params.specular_intensity", NAN, "finite"),
]


@pytest.mark.parametrize("key, value, fragment", CASES,
                         ids=[f"{key}={value!r}" for key, value, _ in CASES])
def test_bad_scene_value_exits_2_naming_the_key(tmp_path, capsys, monkeypatch, key, value,
                                                fragment):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(toml_document(set_key(key, value)(GOOD)))
    before = b"an earlier render, not to be replaced"
    (tmp_path / "out.png").write_bytes(before)
    code = main(["render", "s.toml", "-o", "out.png"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    # the key is named: object[0].params.color, light[2].radius, camera.fov, size
    named = key if fragment not in ("up is parallel", "far must be greater than near",
                                    "scale must not be zero",
                                    "scale must be at least 1e-06 in size") \
        else NAMED_BY_TABLE[key]
    assert err.startswith(f"error: s.toml: {named}"), err
    assert fragment in err, err
    assert (tmp_path / "out.png").read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.png", "s.toml"]


@pytest.mark.slow
def test_the_good_scene_renders(tmp_path, capsys, monkeypatch):
    # the cases above fail because of their one edit, not because the scene was bad already
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(toml_document(GOOD))
    code = main(["render", "s.toml", "-o", "out.png"])
    assert code == 0, capsys.readouterr().err


def test_the_python_api_takes_numpy_values_and_a_fields_own_conversion():
    from typing import Annotated

    import numpy as np
    from pydantic import BeforeValidator

    from deferred.errors import InputError
    from deferred.interfaces import registry
    from deferred.params import Params, validate_params
    from deferred.scene.loader import scene_from_dict

    point = registry.lights.get("point").from_dict(
        {"intensity": np.float32(2.0), "radius": np.int64(3), "position": np.array([0., 1., 2.])})
    assert point.params.intensity == 2.0 and point.params.position == (0.0, 1.0, 2.0)
    scene = scene_from_dict({"camera": {"position": np.array([0.0, 1.0, 4.0])},
                             "object": [{"mesh": "builtin:sphere", "material": "revie_fur",
                                         "params": {"seed": 2_000_000_000}}]})
    assert scene.objects[0].material.params.seed == 2_000_000_000  # ints: int32, not 1e9

    class Hex(Params):
        n: Annotated[int, BeforeValidator(lambda v: int(v, 16) if isinstance(v, str) else v)] = 0

    assert validate_params(Hex, {"n": "0x10"}, "p").n == 16  # the plugin's conversion runs
    with pytest.raises(InputError, match=r"expected a number, not true or false"):
        registry.lights.get("point").from_dict({"intensity": np.bool_(True)}, "l")
    with pytest.raises(InputError, match=r"scale\[2\]: expected a number, not true or false"):
        scene_from_dict({"object": [{"mesh": "builtin:sphere", "scale": [1, 2, True]}]})


def test_a_plugins_nested_fields_are_held_to_the_same_rules():
    from collections.abc import Sequence

    from pydantic import BaseModel

    from deferred.errors import InputError
    from deferred.params import Params, validate_params

    class Inner(BaseModel):  # a plain pydantic model inside a plugin's parameters
        x: float = 0.0

    class Plugin(Params):
        weights: dict[str, float] = {}
        samples: Sequence[float] = ()
        inner: Inner = Inner()

    # the key names where inside the field the value lies, and shows it
    cases = [({"weights": {"a": True}},
              r"weights\.a: expected a number, not true or false \(got True\)"),
             ({"weights": {"a": "2.5"}}, r"weights\.a: expected a number, not a string"),
             ({"samples": [1.0, 1e300]}, r"samples\[1\]: must be within"),
             ({"inner": {"x": float("nan")}}, r"inner\.x: must be a finite number")]
    for values, message in cases:
        with pytest.raises(InputError, match=message):
            validate_params(Plugin, values, "p")
    good = validate_params(Plugin, {"weights": {"a": 1.0}, "samples": [1, 2],
                                    "inner": {"x": 2.0}}, "p")
    assert good.weights == {"a": 1.0} and good.inner.x == 2.0
