"""The README's Python blocks marked to run do run, as written, in a fresh interpreter.

A block is marked by the HTML comment ``<!-- test: run -->`` on the line before its
```` ```python ```` fence (the comment does not show on GitHub). Each marked block runs alone, in
its own interpreter, in an empty temporary folder (files it writes land there).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest
from locations import ROOT

README = ROOT / "README.md"
MARKER = "<!-- test: run -->"
MARKED_BLOCK = re.compile(r"^" + re.escape(MARKER) + r"[ \t]*\n```python[ \t]*\n(.*?)^```[ \t]*$",
                          re.M | re.S)


def marked_blocks(text: str) -> list[tuple[int, str]]:
    """(line number of the ```python fence, its code) of every marked block."""
    return [(text.count("\n", 0, m.start(1)), m.group(1)) for m in MARKED_BLOCK.finditer(text)]


def test_every_marker_is_followed_by_a_python_block():
    text = README.read_text(encoding="utf-8")
    assert text.count(MARKER) == len(marked_blocks(text)), \
        f"a {MARKER} line must be followed directly by a ```python fence"


def test_the_debugging_snippet_is_marked():
    blocks = [code for _, code in marked_blocks(README.read_text(encoding="utf-8"))]
    assert any("capture_frame(renderer)" in code for code in blocks)


def test_marker_extraction():
    text = f"x\n{MARKER}\n```python\nprint(1)\n```\n\n```python\nunmarked()\n```\n"
    assert marked_blocks(text) == [(3, "print(1)\n")]


@pytest.mark.slow
@pytest.mark.parametrize("line, code", [
    pytest.param(line, code, id=f"README.md:{line}")
    for line, code in marked_blocks(README.read_text(encoding="utf-8"))])
def test_readme_block_runs(line, code, tmp_path):
    env = {**os.environ, "PYTHONWARNINGS": "error::DeprecationWarning"}
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, f"README.md line {line}:\n{done.stderr[-3000:]}"
