"""The README and the documentation's Python blocks marked to run do run, as written, in a
fresh interpreter; the README stays short and starts with the two documented commands.

A block is marked by the HTML comment ``<!-- test: run -->`` on the line before its
```` ```python ```` fence (the comment shows neither on GitHub nor on the site). Each marked block
runs alone, in its own interpreter, in an empty temporary folder (files it writes land there).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest
from locations import ROOT

README = ROOT / "README.md"
PAGES = sorted([README, *(ROOT / "docs").rglob("*.md")])
README_LINES = 150
# the README's first two commands: install and render the demo; install and run the tests
# (.ci/run runs the second's test command)
FIRST_COMMANDS = [
    "python3 -m venv .venv && . .venv/bin/activate && pip install -e . && "
    "deferred render -o demo.png",
    "python3 -m venv .venv && . .venv/bin/activate && pip install -e '.[dev]' && "
    "python -m pytest",
]
MARKER = "<!-- test: run -->"
MARKED_BLOCK = re.compile(r"^" + re.escape(MARKER) + r"[ \t]*\n```python[ \t]*\n(.*?)^```[ \t]*$",
                          re.M | re.S)


def marked_blocks(text: str) -> list[tuple[int, str]]:
    """(line number of the ```python fence, its code) of every marked block."""
    return [(text.count("\n", 0, m.start(1)), m.group(1)) for m in MARKED_BLOCK.finditer(text)]


def all_blocks() -> list[tuple[str, int, str]]:
    return [(page.relative_to(ROOT).as_posix(), line, code) for page in PAGES
            for line, code in marked_blocks(page.read_text(encoding="utf-8"))]


def test_every_marker_is_followed_by_a_python_block():
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        assert text.count(MARKER) == len(marked_blocks(text)), \
            f"{page}: a {MARKER} line must be followed directly by a ```python fence"


def test_the_debugging_snippet_is_marked():
    blocks = [code for _, _, code in all_blocks()]
    assert any("capture_frame(renderer)" in code for code in blocks)


def test_the_readme_is_short_and_starts_with_the_two_commands():
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= README_LINES
    first = re.search(r"^```sh\n(.*?)^```", text, re.M | re.S)
    assert first is not None and first.start() < 200, "the commands come first"
    assert first.group(1).splitlines() == FIRST_COMMANDS
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert "pip install -e '.[dev]'" in ci and "python -m pytest" in ci
    getting_started = (ROOT / "docs" / "getting-started.md").read_text(encoding="utf-8")
    assert "pip install -e ." in getting_started and "deferred render -o demo.png" in \
        getting_started


def test_the_readmes_links_reach_files():
    """The README links into the site's pages by their files: each one is there."""
    text = README.read_text(encoding="utf-8")
    links = re.findall(r"\]\(([^)\s#]+)(?:#[^)]*)?\)", text)
    local = [link for link in links if not link.startswith(("http:", "https:"))]
    assert len(local) >= 10
    assert all((ROOT / link).exists() for link in local), \
        [link for link in local if not (ROOT / link).exists()]


def test_marker_extraction():
    text = f"x\n{MARKER}\n```python\nprint(1)\n```\n\n```python\nunmarked()\n```\n"
    assert marked_blocks(text) == [(3, "print(1)\n")]


@pytest.mark.slow
@pytest.mark.parametrize("page, line, code", [
    pytest.param(page, line, code, id=f"{page}:{line}") for page, line, code in all_blocks()])
def test_readme_block_runs(page, line, code, tmp_path):
    env = {**os.environ, "PYTHONWARNINGS": "error::DeprecationWarning"}
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, f"{page} line {line}:\n{done.stderr[-3000:]}"


def test_the_readmes_scene_loads():
    from deferred.scene.loader import scene_from_toml

    blocks = re.findall(r"^```toml\n(.*?)^```", README.read_text(encoding="utf-8"), re.M | re.S)
    assert blocks
    for block in blocks:
        scene = scene_from_toml(block, "README.md")
        assert scene.objects and scene.lights
