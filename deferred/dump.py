"""Buffer dumps (DESIGN.md, "Dumps"): every buffer of every pass, as float EXR with named channels.

:func:`capture_frame` renders one frame and keeps, for each pass, every target it wrote as it
stood after the pass (top row first, in the target's stored type) plus the wall-clock time of the
pass (``ctx.finish()`` on both sides: GL timer queries read nothing on llvmpipe).
:func:`write_dump` turns a capture into files::

    DIR/gbuffer.exr       decoded G-buffer: albedo.R albedo.G albedo.B specular.intensity
                          specular.exponent N.X N.Y N.Z Z material.id (Z is the z_channel)
    DIR/light.exr         light accumulation, R G B
    DIR/final.exr         composition buffer (linear HDR), R G B A; DIR/final.png the frame
    DIR/passes/NN_<pass>.exr   what pass NN wrote, channels "<target>.R", ... ("<target>.Z")
    DIR/contact.png       every buffer as a labelled thumbnail, in pass order
    DIR/manifest.json     passes (phase, inputs, outputs, formats, time), G-buffer layout, GL

A file whose buffers are all 8-bit or 16-bit is half float (8-bit codes stay distinct in half);
one holding any 32-bit buffer, and ``gbuffer.exr`` (decoded normals, linear depth), is float.
(Mixed per-channel formats would be exact too, but OIIO writes them at half the speed.)

:func:`pixel_history` probes each pass at one pixel (scissor + occlusion query), like a frame
debugger's pixel history; :func:`compare_dumps` reads two dump folders back and differences them.
"""

from __future__ import annotations

import fnmatch
import json
import re
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np

from .errors import InputError
from .gbuffer import (
    ALBEDO_SPECULAR,
    GBUFFER_COLOR_TARGETS,
    GBUFFER_TARGETS,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    bytes_per_pixel,
    decode,
)
from .imageio import read_channels, srgb_encode, write_image, write_text
from .passes import ClearPass, RenderPass
from .preview import (
    Tile,
    contact_sheet,
    depth_colors,
    grey,
    heat_colors,
    id_colors,
    normal_colors,
    target_views,
    to_uint8,
    tonemap,
)
from .renderer import Renderer
from .targets import COMPOSITE, LIGHT_ACCUMULATION
from .targets_spec import TargetSpec

MANIFEST_FORMAT = "deferred-dump/1"
GBUFFER_CHANNELS = ("albedo.R", "albedo.G", "albedo.B", "specular.intensity",
                    "specular.exponent", "N.X", "N.Y", "N.Z", "Z", "material.id")

# Buffer views by name (``deferred render --view``): channels and what they show.
NAMED_VIEWS: dict[str, tuple[tuple[str, ...], str]] = {
    "albedo": (GBUFFER_CHANNELS[0:3], "linear albedo (G-buffer)"),
    "normal": (GBUFFER_CHANNELS[5:8], "view-space normal, decoded (G-buffer)"),
    "depth": (("Z",), "linear view depth, 0 = background (G-buffer)"),
    "specular": (GBUFFER_CHANNELS[3:5], "specular intensity and exponent (G-buffer)"),
    "material": (("material.id",), "material id, 0 = background (G-buffer)"),
    "light": (("R", "G", "B"), "light accumulation, linear HDR"),
    "composite": (("R", "G", "B", "A"), "composition buffer, linear HDR before tone mapping"),
}


# -- capture -----------------------------------------------------------------------------------
def channel_suffixes(spec: TargetSpec) -> tuple[str, ...]:
    return ("Z",) if spec.depth else tuple("RGBA"[: spec.components])


def fits_half(specs: Sequence[TargetSpec]) -> bool:
    """Whether half float holds every value of these targets exactly (8-bit codes distinctly)."""
    return all(not spec.depth and spec.dtype in ("f1", "f2") for spec in specs)


def to_float(raw: np.ndarray) -> np.ndarray:
    """A read-back buffer in its stored type as float32 (8-bit as [0, 1])."""
    if raw.dtype == np.uint8:
        return raw.astype(np.float32) / 255.0
    return raw.astype(np.float32)


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


