"""Registries: built-ins and entry-point plugins found by name and loaded alone, unique and
stable type ids, clear errors."""

import json
import subprocess
import sys

import pytest

from deferred.errors import InputError
from deferred.interfaces.registry import PluginWarning, Registry


def fake_distribution(tmp_path, group, line):
    info = tmp_path / "fake_plugin-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: fake-plugin\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(f"[{group}]\n{line}\n")


def test_entry_point_plugin_is_loaded(tmp_path, monkeypatch):
    fake_distribution(tmp_path, "deferred.test_materials",
                      "test_checker = plugin_material:CheckerMaterial")
    monkeypatch.syspath_prepend(str(tmp_path))
    registry = Registry("material", "deferred.test_materials", "deferred.materials")
    cls = registry.get("test_checker")
    assert cls.__name__ == "CheckerMaterial"


def test_broken_plugin_fails_only_where_it_is_asked_for(tmp_path, monkeypatch):
    fake_distribution(tmp_path, "deferred.test_broken",
                      "oops = no_such_module:Thing\ntest_checker = plugin_material:CheckerMaterial")
    monkeypatch.syspath_prepend(str(tmp_path))
    registry = Registry("material", "deferred.test_broken", "json")  # no built-ins
    # asking for the good plugin loads it alone: the broken one is never imported
    assert registry.get("test_checker").__name__ == "CheckerMaterial"
    with pytest.raises(InputError, match="cannot load material plugin 'oops' \\(fake-plugin\\): "
                                         "ModuleNotFoundError"):
        registry.get("oops")
    # listing skips it with a warning naming it
    with pytest.warns(PluginWarning, match="plugin 'oops'"):
        registry = Registry("material", "deferred.test_broken", "json")
        assert list(registry) == ["test_checker"]


def test_entry_points_load_lazily(tmp_path, monkeypatch):
    fake_distribution(tmp_path, "deferred.test_lazy",
                      "test_checker = plugin_material:CheckerMaterial")
    monkeypatch.syspath_prepend(str(tmp_path))
    registry = Registry("material", "deferred.test_lazy", "json")
    registry.get("test_checker")
    assert set(registry._tried) == {"test_checker"}


def test_type_ids_are_never_reused():
    registry = Registry("material", "deferred.none", "deferred.materials")
    classes = [type(name, (), {"name": name}) for name in ("x", "y", "z")]
    registry.register(classes[0])
    registry.register(classes[1])
    registry.unregister("x")
    registry.register(classes[2])
    ids = {cls.name: cls.type_id for cls in classes}
    assert len(set(ids.values())) == 3
    with pytest.raises(InputError, match="unknown material 'x'"):
        registry.get("x")


def test_an_unknown_name_with_a_newline_stays_on_one_line():
    """A property test found a light type holding a newline split the one-line error."""
    from deferred.interfaces import registry

    message = registry.lights.unknown("la\nser")
    assert "\n" not in message and message.startswith("unknown light 'la\\nser'")


# The built-ins' type ids: the G-buffer's id channel (materials, shading models) and a listed
# light's record hold them, so they never change, whatever loads first.
BUILTIN_IDS = {
    "materials": {"cartoon_hair": 1, "revie_fur": 2, "shell_fur": 3, "standard": 4,
                  "stipple_glass": 5, "pbr": 6, "glass": 7, "subsurface": 8},
    "lights": {"ambient": 1, "directional": 2, "point": 3, "spot": 4, "environment": 5,
               "rect": 6, "disc": 7},
    "shading_models": {"blinn_phong": 1, "kajiya_kay": 2, "toon": 3, "marschner": 4, "pbr": 5,
                       "toon_strands": 6, "subsurface": 7},
    "effects": {"edges": 1, "fxaa": 2, "ssao": 3, "taa": 4},
}

FEATURE_MODULES = ("deferred.materials.", "deferred.lights.", "deferred.effects.")


def run_python(code: str, cwd) -> str:
    result = subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True,
                            text=True)
    assert result.returncode == 0, result.stderr
    return result.stdout


@pytest.mark.parametrize("order", [1, -1])
def test_builtin_type_ids_do_not_depend_on_what_loads_first(order, tmp_path):
    code = f"""
import json
from deferred.interfaces import registry
ids = {{}}
for kind, names in {BUILTIN_IDS!r}.items():
    reg = getattr(registry, kind)
    ids[kind] = {{name: reg.get(name).type_id for name in list(names)[::{order}]}}
print(json.dumps(ids))
"""
    assert json.loads(run_python(code, tmp_path)) == BUILTIN_IDS


def test_listings_hold_every_builtin_in_id_order():
    from deferred.interfaces import registry

    for kind, ids in BUILTIN_IDS.items():
        reg = getattr(registry, kind)
        assert list(reg)[:len(ids)] == list(ids)
        assert [cls.name for cls in reg.builtins()] == list(ids)


def test_a_scene_imports_only_the_types_it_uses(tmp_path):
    (tmp_path / "scene.toml").write_text(
        '[[object]]\nmesh = "builtin:sphere"\nmaterial = "standard"\n\n'
        '[[light]]\ntype = "point"\nposition = [0.0, 2.0, 2.0]\n')
    code = f"""
import sys
from deferred.cli import main
assert main(["render", "scene.toml", "-o", "out.png", "--size", "32x24"]) == 0
print(" ".join(sorted(m for m in sys.modules if m.startswith({FEATURE_MODULES!r}))))
"""
    loaded = run_python(code, tmp_path).split()
    assert "deferred.materials.standard" in loaded and "deferred.lights.point" in loaded
    for unused in ("deferred.materials.revie_fur", "deferred.materials.shell_fur",
                   "deferred.materials.cartoon_hair", "deferred.materials.stipple_glass",
                   "deferred.lights.spot", "deferred.lights.directional",
                   "deferred.lights.ambient", "deferred.effects.taa"):
        assert unused not in loaded


def test_a_plugin_cannot_take_a_builtins_name():
    registry = Registry("material", "deferred.none", "deferred.materials")
    impostor = type("Impostor", (), {"name": "standard"})
    with pytest.raises(ValueError, match="'standard' is the name of the built-in "
                                         "deferred.materials.standard.StandardMaterial"):
        registry.register(impostor)
    # the built-in itself keeps its id in any registry reading the same catalogue
    assert registry.get("standard").type_id == BUILTIN_IDS["materials"]["standard"]
