"""The API reference (docs/build_api.py, pdoc) builds cleanly and documents the public names."""

from __future__ import annotations

import html
import importlib.util
import inspect
import re
from pathlib import Path

import pytest
from locations import ROOT

pytest.importorskip("pdoc")

BUILD_SCRIPT = ROOT / "docs" / "build_api.py"


def load_build_script():
    spec = importlib.util.spec_from_file_location("build_api", BUILD_SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("api")
    problems = load_build_script().build(out)
    assert problems == [], "pdoc warned:\n" + "\n".join(problems)
    return out


def sections(page: Path) -> dict[str, str]:
    """Documented name -> its rendered docstring as text ('' when it has none)."""
    found = {}
    for part in re.split(r'<section id="', page.read_text(encoding="utf-8"))[1:]:
        name = part.split('"', 1)[0]
        doc = re.search(r'<div class="docstring">(.*?)</div>', part, re.S)
        found[name] = html.unescape(re.sub(r"<[^>]+>", "", doc.group(1))).strip() if doc else ""
    return found


def members(page: Path) -> set[str]:
    """Documented members of classes (``Renderer.render``)."""
    return set(re.findall(r'<div id="([^"]+\.[^"]+)"', page.read_text(encoding="utf-8")))


@pytest.mark.slow
def test_reference_has_the_two_public_modules_only(reference):
    pages = sorted(p.relative_to(reference).as_posix() for p in reference.rglob("*.html"))
    assert pages == ["deferred.html", "deferred/api.html", "index.html"]


def test_package_root_documents_the_entry_points(reference):
    names = sections(reference / "deferred.html")
    for name in ("Renderer", "RenderResult", "load_scene", "Scene", "render_scene",
                 "InputError", "create_context"):
        assert names.get(name), f"deferred.{name} is missing or has no docstring"
    assert {"Renderer.render", "Renderer.release"} <= members(reference / "deferred.html")


def test_plugin_api_documents_what_plugins_import(reference):
    names = sections(reference / "deferred" / "api.html")
    for name in ("Material", "MaterialParams", "ShadingModel", "Light", "Effect", "RenderPass",
                 "ObjectPass", "FullscreenPass", "TargetSpec", "Order", "Phase", "read_image",
                 "read_channels", "view_point", "view_direction", "GBufferData", "copy_pass"):
        assert names.get(name), f"deferred.api.{name} is missing or has no docstring"
    assert {"Order.TRANSPARENT", "TargetSpec.scale", "TargetSpec.from_format",
            "Material.scene_passes", "ObjectPass.draw_uniforms"} <= \
        members(reference / "deferred" / "api.html")


@pytest.mark.parametrize("module_name", ["deferred", "deferred.api"])
def test_every_public_class_and_function_has_its_own_docstring(module_name):
    module = importlib.import_module(module_name)
    missing = []
    for name in module.__all__:
        obj = getattr(module, name)
        if inspect.isclass(obj):
            own = obj.__dict__.get("__doc__")
        elif inspect.isfunction(obj):
            own = obj.__doc__
        else:
            continue  # constants and registries are described in the module docstring
        if not (own and own.strip()):
            missing.append(name)
    assert missing == []


def test_restructuredtext_roles_are_rendered(reference):
    """Docstrings use :class:`X` and ``code``; none may reach the page as raw markup."""
    for page in ("deferred.html", "deferred/api.html"):
        for name, text in sections(reference / page).items():
            assert not re.search(r":(class|func|meth|data|attr|mod):`", text), (page, name)
            assert "``" not in text, (page, name)
