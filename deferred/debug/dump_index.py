"""The dump's ``index.html``: a page a browser opens from the folder, without a server (every
thumbnail is inside it as a PNG data URI; the contact sheet and the EXRs are linked by relative
paths): the frame's facts, the contact sheet, each pass with its thumbnails, time and file, and
the pixel history where ``--pixel`` asked for one."""

from __future__ import annotations

import base64
import html
import io
from collections.abc import Sequence
from typing import Any

from deferred.debug.preview import Tile, thumbnail, to_uint8

THUMB_WIDTH = 160

STYLE = """
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #1d1d1f; background: #fff; }
h1 { font-size: 1.4em; margin: 0 0 .3em; } h2 { font-size: 1.15em; margin: 1.6em 0 .5em; }
.facts { color: #555; } .facts b { color: #1d1d1f; }
.sheet img { max-width: 100%; image-rendering: pixelated; border: 1px solid #ccc; }
.pass { border-top: 1px solid #ddd; padding: .6em 0; }
.pass h3 { font-size: 1em; margin: 0 0 .3em; font-family: ui-monospace, monospace; }
.pass .meta { color: #666; font-size: .9em; }
figure { display: inline-block; margin: .3em .6em .3em 0; vertical-align: top; }
figure img { display: block; image-rendering: pixelated; border: 1px solid #ccc; }
figcaption { font-size: .8em; color: #444; max-width: 180px; }
table { border-collapse: collapse; font-family: ui-monospace, monospace; font-size: .85em; }
td, th { border: 1px solid #ddd; padding: .2em .5em; text-align: left; vertical-align: top; }
"""

# Counts the images that loaded, so a headless browser's DOM says whether the page is whole.
SCRIPT = """window.addEventListener("load", function () {
  var loaded = 0;
  for (var i = 0; i < document.images.length; i++) {
    if (document.images[i].complete && document.images[i].naturalWidth > 0) loaded++;
  }
  document.body.setAttribute("data-images-loaded", String(loaded));
  document.body.setAttribute("data-images", String(document.images.length));
});"""


def png_data_uri(rgb: Any, width: int = THUMB_WIDTH) -> str:
    """A thumbnail of ``rgb`` (float, [0, 1], top row first) as a ``data:image/png`` URI."""
    from PIL import Image

    small = to_uint8(thumbnail(rgb, width))
    out = io.BytesIO()
    Image.fromarray(small).save(out, format="PNG")
    return "data:image/png;base64," + base64.b64encode(out.getvalue()).decode("ascii")


def _figure(tile: Tile) -> str:
    caption = html.escape(tile.subtitle)
    return (f'<figure><img src="{png_data_uri(tile.rgb)}" alt="{caption}">'
            f"<figcaption>{caption}</figcaption></figure>")


def _values(values: Sequence[float] | None) -> str:
    return "" if values is None else "(" + ", ".join(f"{v:.6g}" for v in values) + ")"


def _history(history: dict[str, Any]) -> list[str]:
    x, y = history["pixel"]
    rows = ["<h2>Pixel history</h2>",
            f"<p>pixel {x},{y} ({html.escape(history['coordinates'])}): the passes that "
            "wrote it</p>",
            "<table><tr><th>pass</th><th>fragments</th><th>target</th><th>before</th>"
            "<th>after</th></tr>"]
    for event in history["passes"]:
        fragments = "clear" if event["fragments"] is None else str(event["fragments"])
        for target, after in event["after"].items():
            if target in event.get("cleared_to", {}):
                before = f"cleared to {_values(event['cleared_to'][target])}"
            elif target in event.get("first_writes", []):
                before = "first write this frame"
            else:
                before = _values(event["before"].get(target))
            rows.append(f"<tr><td>{event['index']:02d} {html.escape(event['pass'])}</td>"
                        f"<td>{fragments}</td><td>{html.escape(target)}</td>"
                        f"<td>{html.escape(before)}</td><td>{_values(after)}</td></tr>")
    rows.append("</table>")
    return rows


def index_html(manifest: dict[str, Any], tiles: Sequence[Tile]) -> str:
    """The page for a dump whose manifest is ``manifest`` and whose contact sheet shows
    ``tiles``."""
    width, height = manifest["size"]
    scene = html.escape(str(manifest["scene"]))
    renderer = html.escape(str(manifest.get("gl", {}).get("renderer", "")))
    by_title: dict[str, list[Tile]] = {}
    for tile in tiles:
        by_title.setdefault(tile.title, []).append(tile)
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
             f"<title>dump: {scene}</title><style>{STYLE}</style>",
             f"<script>{SCRIPT}</script></head><body>",
             f"<h1>{scene}</h1>",
             f'<p class="facts"><b>{html.escape(manifest["pipeline"])}</b> pipeline, '
             f"<b>{width}x{height}</b>, frame {manifest['frame_ms']:.2f} ms, "
             f"{len(manifest['passes'])} passes, {renderer}; written {manifest['created']}. "
             'Files: <a href="manifest.json">manifest.json</a>, '
             '<a href="final.png">final.png</a>, <a href="final.exr">final.exr</a>.</p>',
             "<h2>Contact sheet</h2>",
             '<p class="sheet"><a href="contact.png"><img id="contact" src="contact.png" '
             'alt="contact sheet: every buffer of every pass"></a></p>',
             "<h2>Passes</h2>"]
    for p in manifest["passes"]:
        title = f"{p['index']:02d} {p['name']}"
        link = f' <a href="{html.escape(p["file"])}">{html.escape(p["file"])}</a>' \
            if p.get("file") else " (not captured)"
        parts.append(f'<div class="pass" id="pass-{p["index"]}"><h3>{html.escape(title)}</h3>'
                     f'<div class="meta">{html.escape(p["phase"])} phase, '
                     f"{p['time_ms']:.2f} ms, {p['draw_calls']} draw calls; writes "
                     f"{html.escape(', '.join(p['outputs']))};{link}</div>")
        parts += [_figure(tile) for tile in by_title.get(title, [])]
        parts.append("</div>")
    if "frame" in by_title:
        parts.append("<h2>The frame's buffers</h2>")
        parts += [_figure(tile) for tile in by_title["frame"]]
    if "pixel_history" in manifest:
        parts += _history(manifest["pixel_history"])
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"
