"""The viewer's window: a moderngl-window window, real or headless, sized for the frame and the
panels, and the runs of a viewer in it (the window's loop until it closes, or one headless
frame written to a file)."""

from __future__ import annotations

import os
import re
import sys
import time as clock
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

from deferred.errors import InputError
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


# What to do where no window can open: said with the error
OFFSCREEN_HINT = ("draw it offscreen with --headless --screenshot OUT.png, or run the viewer on a "
                  "virtual display (Xvfb: xvfb-run deferred view ...)")


def make_window(size: tuple[int, int], headless: bool,
                title: str = "deferred view") -> BaseWindow:
    """A moderngl-window window: the headless one (EGL, an offscreen framebuffer) or a real
    one (glfw by default; ``DEFERRED_VIEW_WINDOW`` names another moderngl-window backend, e.g.
    pyglet). GL 4.3 where the driver has it (compute shaders: the tiled and clustered light
    paths), else 3.3. A real window that cannot open (no display, a display that does not
    answer) is the environment's problem: an :class:`InputError` naming ``--headless``."""
    import moderngl_window

    name = "headless" if headless else os.environ.get("DEFERRED_VIEW_WINDOW", "glfw")
    if not headless:
        check_display()
    cls = moderngl_window.get_local_window_cls(name)
    extra: dict[str, Any] = {"backend": os.environ.get("DEFERRED_GL_BACKEND", "egl")} \
        if headless else {}
    failure: Exception | None = None
    # glfw reports its errors as Python warnings (b'X11: ...'): kept for the one error line
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        for version in ((4, 3), (3, 3)):
            try:
                return cls(title=title, size=size, gl_version=version, vsync=False,
                           resizable=not headless, aspect_ratio=None, **extra)
            except Exception as exc:  # noqa: BLE001 - window backends raise their own types
                failure = exc
    reasons = [backend_message(warning.message) for warning in said
               if type(warning.message).__name__ == "GLFWError"]
    reason = reasons[-1] if reasons else str(failure)
    if headless:
        raise RuntimeError(f"cannot open a {name} window: {reason}")
    raise InputError(f"cannot open a {name} window ({reason}): {OFFSCREEN_HINT}", "deferred view")


def check_display() -> None:
    """Refuse at once where an X11 or Wayland window has no display to open on."""
    if not sys.platform.startswith(("linux", "freebsd", "openbsd", "netbsd")):
        return  # macOS and Windows windows need no DISPLAY
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise InputError(f"no display to open a window on (DISPLAY and WAYLAND_DISPLAY are "
                         f"unset): {OFFSCREEN_HINT}", "deferred view")


def backend_message(warning: Warning) -> str:
    """A window backend's error as text: glfw's ``(65550) b'X11: ...'`` as ``X11: ...``."""
    text = str(warning)
    quoted = re.fullmatch(r"\(\d+\) b(['\"])(.*)\1", text)
    return quoted.group(2) if quoted else text


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
