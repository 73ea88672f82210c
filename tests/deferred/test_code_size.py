"""Code size as a test: no module of the framework or its built-in plugins over 500 lines, no
function (or method) over 80, its decorators counted. A module or function past the limit is
split along its responsibilities, not trimmed to fit."""

from __future__ import annotations

import ast
from pathlib import Path

from locations import ROOT

MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 80
CHECKED_FOLDERS = ("deferred", "lights", "materials")


class _Functions(ast.NodeVisitor):
    """Each function's qualified name, line and length in lines (decorators included)."""

    def __init__(self) -> None:
        self.scope: list[str] = []
        self.found: list[tuple[str, int, int]] = []

    def visit_ClassDef(self, node: ast.ClassDef) -> None:
        self.scope.append(node.name)
        self.generic_visit(node)
        self.scope.pop()

    def visit_FunctionDef(self, node: ast.FunctionDef | ast.AsyncFunctionDef) -> None:
        start = min([node.lineno, *(decorator.lineno for decorator in node.decorator_list)])
        self.found.append((".".join([*self.scope, node.name]), node.lineno,
                           node.end_lineno - start + 1))
        self.scope.append(node.name)
        self.generic_visit(node)
        self.scope.pop()

    visit_AsyncFunctionDef = visit_FunctionDef


def oversized(path: Path, name: str) -> list[str]:
    """What in the module at ``path`` (shown as ``name``) is over the limits, one line each."""
    text = path.read_text(encoding="utf-8")
    found = []
    lines = len(text.splitlines())
    if lines > MAX_MODULE_LINES:
        found.append(f"{name}: {lines} lines (a module: at most {MAX_MODULE_LINES})")
    functions = _Functions()
    functions.visit(ast.parse(text, name))
    found += [f"{name}:{line} {qualified}: {length} lines (a function: at most "
              f"{MAX_FUNCTION_LINES})"
              for qualified, line, length in functions.found if length > MAX_FUNCTION_LINES]
    return found


def test_no_module_or_function_over_the_limits():
    found = [problem for folder in CHECKED_FOLDERS
             for path in sorted((ROOT / folder).rglob("*.py"))
             for problem in oversized(path, path.relative_to(ROOT).as_posix())]
    assert not found, "over the limits, split by responsibility:\n" + "\n".join(found)


def test_the_limits_catch_a_long_module_and_a_long_function(tmp_path):
    """The check can fail: a decorated method of 81 lines with its decorator is named, with
    its class, and so is a module of 501 lines; 80 lines and 500 pass."""
    body = "".join(f"        x{i} = {i}\n" for i in range(78))
    source = ("class Atlas:\n"
              "    @staticmethod\n"
              "    def update():\n" + body + "        return 0\n"  # 81 lines
              "\n"
              "    def bind():\n" + body + "        return 0\n")  # 80 lines
    module = tmp_path / "atlas.py"
    module.write_text(source)
    assert oversized(module, "atlas.py") == [
        "atlas.py:3 Atlas.update: 81 lines (a function: at most 80)"]
    lines = len(source.splitlines())
    module.write_text(source + "\n" * (MAX_MODULE_LINES - lines))
    assert oversized(module, "atlas.py") == [
        "atlas.py:3 Atlas.update: 81 lines (a function: at most 80)"]
    module.write_text(source + "\n" * (MAX_MODULE_LINES + 1 - lines))
    assert oversized(module, "atlas.py")[0] == "atlas.py: 501 lines (a module: at most 500)"
