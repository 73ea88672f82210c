"""The viewer's input: the window's mouse, keyboard and text events go to imgui over the panels,
and over the viewport to the camera controller, the clock and the viewer's actions; the keys
(docs/guide/view.md)."""

from __future__ import annotations

from typing import Any

from imgui_bundle import imgui

from deferred.viewer.display import MODES
from deferred.viewer.panels import PANEL_WIDTH

# The input drives a deferred.viewer.app.Viewer, which imports this module: typed as Viewer in
# the text, Any to the checker (no import circle), as in deferred.viewer.panels.
Viewer = Any



class ViewerInput:
    """The window's events, as the viewer's: attached to ``window`` on creation. Keeps the
    pointer, the button dragging and the keys held (fly keys move the camera while held)."""

    def __init__(self, viewer: Viewer, window: Any):
        self.viewer = viewer
        self.keys = key_codes(window)
        self.dragging: int | None = None
        self.mouse = (-1.0, -1.0)  # the pointer's last window position
        self.keys_down: set[int] = set()
        self._attach(window)

    def _attach(self, wnd: Any) -> None:
        wnd.mouse_press_event_func = lambda x, y, b: self.mouse_press(
            x, y, b, ctrl=bool(getattr(wnd.modifiers, "ctrl", False)))
        wnd.mouse_release_event_func = self.mouse_release
        wnd.mouse_drag_event_func = self.mouse_drag
        wnd.mouse_position_event_func = self.mouse_move
        wnd.mouse_scroll_event_func = self.mouse_scroll
        wnd.key_event_func = self.key_event
        wnd.unicode_char_entered_func = self.char_entered
        wnd.resize_func = self.viewer.resize

    def _in_panels(self, x: float) -> bool:
        return self.viewer.show_panels and x < PANEL_WIDTH

    def _pointer(self, x: float, y: float) -> None:
        self.mouse = (float(x), float(y))
        self.viewer.io.add_mouse_pos_event(float(x), float(y))

    def mouse_move(self, x: float, y: float, dx: float = 0, dy: float = 0) -> None:
        self._pointer(x, y)

    def mouse_press(self, x: float, y: float, button: int, ctrl: bool = False) -> None:
        self._pointer(x, y)
        if self._in_panels(x):
            self.viewer.io.add_mouse_button_event(_imgui_button(button), True)
            return
        pixel = self.viewer.frame_pixel(x, y)
        if pixel is None:
            return
        if ctrl and button == 1:
            self.viewer.inspect(*pixel)
            return
        self.dragging = button

    def mouse_release(self, x: float, y: float, button: int) -> None:
        self._pointer(x, y)
        self.viewer.io.add_mouse_button_event(_imgui_button(button), False)
        self.dragging = None

    def mouse_drag(self, x: float, y: float, dx: float, dy: float) -> None:
        self._pointer(x, y)
        controller = self.viewer.session.controller
        if self.dragging == 1:
            controller.orbit(dx, dy)
        elif self.dragging in (2, 3):
            controller.pan(dx, dy, self.viewer.size[1])
        else:
            return
        self.viewer.touch()

    def mouse_scroll(self, x_offset: float, y_offset: float) -> None:
        if self._in_panels(self.mouse[0]):
            self.viewer.io.add_mouse_wheel_event(float(x_offset), float(y_offset))
            return
        self.viewer.session.controller.zoom(y_offset)
        self.viewer.touch()

    def char_entered(self, char: str) -> None:
        self.viewer.io.add_input_character(ord(char))

    def key_event(self, key: Any, action: Any, modifiers: Any) -> None:
        keys = self.keys
        io = self.viewer.io
        pressed = action == keys.ACTION_PRESS
        imgui_key = _imgui_key(keys, key)
        if imgui_key is not None:
            io.add_key_event(imgui_key, pressed)
        ctrl = bool(getattr(modifiers, "ctrl", False))
        io.add_key_event(imgui.Key.mod_ctrl, ctrl)
        if not pressed:
            self.keys_down.discard(key)
            return
        self.keys_down.add(key)
        if io.want_text_input:
            return
        self.shortcut(key, ctrl)

    def shortcut(self, key: Any, ctrl: bool = False) -> None:
        """The keys (docs/guide/view.md)."""
        keys = self.keys
        viewer = self.viewer
        if ctrl and key == keys.S:
            viewer.save()
        elif key == keys.R:
            viewer.reset_camera()
        elif key == keys.F:
            viewer.session.controller.fly = not viewer.session.controller.fly
        elif key == keys.SPACE:
            viewer.timeline.toggle()
        elif key == keys.RIGHT:
            viewer.timeline.step(1)
        elif key == keys.LEFT:
            viewer.timeline.step(-1)
        elif key == keys.HOME:
            viewer.timeline.scrub(0.0)
        elif key == keys.TAB:
            viewer.mode = list(MODES)[(list(MODES).index(viewer.mode) + 1) % len(MODES)]
        elif key == keys.P:
            viewer.pipeline, viewer.other_pipeline = viewer.other_pipeline, viewer.pipeline
        elif key == keys.B:
            viewer.view_name = None
        elif key == keys.C and not ctrl:
            viewer.save(camera=True)
        elif key == keys.F12:
            viewer.screenshot(window=False)
        elif key == keys.H:
            viewer.show_panels = not viewer.show_panels
        elif key == keys.ESCAPE:
            viewer.wnd.close()

    def fly(self, seconds: float) -> None:
        """The camera flown by the keys held (W/S, A/D, Q/E) for ``seconds``, in fly mode."""
        controller = self.viewer.session.controller
        if not controller.fly or not self.keys_down:
            return
        keys = self.keys
        down = self.keys_down
        forward = (keys.W in down) - (keys.S in down)
        right = (keys.D in down) - (keys.A in down)
        up = (keys.E in down) - (keys.Q in down)
        if forward or right or up:
            controller.fly_move(forward, right, up, min(seconds, 0.1))
            self.viewer.touch()


def key_codes(window: Any) -> Any:
    """The window's key codes; glfw's for the headless window, whose keys are all one
    placeholder (it has no keyboard: the tests send glfw's codes)."""
    keys = window.keys
    if getattr(keys, "R", None) == getattr(keys, "SPACE", None):
        from moderngl_window.context.glfw.keys import Keys

        return Keys
    return keys


def _imgui_button(button: int) -> int:
    """moderngl-window's buttons (1 left, 2 right, 3 middle) as imgui's (0, 1, 2)."""
    return {1: 0, 2: 1, 3: 2}.get(button, 0)


def _imgui_key(keys: Any, key: Any) -> Any:
    names = {"BACKSPACE": imgui.Key.backspace, "ENTER": imgui.Key.enter,
             "TAB": imgui.Key.tab, "LEFT": imgui.Key.left_arrow,
             "RIGHT": imgui.Key.right_arrow, "UP": imgui.Key.up_arrow,
             "DOWN": imgui.Key.down_arrow, "DELETE": imgui.Key.delete,
             "HOME": imgui.Key.home, "END": imgui.Key.end, "ESCAPE": imgui.Key.escape}
    for name, imgui_key in names.items():
        if getattr(keys, name, object()) == key:
            return imgui_key
    return None
