"""Frame capture: :func:`capture_frame` renders one frame and keeps, for each selected pass, the
targets it wrote as they stood after it (top row first, in the stored type) and its wall-clock
time (``ctx.finish()`` on both sides, on any driver: timer queries are not on every one);
:class:`FrameCapture` holds them with the end-of-frame targets and decodes the G-buffer.
"""

from __future__ import annotations

import fnmatch
from collections.abc import Sequence
from dataclasses import dataclass, field
from time import perf_counter

import numpy as np

from deferred.core.passes import RenderPass
from deferred.errors import InputError
from deferred.gbuffer.layout import (
    ALBEDO_SPECULAR,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    GBufferLayout,
    decode,
)
from deferred.gl.target_spec import TargetSpec, targets_bytes
from deferred.names import LIST_PATHS, Pipeline
from deferred.render.renderer import Renderer

GBUFFER_CHANNELS = ("albedo.R", "albedo.G", "albedo.B", "specular.intensity",
                    "specular.exponent", "N.X", "N.Y", "N.Z", "Z", "material.id",
                    "shading.model")


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
    layout: GBufferLayout = field(default_factory=lambda: GBufferLayout({}))
    _gbuffer: dict[str, np.ndarray] | None = field(default=None, repr=False, compare=False)
    # the length of the light list each pixel's shading loops over (tiled, clustered, Forward+;
    # None on the other paths), top row first
    light_lists: np.ndarray | None = None
    # the shadow atlas's depths, (size, size) top row first, where a light casts shadows
    shadow_atlas: np.ndarray | None = None
    # the cascade (1-based; 0: none) of the first shadowed directional light each pixel reads,
    # from its linear depth; None without such a light or a linear depth
    shadow_cascades: np.ndarray | None = None

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

    def gbuffer_channels(self) -> tuple[str, ...]:
        """The core channels, then each declared datum's as ``name.channel``."""
        return GBUFFER_CHANNELS + tuple(
            f"{name}.{channel}" for name, data in self.layout.data.items()
            for channel in data.channels)

    def gbuffer(self) -> dict[str, np.ndarray]:
        """The decoded G-buffer by channel name (:meth:`gbuffer_channels`), float32 (H, W)."""
        if self._gbuffer is not None:
            return self._gbuffer
        g = decode(self.target(ALBEDO_SPECULAR), self.target(NORMAL_EXPONENT_ID),
                   self.target(LINEAR_DEPTH))
        covered = g["material_id"] > 0.0
        # The zero encoding decodes to +Z; a pixel with no surface has no normal.
        normal = np.where(covered[..., None], g["normal"], 0.0).astype(np.float32)
        values = [g["albedo"][..., 0], g["albedo"][..., 1], g["albedo"][..., 2],
                  g["specular_intensity"], g["specular_exponent"], normal[..., 0],
                  normal[..., 1], normal[..., 2], g["linear_depth"], g["material_id"],
                  g["shading_model"]]
        for name in self.layout.data:
            data = self.target(name)
            values += [data[..., k] for k in range(data.shape[-1])]
        self._gbuffer = dict(zip(self.gbuffer_channels(), values, strict=True))
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


def capture_bytes(renderer: Renderer, passes: Sequence[str] | None = None) -> int:
    """Bytes :func:`capture_frame` holds: the targets each selected pass writes and every target
    at the end of the frame, in their stored types."""
    width, height = renderer.size
    specs = renderer.graph.targets
    selected = select_passes(renderer.passes, passes)
    written = [name for p in renderer.passes if p.name in selected
               for name in dict.fromkeys(p.writes)]
    return targets_bytes([specs[name] for name in written], width, height) + \
        targets_bytes(specs.values(), width, height)


def capture_frame(renderer: Renderer, passes: Sequence[str] | None = None,
                  warmup: bool = True, time: float = 0.0) -> FrameCapture:
    """Render the frame at ``time`` (seconds) with ``renderer`` and capture what every pass
    wrote.

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
            renderer.render(time=time)
        finally:
            renderer.targets.scissor = None
    ctx = renderer.gl.ctx
    targets = renderer.targets
    started: list[float] = []
    captures: list[PassCapture] = []

    def before(render_pass: RenderPass, frame) -> None:
        ctx.finish()
        started.append(perf_counter())

    def after(render_pass: RenderPass, frame) -> None:
        ctx.finish()
        elapsed = (perf_counter() - started[-1]) * 1000.0
        raw = {}
        if render_pass.name in selected:
            raw = {t: targets.read_raw(t)[::-1] for t in dict.fromkeys(render_pass.writes)}
        captures.append(PassCapture(len(captures), render_pass.name, render_pass.phase.value,
                                    tuple(render_pass.reads), tuple(render_pass.writes),
                                    elapsed, 0, targets.specs, raw))

    result = renderer.render(on_pass=after, before_pass=before, time=time)
    frame_ms = sum(c.time_ms for c in captures)  # without the read-backs between passes
    for capture in captures:
        capture.draw_calls = result.draws_by_pass.get(capture.name, 0)
        capture.specs = dict(targets.specs)
    scene = renderer.scene
    ends = {name: targets.read_raw(name)[::-1] for name in targets.specs}  # top row first
    light_lists = None
    if renderer.light_path in LIST_PATHS and renderer.light_lists is not None:
        depth = None  # deferred: only surfaces read a list (Forward+: every fragment drawn)
        if renderer.pipeline_name == Pipeline.DEFERRED:  # GL's bottom row first, as the lists count
            depth = to_float(ends[LINEAR_DEPTH])[::-1, :, 0]
        light_lists = renderer.light_lists.pixel_counts(*renderer.size, depth)[::-1]
    atlas = renderer.shadow_atlas
    shadow_atlas = cascades = None
    if atlas is not None:
        shadow_atlas = atlas.read_depth()[::-1].copy()
        splits = next(iter(atlas.splits.values()), None)  # scene order: the first light's
        if splits is not None and LINEAR_DEPTH in ends:
            cascades = cascade_of(to_float(ends[LINEAR_DEPTH])[..., 0], splits)
    return FrameCapture(
        scene=scene.source, pipeline=renderer.pipeline_name, size=renderer.size,
        gl_info=renderer.gl.info, specs=dict(targets.specs), passes=captures, targets=ends,
        image=result.image, frame_ms=frame_ms, tonemap=scene.tonemap, exposure=scene.exposure,
        layout=scene.gbuffer_layout(), light_lists=light_lists, shadow_atlas=shadow_atlas,
        shadow_cascades=cascades)


def cascade_of(depth: np.ndarray, splits: np.ndarray) -> np.ndarray:
    """The cascade (1-based) a linear view depth falls in, as ``lighting/shadows.glsl`` picks it
    (the first whose far depth lies beyond it); 0 for no surface or beyond the last."""
    index = np.searchsorted(np.asarray(splits, np.float64), depth, side="left") + 1
    return np.where((depth > 0.0) & (index <= len(splits)), index, 0).astype(np.float32)