@dataclass
class PassCapture:
    """One pass of a captured frame; ``raw`` holds the targets it wrote as they stood after it
    (top row first, stored type), empty when the pass was not selected for capture."""

    index: int
    name: str
    phase: str
    reads: tuple[str, ...]
    writes: tuple[str, ...]
    time_ms: float
    draw_calls: int
    specs: dict[str, TargetSpec]
    raw: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def captured(self) -> bool:
        return bool(self.raw)

    @property
    def arrays(self) -> dict[str, np.ndarray]:
        """Target name -> float32 (H, W, C), top row first."""
        return {name: to_float(raw) for name, raw in self.raw.items()}

    def channel_names(self) -> list[str]:
        return [f"{name}.{s}" for name in self.raw for s in channel_suffixes(self.specs[name])]

    def channels(self) -> dict[str, np.ndarray]:
        """Channel name as in the EXR (``albedo_specular.R``) -> float32 (H, W)."""
        out = {}
        for name, pixels in self.arrays.items():
            for k, suffix in enumerate(channel_suffixes(self.specs[name])):
                out[f"{name}.{suffix}"] = pixels[..., k]
        return out


@dataclass
class FrameCapture:
    """A captured frame: per-pass buffers, end-of-frame targets and what produced them."""

    scene: str
    pipeline: str
    size: tuple[int, int]
    gl_info: dict[str, str]
    specs: dict[str, TargetSpec]
    passes: list[PassCapture]
    targets: dict[str, np.ndarray]  # every target at the end of the frame, stored type, top-down
    image: np.ndarray  # (H, W, 4) uint8, the final image
    frame_ms: float
    tonemap: str = "aces"
    exposure: float = 1.0
    _gbuffer: dict[str, np.ndarray] | None = field(default=None, repr=False, compare=False)

    def __getitem__(self, name: str) -> PassCapture:
        for capture in self.passes:
            if capture.name == name:
                return capture
        raise KeyError(name)

    def written(self, target: str) -> bool:
        """Whether any pass of the frame wrote ``target``."""
        return any(target in p.writes for p in self.passes)

    def before(self, name: str) -> dict[str, np.ndarray]:
        """The targets pass ``name`` writes as they stood just before it ran (float32), from the
        last earlier pass that wrote each; raises ``KeyError`` where that pass was not captured
        or no earlier pass wrote the target."""
        index = self[name].index
        out = {}
        for target in self[name].writes:
            earlier = [p for p in self.passes[:index] if target in p.writes]
            if not earlier or target not in earlier[-1].raw:
                raise KeyError(f"{target} before {name}")
            out[target] = to_float(earlier[-1].raw[target])
        return out

    def target(self, name: str) -> np.ndarray:
        """End-of-frame contents of target ``name``, float32 (H, W, C), top row first."""
        return to_float(self.targets[name])

    def gbuffer(self) -> dict[str, np.ndarray]:
        """The decoded G-buffer by channel name (:data:`GBUFFER_CHANNELS`), float32 (H, W)."""
        if self._gbuffer is not None:
            return self._gbuffer
        g = decode(self.target(ALBEDO_SPECULAR), self.target(NORMAL_EXPONENT_ID),
                   self.target(LINEAR_DEPTH))
        covered = g["material_id"] > 0.0
        # The zero encoding decodes to +Z; a pixel with no surface has no normal.
        normal = np.where(covered[..., None], g["normal"], 0.0).astype(np.float32)
        values = [g["albedo"][..., 0], g["albedo"][..., 1], g["albedo"][..., 2],
                  g["specular_intensity"], g["specular_exponent"], normal[..., 0],
                  normal[..., 1], normal[..., 2], g["linear_depth"], g["material_id"]]
        self._gbuffer = dict(zip(GBUFFER_CHANNELS, values, strict=True))
        return self._gbuffer


def select_passes(passes: Sequence[RenderPass], patterns: Sequence[str] | None) -> set[str]:
    """Names of the passes matching any of ``patterns`` (exact names or shell globs); all when
    ``patterns`` is None. A pattern that matches nothing is bad input."""
    names = [p.name for p in passes]
    if patterns is None:
        return set(names)
    chosen: set[str] = set()
    for pattern in patterns:
        matched = [n for n in names if n == pattern or fnmatch.fnmatchcase(n, pattern)]
        if not matched:
            raise InputError(f"no pass matches '{pattern}' (passes: {', '.join(names)})",
                             "--passes")
        chosen.update(matched)
    return chosen


