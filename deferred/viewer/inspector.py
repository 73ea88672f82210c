"""The pixel inspector: a clicked pixel's history through the passes of the frame shown (the
lines ``deferred dump --pixel`` prints)."""

from __future__ import annotations

from deferred.debug.pixel_history import format_history, pixel_history
from deferred.render.renderer import Renderer


def inspect_pixel(renderer: Renderer, x: int, y: int, time: float) -> list[str]:
    """The history of pixel (x, y) (top-down) of the frame at ``time``, as lines."""
    events = pixel_history(renderer, x, y, time=time)
    return format_history(events, x, y, renderer.size)
