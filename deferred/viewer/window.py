"""The viewer's window: a moderngl-window window, real or headless, sized for the frame and the
panels, and the runs of a viewer in it (the window's loop until it closes, or one headless
frame written to a file)."""

from __future__ import annotations

import os
import time as clock
from pathlib import Path
from typing import TYPE_CHECKING, Any

from deferred.viewer.app import Viewer, ViewerOptions
from deferred.viewer.panels import MIN_HEIGHT, PANEL_WIDTH
from deferred.viewer.record import save_screenshot
from deferred.viewer.session import Session

if TYPE_CHECKING:
    from moderngl_window.context.base import BaseWindow


def window_size(frame: tuple[int, int], with_panels: bool = True) -> tuple[int, int]:
    width, height = frame
    return (width + (PANEL_WIDTH if with_panels else 0),
            max(height, MIN_HEIGHT if with_panels else height))


def make_window(size: tuple[int, int], headless: bool,
                title: str = "deferred view") -> BaseWindow:
    """A moderngl-window window: the headless one (EGL, an offscreen framebuffer) or a real
    one (glfw by default; ``DEFERRED_VIEW_WINDOW`` names another moderngl-window backend, e.g.
    pyglet). GL 4.3 where the driver has it (compute shaders: the tiled and clustered light
    paths), else 3.3."""
    import moderngl_window

    name = "headless" if headless else os.environ.get("DEFERRED_VIEW_WINDOW", "glfw")
    cls = moderngl_window.get_local_window_cls(name)
    extra: dict[str, Any] = {"backend": os.environ.get("DEFERRED_GL_BACKEND", "egl")} \
        if headless else {}
    failure: Exception | None = None
    for version in ((4, 3), (3, 3)):
        try:
            return cls(title=title, size=size, gl_version=version, vsync=False,
                       resizable=not headless, aspect_ratio=None, **extra)
        except Exception as exc:  # noqa: BLE001 - window backends raise their own types
            failure = exc
    raise RuntimeError(f"cannot open a {name} window: {failure}")


def run_headless(session: Session, options: ViewerOptions, screenshot: str | Path,
                 gui_frames: int = 2) -> Path:
    """Open the viewer's window offscreen, draw the frame (panels included) once, write it
    to ``screenshot`` (.png) and close."""
    size = options.size or session.scene.size
    window = make_window(window_size(size, options.panels), headless=True)
    viewer = Viewer(session, window, options)
    try:
        viewer.update(force_full=True)
        for _ in range(gui_frames):  # imgui lays its windows out in the first frame
            viewer.draw()
        if viewer.render_exception is not None:
            raise viewer.render_exception
        return save_screenshot(screenshot, viewer.window_image())
    finally:
        viewer.close()
        window.destroy()


def run_window(session: Session, options: ViewerOptions) -> None:
    size = options.size or session.scene.size
    window = make_window(window_size(size, options.panels), headless=False)
    viewer = Viewer(session, window, options)
    try:
        _loop(viewer, window)
    finally:
        viewer.close()
        window.destroy()


def _loop(viewer: Viewer, wnd: BaseWindow) -> None:
    """The window's loop until it closes."""
    viewer.running = True
    while not wnd.is_closing:
        viewer.tick()
        viewer.draw()
        wnd.swap_buffers()
        if not viewer.timeline.playing and not viewer.interacting() and \
                viewer.shown_key == viewer.state_key() and not viewer.shown_reduced:
            clock.sleep(1 / 60)  # idle: the panels only
