"""Pixel history (``deferred dump --pixel``): every pass of a frame probed at one pixel with a
one-pixel scissor and an occlusion query, like a frame debugger's pixel history, and the
result as lines for a terminal.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from deferred.core.passes import ClearPass, RenderPass
from deferred.debug.capture import to_float
from deferred.errors import InputError
from deferred.render.renderer import Renderer


@dataclass
class PixelEvent:
    """What one pass did to one pixel: fragments that reached it (None for a clear) and each
    written target's value before and after.

    ``before`` is the value the pass found. For a target no earlier pass of the frame wrote
    (``first_writes``) that is what the previous frame left, not this frame's: it is named so,
    never compared. A target the pass creates with a clear value (``cleared_to``) is cleared
    to it before the pass draws."""

    index: int
    name: str
    phase: str
    fragments: int | None
    before: dict[str, list[float]]
    after: dict[str, list[float]]
    cleared: bool = False  # the pass cleared a target it creates: every pixel of it
    first_writes: tuple[str, ...] = ()  # targets no earlier pass of this frame wrote
    cleared_to: dict[str, list[float]] = field(default_factory=dict)

    @property
    def changed(self) -> bool:
        return self.before != self.after

    @property
    def wrote(self) -> bool:
        return self.fragments is None or self.fragments > 0 or self.changed or self.cleared

    def describe(self) -> dict[str, Any]:
        return {"index": self.index, "pass": self.name, "phase": self.phase,
                "fragments": self.fragments, "cleared": self.cleared,
                "before": {t: v for t, v in self.before.items() if t not in self.first_writes},
                "first_writes": list(self.first_writes), "cleared_to": dict(self.cleared_to),
                "after": self.after}


def parse_pixel(text: str, size: tuple[int, int]) -> tuple[int, int]:
    try:
        x, y = (int(v) for v in text.split(","))
    except ValueError:
        raise InputError(f"expected X,Y such as 640,360, got '{text}'", "--pixel") from None
    width, height = size
    if not (0 <= x < width and 0 <= y < height):
        raise InputError(f"{x},{y} is outside the {width}x{height} image", "--pixel")
    return x, y


def pixel_history(renderer: Renderer, x: int, y: int, time: float = 0.0) -> list[PixelEvent]:
    """Every pass's effect on pixel (x, y) (top-down image coordinates) of the next frame
    (the frame at ``time``, seconds).

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
    written: set[str] = set()  # targets a pass of this frame wrote so far
    pending: list[tuple[dict[str, np.ndarray], int | None]] = []  # from before to after

    def texel(target: str) -> tuple[int, int, int, int]:
        """The pixel in ``target`` (in a reduced one, the texel covering it)."""
        return targets.rect_at((gx, gy, 1, 1), targets[target].size)[:2] + (1, 1)

    def read(target: str) -> np.ndarray:
        spec = targets.specs[target]
        if spec.depth:
            data = targets.framebuffer((), target).read(texel(target), components=1,
                                                         attachment=-1, dtype="f4")
            return np.frombuffer(data, np.float32).copy()
        data = targets.framebuffer((target,)).read(texel(target), components=spec.components,
                                                   dtype=spec.dtype)
        return np.frombuffer(data, {"f1": np.uint8, "f2": np.float16,
                                    "f4": np.float32}[spec.dtype]).copy()

    def before(render_pass: RenderPass, frame) -> None:
        writes = list(dict.fromkeys(render_pass.writes))
        values = {t: read(t) for t in writes}
        targets.scissor = (gx, gy, 1, 1)
        try:
            with query:
                frame.run_pass(render_pass)
        finally:
            targets.scissor = None
        fragments = None if isinstance(render_pass, ClearPass) else int(query.samples)
        for target, value in values.items():  # undo the probe: the real pass comes next
            targets[target].write(value.tobytes(), viewport=texel(target), alignment=1)
        pending.append((values, fragments))

    def after(render_pass: RenderPass, frame) -> None:
        values, fragments = pending.pop()
        # a pass whose creates are cleared wrote the pixel even where no fragment reached it
        # (the background of a list shading pass)
        cleared_to = {t: [float(v) for v in spec.clear[:len(values[t])]]
                      for t, spec in render_pass.creates.items()
                      if spec.clear is not None and t in values}
        writes = list(dict.fromkeys(render_pass.writes))
        events.append(PixelEvent(
            len(events), render_pass.name, render_pass.phase.value, fragments,
            {t: _floats(v) for t, v in values.items()},
            {t: _floats(read(t)) for t in writes}, bool(cleared_to),
            tuple(t for t in writes if t not in written), cleared_to))
        written.update(writes)

    renderer.render(on_pass=after, before_pass=before, time=time)
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
        if event.cleared and event.fragments is not None:
            what = f"cleared, {what}"
        lines.append(f"{event.index:02d} {event.name} ({event.phase}): {what}")
        for target, value in event.after.items():
            if target in event.cleared_to:
                was, note = f"cleared to {_fmt(event.cleared_to[target])}", ""
            elif target in event.first_writes:  # what it held is the previous frame's
                was, note = "(first write this frame)", ""
            else:
                was = _fmt(event.before.get(target))
                note = "" if value != event.before.get(target) else "  (unchanged)"
            lines.append(f"    {target:<20} {was} -> {_fmt(value)}{note}")
    return lines


def _fmt(values: list[float] | None) -> str:
    if values is None:
        return "?"
    return "(" + ", ".join(f"{v:.6g}" for v in values) + ")"
