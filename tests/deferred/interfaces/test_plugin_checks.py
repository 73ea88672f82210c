"""Plugins checked as they load: an entry point that raises on import, gives something other than
a class of its registry's interface, or shares its name with another distribution's is one line
naming the entry point, its distribution and what is wrong (exit 2 where a scene asks for it, a
warning where everything is listed)."""

from __future__ import annotations

import textwrap

import pytest
from command_line import assert_one_line_error, run

from deferred.errors import InputError
from deferred.interfaces.registry import PluginWarning, Registry

PLUGIN_MODULE = '''
import sys
from deferred.api import Light, Material, Params

class Boom:  # implements nothing
    name = "boom"

class LightAsMaterial(Light):
    name = "lamp"

class Nameless(Material):
    pass

class BadParams(Material):
    name = "bad_params"
    Params = dict

class Good(Material):
    name = "good"

def factory():
    return Good

instance = Good()
'''


def fake_distribution(folder, name, group, *lines):
    info = folder / f"{name.replace('-', '_')}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(f"[{group}]\n" + "\n".join(lines) + "\n")


@pytest.fixture
def plugins(tmp_path, monkeypatch):
    """A module of broken plugin classes on sys.path, and a helper declaring entry points."""
    (tmp_path / "checked_plugins.py").write_text(textwrap.dedent(PLUGIN_MODULE))
    (tmp_path / "raising_plugin.py").write_text("raise RuntimeError('needs a GPU driver')\n")
    (tmp_path / "exiting_plugin.py").write_text("import sys\nsys.exit(3)\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    return tmp_path


@pytest.mark.parametrize("line, expected", [
    ("boom = raising_plugin:Boom",
     "cannot load material plugin 'boom' (fake-plugin): RuntimeError: needs a GPU driver"),
    ("boom = exiting_plugin:Boom", "cannot load material plugin 'boom' (fake-plugin): SystemExit"),
    ("boom = checked_plugins:Boom",
     "material plugin 'boom' (fake-plugin) loads checked_plugins:Boom, which is not a Material "
     "subclass (it derives from nothing)"),
    ("lamp = checked_plugins:LightAsMaterial",
     "loads checked_plugins:LightAsMaterial, which is not a Material subclass (it derives from "
     "Light, Revisioned)"),
    ("nameless = checked_plugins:Nameless",
     "loads checked_plugins:Nameless, which lacks name"),
    ("bad_params = checked_plugins:BadParams",
     "loads checked_plugins:BadParams, which has a Params that is not a deferred.api.Params "
     "subclass"),
    ("good = checked_plugins:factory", "which is not a class but a function"),
    ("good = checked_plugins:instance", "which is not a class but an instance of Good"),
])
def test_a_plugin_that_is_not_a_material_is_refused_by_name(plugins, line, expected):
    fake_distribution(plugins, "fake-plugin", "deferred.test_checked", line)
    registry = Registry("material", "deferred.test_checked", "json",
                        interface="deferred.interfaces.material:Material",
                        requires=("Params", "from_dict"))
    name = line.split(" = ")[0]
    with pytest.raises(InputError) as caught:
        registry.get(name, "s.toml: object[0].material")
    message = str(caught.value)
    assert message.startswith("s.toml: object[0].material: ") and expected in message, message
    assert "\n" not in message
    # listing everything skips it with one warning naming it
    registry = Registry("material", "deferred.test_checked", "json",
                        interface="deferred.interfaces.material:Material",
                        requires=("Params", "from_dict"))
    with pytest.warns(PluginWarning, match=f"plugin '{name}' \\(fake-plugin\\)"):
        assert list(registry) == []


def test_a_name_two_distributions_declare_is_refused_naming_both(plugins):
    fake_distribution(plugins, "velvet-a", "deferred.test_twice", "good = checked_plugins:Good")
    fake_distribution(plugins, "velvet-b", "deferred.test_twice",
                      "good = checked_plugins:factory")
    registry = Registry("material", "deferred.test_twice", "json",
                        interface="deferred.interfaces.material:Material")
    with pytest.raises(InputError, match="material plugin 'good' is declared twice, by "
                                         "checked_plugins:(Good|factory) \\(velvet-[ab]\\) and "):
        registry.get("good")
    registry = Registry("material", "deferred.test_twice", "json",
                        interface="deferred.interfaces.material:Material")
    with pytest.warns(PluginWarning, match="'good' is declared twice.*velvet-a.*velvet-b|"
                                           "'good' is declared twice.*velvet-b.*velvet-a"):
        assert list(registry) == []


def test_a_class_whose_name_another_plugin_registered_is_refused(plugins):
    fake_distribution(plugins, "fake-plugin", "deferred.test_taken",
                      "good = checked_plugins:Good", "also_good = checked_plugins:factory")
    (plugins / "second_good.py").write_text(
        "from deferred.api import Material\n\nclass Good(Material):\n    name = 'good'\n")
    fake_distribution(plugins, "other-plugin", "deferred.test_taken",
                      "taken = second_good:Good")
    registry = Registry("material", "deferred.test_taken", "json",
                        interface="deferred.interfaces.material:Material")
    assert registry.get("good").__module__ == "checked_plugins"
    with pytest.raises(InputError, match="cannot load material plugin 'taken' \\(other-plugin\\): "
                                         "material 'good' is already registered by "
                                         "checked_plugins.Good"):
        registry.get("taken")


def test_the_command_line_says_a_broken_plugin_in_one_line(plugins, capfd):
    fake_distribution(plugins, "fake-plugin", "deferred.materials",
                      "test_boom_plugin = checked_plugins:Boom")
    # listed first: the process remembers a plugin it tried (a command is a process)
    code, out, err = run(capfd, "params", "material")
    assert code == 0, err
    warnings = [line for line in err.splitlines() if "test_boom_plugin" in line]
    assert len(warnings) == 1 and warnings[0].startswith("warning: material plugin "
                                                         "'test_boom_plugin' (fake-plugin)")
    assert "test_boom_plugin" not in out
    scene = plugins / "s.toml"
    scene.write_text('[[object]]\nmesh = "builtin:sphere"\nmaterial = "test_boom_plugin"\n')
    code, _, err = run(capfd, "render", scene, "-o", plugins / "out.png", "--size", "32x24")
    assert_one_line_error(code, err, "s.toml: object[0].material: material plugin "
                          "'test_boom_plugin' (fake-plugin) loads checked_plugins:Boom, which is "
                          "not a Material subclass")
    assert "AttributeError" not in err and not (plugins / "out.png").exists()
