"""The architecture as a test: deferred/'s layers import only downward (type hints included), no
module imports itself through others, and plugins import the public API module alone.

The layers are pyproject.toml's import-linter contract (``lint-imports`` checks the same); the
graph is grimp's, import-linter's own, which reads every import statement, those under
``if TYPE_CHECKING`` and inside functions too."""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import grimp
import pytest
from locations import ROOT

# packages of plugins: they import deferred.api, their own modules and nothing else of deferred
PLUGIN_FOLDERS = {"materials": "deferred.materials", "lights": "deferred.lights",
                  "deferred/effects": "deferred.effects",
                  "examples/plugins/deferred-velvet/deferred_velvet": "deferred_velvet",
                  "examples/plugins/deferred-wax/deferred_wax": "deferred_wax"}


def contract_layers() -> list[grimp.Layer]:
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover
        import tomli as tomllib
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    (contract,) = [c for c in config["contracts"] if c["type"] == "layers"]
    return [grimp.Layer(*(name.strip() for name in layer.split("|")), independent=True)
            for layer in contract["layers"]]


@pytest.fixture(scope="module")
def graph() -> grimp.ImportGraph:
    return grimp.build_graph("deferred", cache_dir=None)


def illegal(graph: grimp.ImportGraph) -> list[str]:
    """``importer -> imported`` packages of each import against the layers."""
    found = graph.find_illegal_dependencies_for_layers(layers=contract_layers())
    return sorted(f"{dep.importer} -> {dep.imported}" for dep in found)


def import_circles(graph: grimp.ImportGraph) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iteratively)."""
    edges = {module: sorted(graph.find_modules_directly_imported_by(module))
             for module in graph.modules}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles = []
    for start in sorted(edges):
        if start in index:
            continue
        work = [(start, iter(edges[start]))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(edges.get(child, ()))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    circles.append(sorted(component))
    return circles


def test_every_layer_imports_only_from_below(graph):
    assert illegal(graph) == []


def test_an_upward_import_breaks_the_contract(graph):
    """The check can fail: the GL layer importing the renderer is caught, and so is the core
    naming a scene class in a type hint (an edge grimp records like any other)."""
    for importer, imported in (("deferred.gl.context", "deferred.render.renderer"),
                               ("deferred.core.passes", "deferred.scene.scene")):
        graph.add_import(importer=importer, imported=imported)
        try:
            upward = f"{importer.rsplit('.', 1)[0]} -> {imported.rsplit('.', 1)[0]}"
            assert illegal(graph) == [upward]
        finally:
            graph.remove_import(importer=importer, imported=imported)


def test_no_import_circles(graph):
    assert import_circles(graph) == []
    graph.add_import(importer="deferred.gl.uniforms", imported="deferred.gl.shaderlib")
    try:  # shaderlib imports uniforms already
        assert ["deferred.gl.shaderlib", "deferred.gl.uniforms"] in import_circles(graph)
    finally:
        graph.remove_import(importer="deferred.gl.uniforms", imported="deferred.gl.shaderlib")


def deferred_imports(path: Path, package: str) -> list[tuple[int, str]]:
    """(line, module) of every import of a ``deferred`` module in ``path``, relative ones
    resolved against ``package`` (the file's own package)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                module = ".".join(base[:len(base) - node.level + 1] +
                                  ([node.module] if node.module else []))
            else:
                module = node.module or ""
            found.append((node.lineno, module))
        elif isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
    return [(line, module) for line, module in found
            if module == "deferred" or module.startswith("deferred.")]


def plugin_files() -> list[tuple[Path, str, str]]:
    """(file, the package it is in, the plugin package it belongs to) of every plugin file."""
    files = []
    for folder, package in PLUGIN_FOLDERS.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            inner = path.relative_to(ROOT / folder).parent.parts
            files.append((path, ".".join([package, *inner]), package))
    return files


def plugin_violations(files: list[tuple[Path, str, str]]) -> list[str]:
    """``file:line: module`` of each import of deferred that is neither the API module nor the
    plugin's own package."""
    bad = []
    for path, package, own in files:
        for line, imported in deferred_imports(path, package):
            if imported != "deferred.api" and imported != own and \
                    not imported.startswith(f"{own}."):
                bad.append(f"{path.name}:{line}: {imported}")
    return bad


def test_plugins_import_only_the_public_api():
    files = plugin_files()
    assert len(files) > 20  # the built-ins, their techniques, the effects and the velvet plugin
    assert plugin_violations(files) == []


def test_a_plugin_reaching_past_the_api_is_caught(tmp_path):
    plugin = tmp_path / "material.py"
    plugin.write_text("from deferred.api import Material\nfrom . import shaders\n"
                      "from deferred.core.frame import Frame\n"
                      "from deferred.materials.techniques import fur\n")
    assert plugin_violations([(plugin, "plugin", "plugin")]) == [
        "material.py:3: deferred.core.frame", "material.py:4: deferred.materials.techniques"]


def test_the_glsl_a_plugin_may_include_exists():
    from deferred.api import GLSL_INCLUDES
    from deferred.gl.shaderlib import FrameworkShaders

    shaders = FrameworkShaders()
    assert [name for name in GLSL_INCLUDES
            if not shaders.joinpath(*name.split("/")).is_file()] == []
