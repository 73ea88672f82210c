"""Registries: entry-point plugins, unique and stable type ids, clear errors."""

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
