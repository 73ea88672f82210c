"""The viewer's state and its frames: the scene as the framework's renderers draw it, with the
camera controller, the panels, the split and buffer views, the timeline, hot reload and
recording, put on its window (:mod:`~deferred.viewer.window` opens the window and runs the
loop; :mod:`~deferred.viewer.input` turns the window's events into the viewer's actions).

The viewport sits right of the panels, never under them, at the render size: each pixel of it
is the pixel ``deferred render`` writes for the same camera and time. While the camera moves
or a value is dragged, frames are drawn at a reduced resolution and filtered up; when input
stops, the full frame is drawn again (with each pass timed for the bar chart).
"""

from __future__ import annotations

import math
import time as clock
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import moderngl
import numpy as np
from imgui_bundle import imgui

from deferred.errors import one_line
from deferred.gl.targets import FINAL
from deferred.names import Pipeline
from deferred.render.renderer import Renderer
from deferred.render.temporal import temporal_effect
from deferred.viewer import panels
from deferred.viewer.buffers import (
    ALL_CHANNELS,
    buffer_names,
    capture_view,
    display_image,
    material_view_scene,
)
from deferred.viewer.compare import psnr
from deferred.viewer.display import FrameSlot, Rect, Viewport
from deferred.viewer.imgui_gl import ImguiRenderer, PanelLayer
from deferred.viewer.input import ViewerInput
from deferred.viewer.inspector import inspect_pixel
from deferred.viewer.panels import PANEL_WIDTH
from deferred.viewer.record import Recording, save_screenshot
from deferred.viewer.reload import Watcher
from deferred.viewer.renderers import RendererPool, timed_render
from deferred.viewer.session import Session
from deferred.viewer.timeline import Timeline, scene_duration

INTERACTION_SECONDS = 0.25  # input this recent draws reduced frames
# Reduced frames (adaptive): the divisors tried, and the time a reduced render may take so
# that, with the window's own drawing, interaction stays near 15 frames a second
# (12 and 16 for scenes still over the budget at 1/8: the demo's fur, its vertex work)
REDUCTIONS = (2, 3, 4, 6, 8, 12, 16)
INTERACTIVE_BUDGET_MS = 45.0
# At most this many frames of an unchanged state are drawn (a temporal history converging)
STILL_FRAMES = 256
BACKGROUND = (0.11, 0.11, 0.12)
RATES_SECONDS = 0.5  # how often the panel's frame rate and frame time change


@dataclass
class ViewerOptions:
    pipeline: str = Pipeline.DEFERRED.value
    light_path: str | None = None
    size: tuple[int, int] | None = None  # the frame size (default: the scene's)
    time: float = 0.0
    view: str | None = None  # a buffer view
    split: str | None = None  # the other side's pipeline: split view from the start
    reduce: int | None = None  # the reduced frames' divisor; None: adapts (REDUCTIONS)
    panels: bool = True