def capture_frame(renderer: Renderer, passes: Sequence[str] | None = None,
                  warmup: bool = True) -> FrameCapture:
    """Render one frame with ``renderer`` and capture what every pass wrote.

    ``passes`` limits which passes' targets are kept (names or globs; all by default; every
    pass still runs and is timed). ``warmup`` renders a one-pixel frame first if the renderer
    has not rendered yet, so that pass times do not include compiling shaders.
    """
    selected = select_passes(renderer.passes, passes)
    if warmup and renderer.last_frame is None:
        # A frame clipped to one pixel compiles every program and uploads every mesh and
        # texture, so the times below leave out one-time costs, without shading a whole frame.
        renderer.targets.scissor = (0, 0, 1, 1)
        try:
            renderer.render()
        finally:
            renderer.targets.scissor = None
    ctx = renderer.gl.ctx
    targets = renderer.targets
    started: list[float] = []
    captures: list[PassCapture] = []

    def before(render_pass: RenderPass, frame) -> None:
        ctx.finish()
        started.append(time.perf_counter())

    def after(render_pass: RenderPass, frame) -> None:
        ctx.finish()
        elapsed = (time.perf_counter() - started[-1]) * 1000.0
        raw = {}
        if render_pass.name in selected:
            raw = {t: targets.read_raw(t)[::-1] for t in dict.fromkeys(render_pass.writes)}
        captures.append(PassCapture(len(captures), render_pass.name, render_pass.phase.value,
                                    tuple(render_pass.reads), tuple(render_pass.writes),
                                    elapsed, 0, targets.specs, raw))

    result = renderer.render(on_pass=after, before_pass=before)
    frame_ms = sum(c.time_ms for c in captures)  # without the read-backs between passes
    for capture in captures:
        capture.draw_calls = result.draws_by_pass.get(capture.name, 0)
        capture.specs = dict(targets.specs)
    scene = renderer.scene
    return FrameCapture(
        scene=scene.source, pipeline=renderer.pipeline_name, size=renderer.size,
        gl_info=renderer.gl.info, specs=dict(targets.specs), passes=captures,
        targets={name: targets.read_raw(name)[::-1] for name in targets.specs},
        image=result.image, frame_ms=frame_ms, tonemap=scene.tonemap, exposure=scene.exposure)


# -- views -------------------------------------------------------------------------------------
@dataclass
class View:
    """One buffer as values (for EXR) and as a display image (for PNG)."""

    name: str
    pixels: np.ndarray  # (H, W, C) float32, top row first
    channels: tuple[str, ...]
    half: bool  # whether half float holds the values exactly
    preview: np.ndarray  # (H, W, 3) float in [0, 1]


def view_catalogue(passes: Sequence[RenderPass]) -> list[tuple[str, str]]:
    """Every ``--view`` name for a pass list, with what it shows."""
    rows = [(name, f"{doc} [{' '.join(channels)}]") for name, (channels, doc)
            in NAMED_VIEWS.items()]
    targets = dict.fromkeys(t for p in passes for t in p.writes)
    rows += [(t, "target at the end of the frame") for t in targets if t not in NAMED_VIEWS]
    for p in passes:
        if len(p.writes) == 1:
            rows.append((p.name, f"{p.writes[0]} after this {p.phase.value} pass"))
        elif p.writes:
            rows.append((f"{p.name}:TARGET", f"TARGET after this {p.phase.value} pass: "
                                             f"{', '.join(p.writes)}"))
    return rows


