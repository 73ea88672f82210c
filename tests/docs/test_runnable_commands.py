"""Every shell block of the documentation marked runnable runs, as written, small.

A block is marked by the HTML comment ``<!-- runnable -->`` on the line before its ```` ```sh ````
fence (the comment shows neither on the site nor on GitHub). A page's blocks run in order, as a
reader runs them (a block may use a file an earlier one wrote), each in bash (``set -e``: every
command must succeed), in an empty temporary folder holding links to the repository's
``examples/`` and ``benchmarks/`` and a small ``model.glb``, so the pages' paths work.
"Small": a ``deferred`` function in front of the commands appends ``--size 96x54`` to
``render``, ``dump`` and ``view``, and a tiny sweep to ``bench`` (click takes an option's last
value), so the pages keep the commands people type.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from gltf_files import GltfBuilder, sphere
from locations import ROOT

MARKER = "<!-- runnable -->"
MARKED = re.compile(r"^" + re.escape(MARKER) + r"[ \t]*\n```sh[ \t]*\n(.*?)^```[ \t]*$",
                    re.M | re.S)
PAGES = sorted([*(ROOT / "docs").rglob("*.md"), ROOT / "README.md"])
SMALL = """set -euo pipefail
deferred() {
    case "$1" in
        render|dump|view)
            case " $* " in
                *" --compare "*) command deferred "$@" ;;  # two dumps: no size of its own
                *) command deferred "$@" --size 96x54 ;;
            esac ;;
        bench) command deferred "$@" --size 64x36 --runs 1 --warmup 0 --lights 0,1 ;;
        *) command deferred "$@" ;;
    esac
}
"""


def marked_blocks(text: str) -> list[tuple[int, str]]:
    """(line number of the ```sh fence, its commands) of every marked block."""
    return [(text.count("\n", 0, m.start(1)), m.group(1)) for m in MARKED.finditer(text)]


def all_blocks() -> list[tuple[str, int, str]]:
    return [(page.relative_to(ROOT).as_posix(), line, code) for page in PAGES
            for line, code in marked_blocks(page.read_text(encoding="utf-8"))]


def test_every_marker_is_followed_by_a_shell_block():
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        assert text.count(MARKER) == len(marked_blocks(text)), \
            f"{page}: a {MARKER} line must be followed directly by a ```sh fence"


def test_the_pages_mark_commands_to_run():
    blocks = all_blocks()
    assert len(blocks) >= 10
    pages = {page for page, _, _ in blocks}
    assert {"docs/getting-started.md", "docs/guide/render.md", "docs/guide/info.md"} <= pages
    commands = {m.group(1) for _, _, code in blocks
                for m in re.finditer(r"^deferred (\w+)", code, re.M)}
    assert {"render", "dump", "bench", "view", "info", "params", "schema"} <= commands


def test_marker_extraction():
    text = f"x\n{MARKER}\n```sh\ndeferred info\n```\n\n```sh\nunmarked\n```\n"
    assert marked_blocks(text) == [(3, "deferred info\n")]


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    for name in ("examples", "benchmarks"):
        (tmp_path / name).symlink_to(ROOT / name, target_is_directory=True)
    gltf = GltfBuilder()
    positions, normals, uvs, faces = sphere(1.0, 16, 8)
    gltf.node(root=True, mesh=gltf.mesh(gltf.primitive(
        positions, normals, faces, gltf.material(color=(0.8, 0.4, 0.2, 1.0)), uvs=uvs)))
    gltf.save_glb(tmp_path / "model.glb")
    return tmp_path


@pytest.mark.slow
@pytest.mark.parametrize("page", sorted({page for page, _, _ in all_blocks()}))
def test_runnable_blocks_run(page, workspace):
    bin_dir = str(Path(sys.executable).parent)  # the environment's deferred
    env = {**os.environ, "PATH": bin_dir + os.pathsep + os.environ.get("PATH", "")}
    env.pop("DISPLAY", None)  # the viewer's commands draw offscreen, as on a server
    env.pop("WAYLAND_DISPLAY", None)
    for _, line, code in [block for block in all_blocks() if block[0] == page]:
        done = subprocess.run(["bash", "-c", SMALL + code], cwd=workspace, env=env,
                              capture_output=True, text=True, timeout=900)
        assert done.returncode == 0, f"{page} line {line}:\n{code}\n{done.stderr[-3000:]}"
