"""The dump's index.html: written beside the EXRs, opening from the folder without a server (its
thumbnails inside it, its links relative), and shown by a headless Chromium (Debian's package;
the test is skipped where none is installed): the screenshot is not blank and shows the contact
sheet, every image loads, and the passes are named."""

from __future__ import annotations

import contextlib
import io
import json
import re
import shutil
import subprocess
from html.parser import HTMLParser

import numpy as np
import pytest

from deferred.cli import main
from deferred.io.images import read_image

SCENE = ('size = [64, 48]\n[[object]]\nname = "ball"\nmesh = "builtin:sphere"\n'
         '[[light]]\ntype = "ambient"\n[[light]]\ntype = "point"\nposition = [1, 1, 2]\n')


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links: list[str] = []

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if name in ("src", "href") and value:
                self.links.append(value)


@pytest.fixture(scope="module")
def dump(tmp_path_factory):
    folder = tmp_path_factory.mktemp("index")
    (folder / "scene.toml").write_text(SCENE)
    said = io.StringIO()
    with contextlib.redirect_stderr(said):
        code = main(["dump", str(folder / "scene.toml"), "-o", str(folder / "d"), "--pixel",
                     "32,24"])
    assert code == 0
    err = said.getvalue()  # its last line says where the page is
    assert err.rstrip().endswith(f"open {(folder / 'd' / 'index.html').resolve()} in a browser")
    return folder / "d"


def test_the_index_links_only_files_of_the_dump(dump):
    page = (dump / "index.html").read_text()
    manifest = json.loads((dump / "manifest.json").read_text())
    assert manifest["files"]["index"] == "index.html"
    parser = _Links()
    parser.feed(page)
    local = [link for link in parser.links if not link.startswith("data:image/png;base64,")]
    assert local and all((dump / link).is_file() for link in local), local
    assert not any(link.startswith(("http:", "https:", "/")) for link in local)
    for p in manifest["passes"]:  # every pass, its file linked
        assert f"{p['index']:02d} {p['name']}" in page
        assert p["file"] is None or f'href="{p["file"]}"' in page
    thumbnails = sum(link.startswith("data:image/png") for link in parser.links)
    assert thumbnails >= len(manifest["passes"])
    assert "<h2>Pixel history</h2>" in page and "cleared to (0, 0, 0, 0)" in page
    assert "first write this frame" in page


@pytest.mark.skipif(shutil.which("chromium") is None,
                    reason="no chromium (Debian's package: apt-get install chromium)")
def test_the_index_opens_in_headless_chromium(dump, tmp_path):
    url = (dump / "index.html").as_uri()
    browser = ["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
               "--virtual-time-budget=5000", "--window-size=1000,1400"]
    shot = tmp_path / "index.png"
    subprocess.run([*browser, f"--screenshot={shot}", url], capture_output=True, timeout=180,
                   check=True)
    dom = subprocess.run([*browser, "--dump-dom", url], capture_output=True, text=True,
                         timeout=180, check=True).stdout
    # every image loaded (the contact sheet by its relative path, the thumbnails inline)
    loaded = re.search(r'data-images-loaded="(\d+)" data-images="(\d+)"', dom)
    assert loaded and int(loaded.group(1)) == int(loaded.group(2)) > 1, dom[:300]
    for name in ("gbuffer.clear", "ball.gbuffer", "post.tonemap", "Contact sheet"):
        assert name in dom
    image = np.rint(read_image(shot)[..., :3] * 255.0).astype(np.int16)
    assert image.std() > 20  # not blank
    # the contact sheet's grey (BACKGROUND 0.12: 31 of 255) on the white page: the sheet shows
    sheet = np.all(np.abs(image - 31) <= 2, axis=-1)
    assert sheet.mean() > 0.02, sheet.mean()
    rows = np.nonzero(sheet.any(axis=1))[0]
    assert rows[0] < 400  # near the top, under the title and the facts