def resolve_view(name: str, passes: Sequence[RenderPass]) -> tuple[str | None, str | None]:
    """``(pass, target)`` a view name needs: (None, None) for a named view, (None, target) for
    a target's end-of-frame contents, (pass, target) for a target after a pass."""
    written = {t for p in passes for t in p.writes}
    if name in NAMED_VIEWS:
        needs = {"light": (LIGHT_ACCUMULATION,), "composite": (COMPOSITE,)}.get(
            name, GBUFFER_COLOR_TARGETS)
        missing = [t for t in needs if t not in written]
        if missing:
            raise InputError(f"view '{name}' shows {', '.join(missing)}, which no pass of this "
                             "pipeline writes", "--view")
        return None, None
    by_name = {p.name: p for p in passes}
    if name in written:
        return None, name
    pass_name, _, target = name.partition(":")
    render_pass = by_name.get(pass_name)
    if render_pass is None:
        raise InputError(f"unknown view '{name}' (see --view help)", "--view")
    if not target:
        if len(render_pass.writes) != 1:
            choices = ", ".join(f"{pass_name}:{t}" for t in render_pass.writes)
            raise InputError(f"pass '{pass_name}' writes {len(render_pass.writes)} targets; "
                             f"choose one of {choices}", "--view")
        target = render_pass.writes[0]
    if target not in render_pass.writes:
        raise InputError(f"pass '{pass_name}' does not write '{target}' (it writes "
                         f"{', '.join(render_pass.writes)})", "--view")
    return pass_name, target


def view(capture: FrameCapture, name: str) -> View:
    """The buffer ``--view name`` shows, from a capture that kept the pass it needs."""
    pass_name, target = resolve_view(name, [_Described(p) for p in capture.passes])
    if target is None:
        return _named_view(capture, name)
    if pass_name is None:
        raw = capture.targets[target]
    else:
        if target not in capture[pass_name].raw:
            raise KeyError(f"pass {pass_name} was not captured")
        raw = capture[pass_name].raw[target]
    spec = capture.specs[target]
    pixels = to_float(raw)
    _, preview = target_views(target, pixels, spec, capture.tonemap, capture.exposure)[0]
    suffixes = channel_suffixes(spec)
    return View(name, pixels, tuple(f"{target}.{s}" for s in suffixes),
                fits_half([spec]), preview)


def _named_view(capture: FrameCapture, name: str) -> View:
    channels, _ = NAMED_VIEWS[name]
    if name in ("light", "composite"):
        source = LIGHT_ACCUMULATION if name == "light" else COMPOSITE
        pixels = capture.target(source)[..., : len(channels)]
        return View(name, pixels, channels, True,
                    tonemap(pixels, capture.tonemap, capture.exposure))
    g = capture.gbuffer()
    pixels = np.stack([g[c] for c in channels], axis=-1)
    covered = g["material.id"] > 0.0
    if name == "albedo":
        preview = srgb_encode(pixels).astype(np.float32)
    elif name == "normal":
        preview = normal_colors(pixels, covered)
    elif name == "depth":
        preview = depth_colors(pixels[..., 0], covered)
    elif name == "specular":
        preview = grey(pixels[..., 0])
    else:
        preview = id_colors(pixels[..., 0])
    return View(name, pixels, channels, name in ("albedo", "material"), preview)


class _Described:
    """A captured pass seen through the RenderPass fields :func:`resolve_view` reads."""

    def __init__(self, capture: PassCapture):
        self.name = capture.name
        self.writes = capture.writes


def write_view(path: Path, result: View) -> None:
    """EXR: the values with named channels; PNG: the display image."""
    if path.suffix.lower() == ".exr":
        write_image(path, result.pixels, channels=result.channels, half=result.half)
    else:
        write_image(path, to_uint8(result.preview))


# -- pixel history -----------------------------------------------------------------------------
@dataclass
class PixelEvent:
    """What one pass did to one pixel: fragments that reached it (None for a clear) and each
    written target's value before and after."""

    index: int
    name: str
    phase: str
    fragments: int | None
    before: dict[str, list[float]]
    after: dict[str, list[float]]

    @property
    def changed(self) -> bool:
        return self.before != self.after

    @property
    def wrote(self) -> bool:
        return self.fragments is None or self.fragments > 0 or self.changed

    def describe(self) -> dict[str, Any]:
        return {"index": self.index, "pass": self.name, "phase": self.phase,
                "fragments": self.fragments, "before": self.before, "after": self.after}


