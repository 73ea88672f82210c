"""The documentation site's generated pages (docs/site_pages.py, added by docs/hooks.py): the
scene file reference covers every registered type and its examples load; the materials gallery
shows every built-in material with its figure and parameters; the command reference holds
every command's help; and the site builds with mkdocs --strict (no warning)."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys

import pytest
from locations import ROOT

from deferred.interfaces import registry
from deferred.interfaces.catalogue import catalogue
from deferred.scene.loader import scene_from_toml
from deferred.scene.schema import scene_schema


@pytest.fixture(scope="module")
def pages():
    spec = importlib.util.spec_from_file_location("site_pages", ROOT / "docs" / "site_pages.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_reference_has_every_type_and_key(pages):
    schema = scene_schema()
    text = pages.scene_reference(schema)
    for name in registry.materials:
        assert f'### `material = "{name}"`' in text
    for kind, types in (("light", registry.lights), ("effect", registry.effects)):
        for name in types:
            assert f'### `type = "{name}"`' in text, (kind, name)
    for definition in schema["definitions"].values():
        for key in definition.get("properties", {}):
            assert f"| `{key}` |" in text, key
    assert "| `specular_exponent` | number | `32.0` | >= 1, <= 2048 | Blinn-Phong exponent |" \
        in text
    assert ":class:" not in text
    assert not re.search(r"[^`\n]``[^`]", text)  # reStructuredText's literals as Markdown's


def test_every_example_of_the_reference_loads(pages, tmp_path):
    """Each example, in a scene of its own (a light table beside an object, an object beside a
    light), loads without an error: the reference never shows a file that is refused."""
    examples = pages.reference_examples(scene_schema())
    assert len(examples) > 15
    for example in examples:
        text = example
        if "[[object]]" not in text:
            text += '\n[[object]]\nmesh = "builtin:sphere"\n'
        if "[[light]]" not in text:
            text += '\n[[light]]\ntype = "ambient"\n'
        if "[[event]]" in text:  # the object it names
            text += '\n[[object]]\nname = "my_object"\nmesh = "builtin:sphere"\n'
        scene_from_toml(text, "example.toml", tmp_path)


def test_the_gallery_shows_every_builtin_material(pages):
    text = pages.materials_gallery(catalogue("material"))
    for entry in catalogue("material"):
        name = entry["name"]
        assert f"## {name}\n" in text
        if entry["module"].startswith("deferred.materials."):  # a built-in: its figure
            assert f"(../figures/materials/{name}.png)" in text, name
            assert (ROOT / "docs" / "figures" / "materials" / f"{name}.png").is_file()
        for p in entry["params"]:
            assert f"| `{p['name']}` |" in text


def test_the_command_reference_has_every_command(pages):
    from deferred.cli import cli

    text = pages.command_reference()
    for name in cli.commands:
        assert f"## deferred {name}\n" in text and f"Usage: deferred {name}" in text


@pytest.mark.slow
def test_the_site_builds_strict(tmp_path):
    pytest.importorskip("mkdocs")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir",
                           str(tmp_path / "site")], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    for page in ("index.html", "reference/scene-file/index.html", "api/index.html",
                 "reference/materials/index.html", "benchmarks/index.html"):
        assert (tmp_path / "site" / page).is_file(), page
    api = (tmp_path / "site" / "api" / "index.html").read_text()
    assert "Renderer" in api and "Material" in api and ":class:" not in api
