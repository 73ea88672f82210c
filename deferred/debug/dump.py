"""Writing a dump folder (``deferred dump``; docs/guide/dump.md): every buffer of
every pass of a captured frame as float EXR with named channels, the frame's decoded buffers, a
contact sheet and a manifest; :func:`write_dump` describes the files.
"""

from __future__ import annotations

import hashlib
import json
import re
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np

from deferred.debug.capture import (
    GBUFFER_CHANNELS,
    FrameCapture,
    PassCapture,
    capture_bytes,
    capture_frame,
    channel_suffixes,
    fits_half,
    select_passes,
    to_float,
)
from deferred.debug.dump_folder import (
    carry_over,
    check_dump_folder,
    staging_folder,
    swap_in_folder,
)
from deferred.debug.dump_index import index_html
from deferred.debug.pixel_history import PixelEvent, pixel_history
from deferred.debug.preview import Tile, contact_sheet, target_views
from deferred.debug.views import view
from deferred.errors import RenderError
from deferred.gbuffer.layout import GBUFFER_COLOR_TARGETS
from deferred.gl.target_spec import TargetSpec
from deferred.gl.targets import COMPOSITE, LIGHT_ACCUMULATION
from deferred.io.images import write_image, write_text
from deferred.io.memory import check_memory
from deferred.io.safety import signals_deferred
from deferred.render.renderer import Renderer

MANIFEST_FORMAT = "deferred-dump/1"
WRITERS = 2  # files compressed at once (OIIO drops the GIL while it compresses)


def stack_buffers(raws: Sequence[np.ndarray], dtype: type = np.float32) -> np.ndarray:
    """Read-back buffers side by side as one (H, W, C) array of ``dtype``, 8-bit as [0, 1],
    filled in place (one pass over memory: this is most of a dump's numpy time)."""
    count = sum(raw.shape[2] for raw in raws)
    out = np.empty(raws[0].shape[:2] + (count,), dtype)
    k = 0
    for raw in raws:
        part = out[..., k: k + raw.shape[2]]
        if raw.dtype == np.uint8:
            np.divide(raw, np.float32(255.0), out=part, casting="unsafe")
        else:
            part[...] = raw
        k += raw.shape[2]
    return out


# Bytes of a pass name in a file name: object labels come from scene files and may be of any
# length, and a file name may hold NAME_MAX bytes with the index and temporary suffix too.
PASS_NAME_MAX = 100


def safe_name(name: str, limit: int = PASS_NAME_MAX) -> str:
    """A pass name as a file name: characters outside ``[A-Za-z0-9._-]`` become ``_`` (object
    labels come from scene files), and a name longer than ``limit`` is cut, with a hash of the
    whole name appended so names that share a long prefix stay distinct."""
    safe = re.sub(r"[^A-Za-z0-9._-]", "_", name)
    if len(safe) > limit:
        digest = hashlib.sha1(name.encode()).hexdigest()[:8]
        safe = f"{safe[:limit - len(digest) - 1]}-{digest}"
    return safe


def pass_file(capture: PassCapture, count: int) -> str:
    digits = max(2, len(str(count - 1)))
    return f"passes/{capture.index:0{digits}d}_{safe_name(capture.name)}.exr"