def parse_pixel(text: str, size: tuple[int, int]) -> tuple[int, int]:
    try:
        x, y = (int(v) for v in text.split(","))
    except ValueError:
        raise InputError(f"expected X,Y such as 640,360, got '{text}'", "--pixel") from None
    width, height = size
    if not (0 <= x < width and 0 <= y < height):
        raise InputError(f"{x},{y} is outside the {width}x{height} image", "--pixel")
    return x, y


def pixel_history(renderer: Renderer, x: int, y: int) -> list[PixelEvent]:
    """Every pass's effect on pixel (x, y) (top-down image coordinates) of the next frame.

    The frame runs as usual; before each pass, the pass also runs once with a one-pixel scissor
    on every framebuffer it uses and an occlusion query around it, then the pixel is put back as
    it was. ``fragments`` is what that query counted (fragments that passed the pass's tests
    there; instanced lights count one per light), from the true state of the frame at that
    point: screen passes sampling neighbours see what they see in a normal frame.
    """
    width, height = renderer.size
    if not (0 <= x < width and 0 <= y < height):
        raise InputError(f"{x},{y} is outside the {width}x{height} image", "--pixel")
    gx, gy = x, height - 1 - y
    targets = renderer.targets
    query = renderer.gl.ctx.query(samples=True)  # moderngl 5 cannot release a query
    events: list[PixelEvent] = []
    pending: list[tuple[dict[str, np.ndarray], int | None]] = []  # from before to after

    def read(target: str) -> np.ndarray:
        spec = targets.specs[target]
        if spec.depth:
            data = targets.framebuffer((), target).read((gx, gy, 1, 1), components=1,
                                                         attachment=-1, dtype="f4")
            return np.frombuffer(data, np.float32).copy()
        data = targets.framebuffer((target,)).read((gx, gy, 1, 1), components=spec.components,
                                                   dtype=spec.dtype)
        return np.frombuffer(data, {"f1": np.uint8, "f2": np.float16,
                                    "f4": np.float32}[spec.dtype]).copy()

    def before(render_pass: RenderPass, frame) -> None:
        writes = list(dict.fromkeys(render_pass.writes))
        values = {t: read(t) for t in writes}
        targets.scissor = (gx, gy, 1, 1)
        try:
            with query:
                render_pass.execute(frame)
        finally:
            targets.scissor = None
        fragments = None if isinstance(render_pass, ClearPass) else int(query.samples)
        for target, value in values.items():  # undo the probe: the real pass comes next
            targets[target].write(value.tobytes(), viewport=(gx, gy, 1, 1), alignment=1)
        pending.append((values, fragments))

    def after(render_pass: RenderPass, frame) -> None:
        values, fragments = pending.pop()
        events.append(PixelEvent(
            len(events), render_pass.name, render_pass.phase.value, fragments,
            {t: _floats(v) for t, v in values.items()},
            {t: _floats(read(t)) for t in dict.fromkeys(render_pass.writes)}))

    renderer.render(on_pass=after, before_pass=before)
    return events


def _floats(raw: np.ndarray) -> list[float]:
    return [float(v) for v in to_float(raw)]


def format_history(events: Sequence[PixelEvent], x: int, y: int,
                   size: tuple[int, int]) -> list[str]:
    """Plain lines for a terminal: each pass that wrote the pixel and the values it wrote."""
    wrote = [e for e in events if e.wrote]
    lines = [f"pixel {x},{y} (top-down) of {size[0]}x{size[1]}: {len(wrote)} of {len(events)} "
             f"passes wrote it"]
    for event in wrote:
        what = "clear" if event.fragments is None else \
            f"{event.fragments} fragment{'s' if event.fragments != 1 else ''}"
        lines.append(f"{event.index:02d} {event.name} ({event.phase}): {what}")
        for target, value in event.after.items():
            was = event.before.get(target)
            note = "" if value != was else "  (unchanged)"
            lines.append(f"    {target:<20} {_fmt(was)} -> {_fmt(value)}{note}")
    return lines


def _fmt(values: list[float] | None) -> str:
    if values is None:
        return "?"
    return "(" + ", ".join(f"{v:.6g}" for v in values) + ")"


# -- writing a dump ----------------------------------------------------------------------------
def safe_name(name: str) -> str:
    """A pass name as a file name: object labels come from scene files."""
    return re.sub(r"[^A-Za-z0-9._-]", "_", name)