class Viewer:
    """The viewer's state and its frame: ``update()`` draws a new frame of the scene when
    something changed, ``draw()`` puts the viewport and the panels on the window."""

    def __init__(self, session: Session, window, options: ViewerOptions | None = None):
        options = options or ViewerOptions()
        self.session = session
        self.wnd = window
        self.ctx: moderngl.Context = window.ctx
        self.options = options
        self.size = options.size or session.scene.size
        self.pipeline = options.pipeline
        self.light_path = options.light_path
        self.mode = "split" if options.split else "single"
        self.other_pipeline = options.split or (Pipeline.FORWARD.value
                                                if self.pipeline == Pipeline.DEFERRED.value
                                                else Pipeline.DEFERRED.value)
        self.other_light_path: str | None = None
        self.split_at = 0.5
        self.gain = 4.0
        self.view_name = options.view
        self.exposure = 0.0
        self.channel = ALL_CHANNELS
        self.view_channels: tuple[str, ...] = ()
        self.adaptive = options.reduce is None
        self.reduce = REDUCTIONS[0] if options.reduce is None else max(1, options.reduce)
        self.show_panels = options.panels
        self.timeline = Timeline(scene_duration(session.scene), time=options.time)
        self.watcher = Watcher(session.scene, session.path)
        self.pool = RendererPool(self.ctx)
        self.viewport = Viewport(self.ctx)
        self.main, self.other = FrameSlot(self.ctx), FrameSlot(self.ctx)
        self._imgui_context = imgui.create_context()
        imgui.set_current_context(self._imgui_context)
        self.io = imgui.get_io()
        self.io.set_ini_filename("")  # no imgui.ini beside the user's files
        self.io.config_flags |= imgui.ConfigFlags_.nav_enable_keyboard
        # a panel that fails part way is closed by imgui at the end of the frame, not asserted
        self.io.config_error_recovery = True
        self.io.config_error_recovery_enable_assert = False
        self.imgui = ImguiRenderer(self.ctx)
        self.panel_layer = PanelLayer(self.ctx, self.imgui)
        # what the panels show
        self.render_error: str | None = None
        self.render_exception: Exception | None = None
        self.notes: list[str] = []  # reload, save, screenshot messages (latest last)
        self.timings: dict[str, float] = {}
        self.timings_first = False  # the timings are of a renderer's first frame
        self.frame_ms = 0.0
        self.fps = 0.0
        self.running = False  # the window's loop runs (the frame rate means something)
        self.psnr: float | None = None
        self.inspector: list[str] = []
        self.buffers: list[str] = []
        self.recording: Recording | None = None
        self.screenshot_path = "view.png"
        self.record_path = "view.mp4"
        self.panel_errors: list[str] = []  # the errors the panels drew last (tests read them)
        # input and what is shown
        # the clock input, interaction and playback read (tests set their own)
        self.now: Callable[[], float] = clock.perf_counter
        self.last_input = -math.inf
        self.shown_key: tuple | None = None
        self.shown_reduced = False
        self.shaders_generation = 0
        self._material_scene: tuple[tuple, Any] | None = None
        self._last_tick = self.now()
        self.still_frames = 0  # frames drawn again for an unchanged state (a history converging)
        self._frame_times: list[float] = []
        self.shown_rates = (0.0, 0.0)  # (fps, frame ms) as the panel shows them
        self._rates_at = -math.inf
        self.input = ViewerInput(self, window)  # attaches the window's events

    # -- layout ----------------------------------------------------------------------------------
    def viewport_rect(self) -> Rect:
        return Rect(PANEL_WIDTH if self.show_panels else 0, 0, *self.size)

    # -- frames ----------------------------------------------------------------------------------
    def interacting(self, now: float | None = None) -> bool:
        now = self.now() if now is None else now
        return now - self.last_input < INTERACTION_SECONDS

    def state_key(self) -> tuple:
        return (self.session.controller.camera(), self.timeline.time, self.session.version,
                id(self.session.scene), self.pipeline, self.light_path, self.mode,
                self.other_pipeline, self.other_light_path, self.view_name, self.exposure,
                self.channel, self.size, self.shaders_generation)

    def tick(self) -> None:
        """Once a window frame: the clock, fly keys, hot reload, then a new frame if needed."""
        now = self.now()
        seconds, self._last_tick = now - self._last_tick, now
        if self.recording is not None and self.timeline.playing:
            self.timeline.advance(1.0 / self.timeline.fps)  # every recorded frame, in turn
        else:
            self.timeline.advance(seconds)
        self.input.fly(seconds)
        self.poll_files()
        self.update()

    def update(self, force_full: bool = False) -> bool:
        """Draw a new frame of the scene if anything it depends on changed, a reduced one
        stands and input stopped, or a temporal effect's history has not yet accumulated its
        still samples for the frame shown; whether one was drawn. A failure keeps the frame
        shown and its error for the panel."""
        interacting = self.interacting() and not force_full
        key = self.state_key()
        same = key == self.shown_key
        if same and (interacting if self.shown_reduced else not self.converging()):
            return False
        self.pool.gl.make_current()  # another context (a renderer of the caller's) may be
        full = not interacting or self.reduce == 1
        size = self.size if full else (max(1, self.size[0] // self.reduce),
                                       max(1, self.size[1] // self.reduce))
        start = clock.perf_counter()
        try:
            self._render(size, full)
        except Exception as exc:  # noqa: BLE001 - any failure is shown, the last frame stays
            self.render_error = one_line(f"{type(exc).__name__}: {exc}"
                                         if not _framework_error(exc) else str(exc))
            self.render_exception: Exception | None = exc
        else:
            self.render_error = self.render_exception = None
        self.frame_ms = (clock.perf_counter() - start) * 1000.0
        self.still_frames = self.still_frames + 1 if same and full and not self.shown_reduced \
            else 0
        self.shown_key, self.shown_reduced = key, not full
        if not full and self.adaptive and self.render_error is None:
            self._adapt(self.frame_ms)
        return True

    def converging(self) -> bool:
        """Whether the full frame shown is a temporal effect's (taa) history still short of
        its ``still_samples``: a still camera draws again until then (each frame adds a sample
        with another jitter), then stops."""
        effect = temporal_effect(self.session.scene)
        if effect is None or self.render_error is not None:
            return False
        samples = getattr(effect.params, "still_samples", STILL_FRAMES)
        return self.still_frames + 1 < min(samples, STILL_FRAMES)

    def _adapt(self, ms: float) -> None:
        """The next reduced frames one step smaller when this one took longer than the
        budget, one step larger when it took well under it (a renderer a step, kept)."""
        index = REDUCTIONS.index(self.reduce) if self.reduce in REDUCTIONS else 0
        if ms > INTERACTIVE_BUDGET_MS and index + 1 < len(REDUCTIONS):
            self.reduce = REDUCTIONS[index + 1]
        elif ms < INTERACTIVE_BUDGET_MS / 3.0 and index > 0:
            self.reduce = REDUCTIONS[index - 1]

    def _render(self, size: tuple[int, int], full: bool) -> None:
        session = self.session
        scene = session.scene
        scene.camera = session.controller.camera()
        time = self.timeline.time
        self.pool.keep_only(scene, *([self._material_scene[1]] if self._material_scene else []))
        if self.view_name:
            self._render_view(size, time)
            return
        renderer = self.pool.get(scene, self.pipeline, self.light_path, size)
        if full:
            self.timings_first = renderer.last_frame is None  # compiling counted in
            self.timings = timed_render(renderer, time)
        else:
            renderer.render(readback=False, time=time)
        self.main.copy_from(renderer.targets[FINAL])
        self.buffers = buffer_names(renderer, scene)
        self.psnr = None
        if self.mode != "single":
            other = self.pool.get(scene, self.other_pipeline, self.other_light_path, size)
            other.render(readback=False, time=time)
            self.other.copy_from(other.targets[FINAL])
            if full:
                self.psnr = psnr(self.main.read(), self.other.read())
        if self.recording is not None and full:
            self.recording.write(self.main.read())

    def _render_view(self, size: tuple[int, int], time: float) -> None:
        scene = self.session.scene
        token = (id(scene), self.session.version, self.view_name)
        if self._material_scene is None or self._material_scene[0] != token:
            self._material_scene = (token, material_view_scene(scene, self.view_name))
        debug_scene = self._material_scene[1]
        if debug_scene is not None:  # the material draws the view: its frame is the view
            debug_scene.camera = scene.camera
            renderer = self.pool.get(debug_scene, self.pipeline, self.light_path, size)
            renderer.render(readback=False, time=time)
            self.main.copy_from(renderer.targets[FINAL])
            self.view_channels = ("R", "G", "B")
            return
        renderer = self.pool.get(scene, self.pipeline, self.light_path, size)
        shown = capture_view(renderer, self.view_name, time)
        self.view_channels = shown.channels
        self.main.upload(display_image(shown, self.exposure, self.channel))
        self.buffers = buffer_names(renderer, scene)

    def full_renderer(self) -> Renderer:
        return self.pool.get(self.session.scene, self.pipeline, self.light_path, self.size)

    # -- hot reload ------------------------------------------------------------------------------
    def poll_files(self, force: bool = False) -> None:
        shaders, scene_files = self.watcher.poll(force)
        if scene_files:
            error = self.session.reload()
            if error is None:
                self.watcher.track(self.session.scene)
                self.timeline.duration = scene_duration(self.session.scene)
                self.timeline.scrub(self.timeline.time)
                self.note(f"reloaded {scene_files[0].name}")
            else:
                self.note(f"{scene_files[0].name} not reloaded: {error}")
        if shaders:
            self.pool.release()  # new renderers compile the files again
            self._material_scene = None
            self.shaders_generation += 1
            self.note(f"recompiling: {', '.join(p.name for p in shaders[:3])} changed")

    def note(self, text: str) -> None:
        self.notes = [*self.notes[-4:], one_line(text)]

    # -- actions the panels and keys share ---------------------------------------------------
    def reset_camera(self) -> None:
        self.session.controller.reset()
        self.touch()

    def touch(self) -> None:
        """Input happened: reduced frames for a moment."""
        self.last_input = self.now()

    def inspect(self, x: int, y: int) -> list[str]:
        """The pixel history of frame pixel (x, y), top-down, for the inspector panel."""
        self.pool.gl.make_current()
        try:
            renderer = self.full_renderer()
            self.inspector = inspect_pixel(renderer, x, y, self.timeline.time)
        except Exception as exc:  # noqa: BLE001 - shown in the panel
            self.inspector = [one_line(str(exc))]
        return self.inspector

    def frame_pixel(self, x: float, y: float) -> tuple[int, int] | None:
        """The frame pixel under window point (x, y), or None outside the viewport."""
        rect = self.viewport_rect()
        if not rect.contains(x, y):
            return None
        return int(x - rect.x), int(y - rect.y)

    def viewport_image(self) -> np.ndarray:
        """The frame shown, (H, W, 4) uint8, top row first."""
        self.pool.gl.make_current()
        return self.main.read()

    def window_image(self) -> np.ndarray:
        """The whole window as drawn last, panels included: (H, W, 3) uint8, top row first."""
        self.pool.gl.make_current()
        fbo = self.wnd.fbo
        width, height = fbo.size
        data = np.frombuffer(fbo.read(components=3, alignment=1), np.uint8)
        # a real window's default framebuffer has no colour attachment 0 to select: moderngl
        # reads it all the same and leaves GL_INVALID_OPERATION, which is not a renderer's
        _ = self.ctx.error
        return data.reshape(height, width, 3)[::-1].copy()

    def screenshot(self, path: str | Path | None = None, window: bool = False) -> Path:
        path = path or self.screenshot_path
        hdr = None
        if str(path).lower().endswith(".exr"):
            hdr = self.full_renderer().read_hdr()
        image = self.window_image() if window else self.viewport_image()
        written = save_screenshot(path, image, hdr)
        self.note(f"wrote {written}")
        return written

    def toggle_recording(self, path: str | None = None) -> None:
        if self.recording is None:
            self.recording = Recording(path or self.record_path, self.timeline.fps)
            self.timeline.playing = True
            self.note(f"recording {self.recording.path}")
        else:
            recording, self.recording = self.recording, None
            self.note(f"wrote {recording.close()}")

    def save(self, camera: bool = False) -> None:
        try:
            written = self.session.save(camera=camera)
        except Exception as exc:  # noqa: BLE001 - shown in the panel
            self.note(f"not saved: {exc}")
            return
        self.watcher.track(self.session.scene)  # our own write is no edit to reload
        self.note(f"saved {written}" + (" (with the camera)" if camera else ""))

    # -- drawing ---------------------------------------------------------------------------------
    def draw(self) -> None:
        """The viewport and the panels into the window's framebuffer."""
        now = clock.perf_counter()
        self._frame_times = [t for t in self._frame_times if now - t < 1.0] + [now]
        self.fps = len(self._frame_times) - 1 if len(self._frame_times) > 1 else 0.0
        if now - self._rates_at >= RATES_SECONDS or not self.running:
            # the panel's figures change twice a second, not every frame: unchanged panels
            # are not drawn again (PanelLayer)
            self.shown_rates, self._rates_at = (self.fps, self.frame_ms), now
        self.pool.gl.make_current()
        fbo = self.wnd.fbo
        fbo.use()
        self.ctx.viewport = (0, 0, *fbo.size)
        self.ctx.scissor = None
        fbo.clear(*BACKGROUND, 1.0)
        rect = self.viewport_rect()
        mode = "single" if self.view_name else self.mode
        self.viewport.draw(fbo, fbo.size[1], rect, self.main,
                           None if mode == "single" else self.other, mode, self.split_at,
                           self.gain)
        if self.show_panels:
            imgui.set_current_context(self._imgui_context)
            self.io.display_size = imgui.ImVec2(*self.wnd.size)
            self.io.delta_time = max(1e-4, now - getattr(self, "_gui_time", now - 1 / 60))
            self._gui_time = now
            imgui.new_frame()
            try:
                self.panel_errors = panels.draw(self, PANEL_WIDTH, self.wnd.size[1])
            except Exception as exc:  # noqa: BLE001 - a panel's failure is shown, not fatal
                self.note(f"panel failed: {type(exc).__name__}: {exc}")
            imgui.render()
            data = imgui.get_draw_data()
            if not self.panel_layer.draw(data, fbo, PANEL_WIDTH, fbo.size[1], BACKGROUND):
                self.imgui.render(data, fbo)

    def resize(self, width: int, height: int) -> None:
        """A real window's viewport follows the window (the panels keep their width)."""
        size = (max(16, width - (PANEL_WIDTH if self.show_panels else 0)), max(16, height))
        if size != self.size:
            self.pool.release()  # the renderers of the old size: a resize compiles once
            self._material_scene = None
            self.size = size

    # -- life ------------------------------------------------------------------------------------
    def close(self) -> None:
        if self.recording is not None:
            self.toggle_recording()
        self.pool.release()
        self.main.release()
        self.other.release()
        self.viewport.release()
        self.panel_layer.release()
        self.imgui.release()
        imgui.destroy_context(self._imgui_context)


def _framework_error(exc: Exception) -> bool:
    from deferred.errors import DeferredError

    return isinstance(exc, DeferredError)