def write_dump(capture: FrameCapture, directory: str | Path,
               history: Sequence[PixelEvent] | None = None,
               pixel: tuple[int, int] | None = None, scene_file: str | None = None,
               progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Write a capture as a dump folder; returns the manifest::

        DIR/gbuffer.exr       decoded G-buffer: albedo.R albedo.G albedo.B specular.intensity
                              specular.exponent N.X N.Y N.Z Z material.id shading.model (Z is
                              the z_channel), then declared data as <name>.<channel>
        DIR/light.exr         light accumulation, R G B
        DIR/final.exr         composition buffer (linear HDR), R G B A; DIR/final.png the frame
        DIR/light_lists.exr   tiled and clustered paths: the volume lights in each pixel's light
                              list, lights.listed (``--view light_lists``)
        DIR/shadow_atlas.exr  where a light casts shadows: the shadow atlas's depths,
                              shadow.depth (``--view shadow_atlas``; the atlas's own size)
        DIR/passes/NN_<pass>.exr   what pass NN wrote, channels "<target>.R", ... ("<target>.Z")
        DIR/contact.png       every buffer as a labelled thumbnail, in pass order
        DIR/index.html        a page opening without a server: the contact sheet, each pass
                              with its thumbnails, time and file, the pixel history
        DIR/manifest.json     passes (phase, inputs, outputs, formats, time), G-buffer layout, GL

    A file whose buffers are all 8-bit or 16-bit is half float (8-bit codes stay distinct in half);
    one holding any 32-bit buffer, and ``gbuffer.exr`` (decoded normals, linear depth), is float.
    (Mixed per-channel formats would be exact too, but OIIO writes them at half the speed.)

    The dump is written as a whole: into a hidden folder next to ``directory``, which then
    replaces it (under a lock on the folder, so concurrent dumps take turns). An error or an
    interruption (Ctrl-C, SIGTERM) leaves the earlier dump as it was and no temporary files;
    pass files of the earlier dump are gone with it, so the folder never mixes two frames,
    and files no dump writes are kept. ``directory`` must be missing, empty or an earlier
    dump (:func:`check_dump_folder`). Write failures raise ``RenderError`` with the reason.
    """
    directory = check_dump_folder(Path(directory).resolve())  # "." has no name for siblings
    step = progress or (lambda _: None)
    files: dict[str, str] = {}
    try:
        with staging_folder(directory) as staging:
            tiles = _write_files(capture, staging, files, step)
            manifest = build_manifest(capture, files, history, pixel, scene_file)
            write_text(staging / "manifest.json", json.dumps(manifest, indent=2) + "\n")
            step("index.html")
            write_text(staging / "index.html", index_html(manifest, tiles))
            if directory.is_dir():
                carry_over(directory, staging)
            swap_in_folder(staging, directory)
    except OSError as exc:  # the lock, the folders, the renames; files report their own
        raise RenderError(f"cannot write {directory}: {_reason(exc)}") from exc
    return manifest


def _reason(exc: OSError) -> str:
    reason = exc.strerror or str(exc) or type(exc).__name__
    return f"{reason}: {exc.filename}" if exc.filename else reason


def _write_files(capture: FrameCapture, directory: Path, files: dict[str, str],
                 step: Callable[[str], None]) -> list[Tile]:
    """Every image of the dump into ``directory``; ``files`` gets the manifest's entries.
    Returns the contact sheet's tiles (the index's thumbnails)."""
    # OIIO drops the GIL while it compresses: files compress in parallel while numpy prepares
    # the next one (this is most of a dump's time). Pass files go first so the pool starts
    # at once; the contact sheet is built in the pool too.
    pool = ThreadPoolExecutor(max_workers=WRITERS)
    try:
        pending: list[Future] = []

        def write(name: str, *args: Any, **kwargs: Any) -> None:
            # the arrays of queued files are held until written: no more than a file
            # prepared ahead of each writer (every pass's float buffers at once would
            # be several times the capture)
            while sum(not future.done() for future in pending) > WRITERS:
                wait(pending, return_when=FIRST_COMPLETED)
            step(name)
            pending.append(pool.submit(write_image, directory / name, *args, **kwargs))

        for p in capture.passes:
            if not p.captured:
                continue
            name = pass_file(p, len(capture.passes))
            half = fits_half([p.specs[t] for t in p.raw])
            pixels = stack_buffers(list(p.raw.values()), np.float16 if half else np.float32)
            write(name, pixels, channels=p.channel_names(), half=half,
                  attributes={"deferred:pass": p.name, "deferred:phase": p.phase})
        if all(capture.written(t) for t in GBUFFER_COLOR_TARGETS):
            g = capture.gbuffer()
            write("gbuffer.exr", np.stack(list(g.values()), axis=-1),
                  channels=capture.gbuffer_channels())
            files["gbuffer"] = "gbuffer.exr"
        if capture.written(LIGHT_ACCUMULATION):
            write("light.exr", capture.target(LIGHT_ACCUMULATION)[..., :3],
                  channels=("R", "G", "B"), half=True)
            files["light"] = "light.exr"
        if capture.light_lists is not None:
            lists = view(capture, "light_lists")
            write("light_lists.exr", lists.pixels, channels=lists.channels, half=lists.half)
            files["light_lists"] = "light_lists.exr"
        if capture.shadow_atlas is not None:
            atlas = view(capture, "shadow_atlas")
            write("shadow_atlas.exr", atlas.pixels, channels=atlas.channels, half=False)
            files["shadow_atlas"] = "shadow_atlas.exr"
        write("final.exr", capture.target(COMPOSITE), channels=("R", "G", "B", "A"), half=True)
        write("final.png", capture.image)
        files.update({"final": "final.exr", "final_png": "final.png", "contact": "contact.png",
                      "index": "index.html"})
        step("contact.png")

        def sheet() -> list[Tile]:
            tiles = contact_tiles(capture)
            write_image(directory / "contact.png", contact_sheet(tiles))
            return tiles

        sheet_written = pool.submit(sheet)
        pending.append(sheet_written)
        for future in pending:
            future.result()  # re-raise the first failure here
        return sheet_written.result()
    finally:
        # On a failure or Ctrl-C, queued files are dropped rather than written into a folder
        # about to be removed; the ones being written finish first, so nothing writes into
        # the folder after it is gone.
        with signals_deferred():
            pool.shutdown(wait=True, cancel_futures=True)


def contact_tiles(capture: FrameCapture, thumb_width: int = 240) -> list[Tile]:
    """Every captured buffer in pass order, then the frame's decoded buffers.

    Buffers are subsampled to about ``thumb_width`` before they are decoded and coloured, which
    is what keeps the sheet cheap at full HD (a stipple pattern shows as dots)."""
    step = max(1, capture.size[0] // thumb_width)
    tiles = []
    for p in capture.passes:
        for target, raw in p.raw.items():
            for label, rgb in target_views(target, to_float(raw[::step, ::step]),
                                           p.specs[target], capture.tonemap, capture.exposure):
                tiles.append(Tile(f"{p.index:02d} {p.name}",
                                  f"{target}: {label}" if label else target, rgb))
    names = ["albedo", "normal", "depth", "specular", "material"] \
        if all(capture.written(t) for t in GBUFFER_COLOR_TARGETS) else []
    names += ["light"] if capture.written(LIGHT_ACCUMULATION) else []
    names += ["light_lists"] if capture.light_lists is not None else []
    names += ["shadow.cascades"] if capture.shadow_cascades is not None else []
    for name in names + ["composite"]:
        tiles.append(Tile("frame", name, view(capture, name).preview[::step, ::step]))
    if capture.shadow_atlas is not None:
        atlas_step = max(1, capture.shadow_atlas.shape[1] // thumb_width)
        tiles.append(Tile("frame", "shadow_atlas",
                          view(capture, "shadow_atlas").preview[::atlas_step, ::atlas_step]))
    tiles.append(Tile("frame", "final.png", capture.image[::step, ::step, :3] / 255.0))
    return tiles


def _format(spec: TargetSpec) -> dict[str, Any]:
    return {"format": spec.format_name, "bytes_per_pixel": spec.bytes_per_pixel,
            "description": spec.description}


def build_manifest(capture: FrameCapture, files: dict[str, str],
                   history: Sequence[PixelEvent] | None = None,
                   pixel: tuple[int, int] | None = None,
                   scene_file: str | None = None) -> dict[str, Any]:
    passes = []
    for p in capture.passes:
        passes.append({
            "index": p.index, "name": p.name, "phase": p.phase, "inputs": list(p.reads),
            "outputs": list(p.writes),
            "formats": {t: p.specs[t].format_name for t in (*p.reads, *p.writes)
                        if t in p.specs},
            "time_ms": round(p.time_ms, 4), "draw_calls": p.draw_calls,
            "file": pass_file(p, len(capture.passes)) if p.captured else None,
            "channels": p.channel_names() if p.captured else [],
        })
    manifest: dict[str, Any] = {
        "format": MANIFEST_FORMAT,
        "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "scene": scene_file or capture.scene,
        "pipeline": capture.pipeline,
        "size": list(capture.size),
        "gl": capture.gl_info,
        "frame_ms": round(capture.frame_ms, 4),
        "timing": "wall clock around ctx.finish() per pass; a one-pixel warm-up frame "
                  "first compiles shaders and uploads meshes and textures",
        "orientation": "top row first",
        "gbuffer": {
            "bytes_per_pixel": capture.layout.bytes_per_pixel,
            "targets": capture.layout.describe(),
            "file": files.get("gbuffer"),
            "channels": list(capture.gbuffer_channels()),
            "precision": "float",
            "notes": "decoded values: octahedral normals as N.X N.Y N.Z (0 where material.id "
                     "is 0), Z = linear view depth (the z_channel, 0 = background), "
                     "material.id and shading.model unpacked from the id channel; declared "
                     "data as stored, valid where the material that wrote the pixel declares "
                     "it",
        },
        "targets": {name: _format(spec) for name, spec in capture.specs.items()},
        "files": files,
        "passes": passes,
    }
    if history is not None and pixel is not None:
        manifest["pixel_history"] = {
            "pixel": list(pixel), "coordinates": "top-down, x right, y down",
            "passes": [e.describe() for e in history if e.wrote]}
    return manifest


def dump_memory(renderer: Renderer, passes: Sequence[str] | None = None) -> int:
    """Bytes a dump of ``renderer``'s frame holds at most: the render targets and the
    materials' textures and state (``Renderer.memory_bytes``), the capture
    (:func:`~deferred.debug.capture.capture_bytes`), and while files are written the float
    buffers of a pass file prepared for each writer and one more, and the decoded G-buffer
    (its channels, their stack and the decoder's temporaries)."""
    width, height = renderer.size
    specs = renderer.graph.targets
    selected = select_passes(renderer.passes, passes)
    pass_channels = [sum(len(channel_suffixes(specs[name])) for name in dict.fromkeys(p.writes))
                     for p in renderer.passes if p.name in selected]
    gbuffer_channels = len(GBUFFER_CHANNELS) + sum(
        len(data.channels) for data in renderer.scene.gbuffer_layout().data.values())
    float_bytes = 4 * width * height
    return (renderer.memory_bytes() + capture_bytes(renderer, passes)
            + (WRITERS + 1) * max(pass_channels, default=0) * float_bytes
            + 3 * gbuffer_channels * float_bytes)


def dump_scene(renderer: Renderer, directory: str | Path, passes: Sequence[str] | None = None,
               pixel: tuple[int, int] | None = None, scene_file: str | None = None,
               progress: Callable[[str], None] | None = None
               ) -> tuple[dict[str, Any], list[PixelEvent] | None]:
    """Capture a frame with ``renderer`` (and the pixel's history) and write the dump; one
    that would hold more than the memory budget is refused before the frame."""
    width, height = renderer.size
    check_memory(dump_memory(renderer, passes),
                 f"a dump of {width}x{height} holds {{}} (the targets, every captured pass's "
                 "buffers, the files being written)", renderer.size_where,
                 "a smaller --size, or --passes to capture fewer passes")
    capture = capture_frame(renderer, passes)
    history = pixel_history(renderer, *pixel) if pixel is not None else None
    manifest = write_dump(capture, directory, history, pixel, scene_file, progress)
    return manifest, history