def pass_file(capture: PassCapture, count: int) -> str:
    digits = max(2, len(str(count - 1)))
    return f"passes/{capture.index:0{digits}d}_{safe_name(capture.name)}.exr"


def write_dump(capture: FrameCapture, directory: str | Path,
               history: Sequence[PixelEvent] | None = None,
               pixel: tuple[int, int] | None = None, scene_file: str | None = None,
               progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Write a capture as a dump folder (module docstring); returns the manifest.

    Each file is written atomically; the manifest comes last, so a folder with a manifest is a
    complete dump. Pass files of an earlier dump into the same folder that this one did not
    write are removed, so the folder never mixes two frames.
    """
    directory = Path(directory)
    (directory / "passes").mkdir(parents=True, exist_ok=True)
    step = progress or (lambda _: None)
    files: dict[str, str] = {}
    # OIIO drops the GIL while it compresses: files compress in parallel while numpy prepares
    # the next one (this is most of a dump's time). Pass files go first so the pool starts
    # at once; the contact sheet is built in the pool too.
    with ThreadPoolExecutor(max_workers=2) as pool:
        pending = []

        def write(name: str, *args: Any, **kwargs: Any) -> None:
            step(name)
            pending.append(pool.submit(write_image, directory / name, *args, **kwargs))

        written = set()
        for p in capture.passes:
            if not p.captured:
                continue
            name = pass_file(p, len(capture.passes))
            half = fits_half([p.specs[t] for t in p.raw])
            pixels = stack_buffers(list(p.raw.values()), np.float16 if half else np.float32)
            write(name, pixels, channels=p.channel_names(), half=half,
                  attributes={"deferred:pass": p.name, "deferred:phase": p.phase})
            written.add(name)
        if all(capture.written(t) for t in GBUFFER_COLOR_TARGETS):
            g = capture.gbuffer()
            write("gbuffer.exr", np.stack(list(g.values()), axis=-1), channels=GBUFFER_CHANNELS)
            files["gbuffer"] = "gbuffer.exr"
        if capture.written(LIGHT_ACCUMULATION):
            write("light.exr", capture.target(LIGHT_ACCUMULATION)[..., :3],
                  channels=("R", "G", "B"), half=True)
            files["light"] = "light.exr"
        write("final.exr", capture.target(COMPOSITE), channels=("R", "G", "B", "A"), half=True)
        write("final.png", capture.image)
        files.update({"final": "final.exr", "final_png": "final.png", "contact": "contact.png"})
        step("contact.png")
        pending.append(pool.submit(lambda: write_image(
            directory / "contact.png", contact_sheet(contact_tiles(capture)))))
        for future in pending:
            future.result()  # re-raise the first failure here
    for old in (directory / "passes").glob("*.exr"):
        if re.fullmatch(r"\d+_.+\.exr", old.name) and f"passes/{old.name}" not in written:
            old.unlink()
    manifest = build_manifest(capture, files, history, pixel, scene_file)
    write_text(directory / "manifest.json", json.dumps(manifest, indent=2) + "\n")
    return manifest


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
    for name in names + ["composite"]:
        tiles.append(Tile("frame", name, view(capture, name).preview[::step, ::step]))
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
            "bytes_per_pixel": bytes_per_pixel(),
            "targets": {name: _format(spec) for name, spec in GBUFFER_TARGETS.items()},
            "file": files.get("gbuffer"),
            "channels": list(GBUFFER_CHANNELS),
            "precision": "float",
            "notes": "decoded values: octahedral normals as N.X N.Y N.Z (0 where material.id "
                     "is 0), Z = linear view depth (the z_channel, 0 = background)",
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


def dump_scene(renderer: Renderer, directory: str | Path, passes: Sequence[str] | None = None,
               pixel: tuple[int, int] | None = None, scene_file: str | None = None,
               progress: Callable[[str], None] | None = None
               ) -> tuple[dict[str, Any], list[PixelEvent] | None]:
    """Capture a frame with ``renderer`` (and the pixel's history) and write the dump."""
    capture = capture_frame(renderer, passes)
    history = pixel_history(renderer, *pixel) if pixel is not None else None
    manifest = write_dump(capture, directory, history, pixel, scene_file, progress)
    return manifest, history


# -- comparing dumps ---------------------------------------------------------------------------
@dataclass
class BufferDiff:
    """Differences of one buffer between two dumps; ``problem`` says why it could not be
    compared (missing on one side, other size or channels)."""

    buffer: str
    channels: list[str] = field(default_factory=list)
    max: float = 0.0
    mean: float = 0.0
    pixels: int = 0  # pixels where any channel differs
    per_channel_max: dict[str, float] = field(default_factory=dict)
    problem: str | None = None
    image: str | None = None  # difference image written, relative to the output folder

    def describe(self) -> dict[str, Any]:
        return {"buffer": self.buffer, "channels": self.channels, "max": self.max,
                "mean": self.mean, "pixels": self.pixels, "per_channel_max": self.per_channel_max,
                "problem": self.problem, "image": self.image}


def dump_buffers(directory: Path) -> dict[str, Path]:
    """Buffer key -> file of a dump folder; pass files are keyed by pass name, not number, so
    dumps whose pass lists differ still line up."""
    if not directory.is_dir():
        raise InputError("not a folder", str(directory))
    found = {p.name: p for p in sorted(directory.glob("*.exr"))}
    for path in sorted((directory / "passes").glob("*.exr")):
        found["passes/" + path.stem.split("_", 1)[-1]] = path
    if not found:
        raise InputError("no EXR buffers here: not a dump folder", str(directory))
    return found


def compare_dumps(first: str | Path, second: str | Path,
                  output: str | Path | None = None) -> list[BufferDiff]:
    """Per-buffer max/mean absolute differences of two dump folders, matched by channel name.

    Buffers that differ get a difference image in ``output``: ``<buffer>.exr`` with |B - A| per
    channel and ``<buffer>.png``, the largest channel difference scaled to the buffer's maximum
    (turbo; black where equal). NaN equals NaN; NaN against a number counts as infinite.
    """
    a_files, b_files = dump_buffers(Path(first)), dump_buffers(Path(second))
    out = Path(output) if output is not None else None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    results = []
    for key in list(a_files) + [k for k in b_files if k not in a_files]:
        if key not in b_files or key not in a_files:
            side = Path(second if key not in b_files else first)
            results.append(BufferDiff(key, problem=f"missing in {side}"))
            continue
        results.append(_compare_buffer(key, a_files[key], b_files[key], out))
    if out is not None:
        write_text(out / "compare.json", json.dumps(
            {"a": str(first), "b": str(second), "buffers": [r.describe() for r in results]},
            indent=2) + "\n")
    return results


def _compare_buffer(key: str, path_a: Path, path_b: Path, out: Path | None) -> BufferDiff:
    a, names_a, _ = read_channels(path_a)
    b, names_b, _ = read_channels(path_b)
    if a.shape[:2] != b.shape[:2]:
        return BufferDiff(key, problem=f"size {a.shape[1]}x{a.shape[0]} vs "
                                       f"{b.shape[1]}x{b.shape[0]}")
    if sorted(names_a) != sorted(names_b):
        return BufferDiff(key, names_b, problem="channels differ: "
                          f"{' '.join(names_a)} vs {' '.join(names_b)}")
    b = b[..., [names_b.index(n) for n in names_a]]
    both_nan = np.isnan(a) & np.isnan(b)
    diff = np.where(both_nan, 0.0, np.abs(b - a))
    diff = np.where(np.isnan(diff), np.inf, diff).astype(np.float32)
    result = BufferDiff(key, names_a, float(diff.max()), float(diff.mean()),
                        int(np.count_nonzero(diff.max(axis=-1))),
                        {n: float(diff[..., k].max()) for k, n in enumerate(names_a)})
    if out is not None and result.max > 0.0:
        stem = key.removesuffix(".exr")
        (out / stem).parent.mkdir(parents=True, exist_ok=True)
        write_image(out / f"{stem}.exr", diff, channels=names_a)
        write_image(out / f"{stem}.png", to_uint8(heat_colors(diff.max(axis=-1))))
        result.image = f"{stem}.exr"
    return result
