"""The viewer's panels (imgui): status and errors, timeline, pipeline and split, buffer view,
objects with their material parameters, lights, effects, pass timings, pixel inspector, file.

A value is edited through :meth:`~deferred.viewer.session.Session.edit`: validated as a scene
file's, applied when good, else shown in red under its widget (the frame keeps the last good
value). :func:`draw` returns the errors it showed.
"""

from __future__ import annotations

import math
import sys
from typing import Any

from imgui_bundle import imgui

from deferred.names import LightPath, Pipeline
from deferred.viewer.buffers import ALL_CHANNELS
from deferred.viewer.compare import describe
from deferred.viewer.display import MODES

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

# The panels draw and change a deferred.viewer.app.Viewer, which imports this module: typed as
# Viewer in the text, Any to the checker (no import circle).
Viewer = Any

PANEL_WIDTH = 400  # the panels' column, left of the viewport
MIN_HEIGHT = 640  # the panels' room when the frame is smaller
RED = imgui.ImVec4(1.0, 0.42, 0.38, 1.0)
GREY = imgui.ImVec4(0.65, 0.65, 0.65, 1.0)
COLOR_WORDS = ("color", "albedo", "ground", "tint", "sky")
PIPELINES = [p.value for p in Pipeline]
LIGHT_PATHS = ["(scene's)", *(p.value for p in LightPath)]
OPEN = imgui.TreeNodeFlags_.default_open
LABEL_WIDTH = 140  # pixels right of each widget for its label


def draw(viewer: Viewer, width: int, height: int) -> list[str]:
    """The panels at the window's left, ``width`` by ``height``; the errors shown."""
    shown: list[str] = []
    imgui.set_next_window_pos(imgui.ImVec2(0, 0))
    imgui.set_next_window_size(imgui.ImVec2(width, height))
    flags = (imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize |
             imgui.WindowFlags_.no_collapse | imgui.WindowFlags_.no_saved_settings)
    imgui.begin("deferred view", None, flags)
    imgui.push_item_width(-LABEL_WIDTH)  # widgets leave the labels their room
    _status(viewer, shown)
    if imgui.collapsing_header("Timeline", OPEN):
        _timeline(viewer)
    if imgui.collapsing_header("Pipeline", OPEN):
        _pipeline(viewer)
    if imgui.collapsing_header("Buffer view", OPEN):
        _buffer_view(viewer)
    if imgui.collapsing_header("Objects", OPEN):
        for index, obj in enumerate(viewer.session.scene.objects):
            _open_if_refused(viewer, "object", index)
            if index == 0:  # the first object's parameters in sight from the start
                imgui.set_next_item_open(True, imgui.Cond_.once)
            if imgui.tree_node(f"{obj.label} ({obj.material.name})##object{index}"):
                _params(viewer, "object", index, shown)
                imgui.tree_pop()
    refused = {kind for kind, _, _ in viewer.session.refused}
    if "light" in refused:
        imgui.set_next_item_open(True)
    if imgui.collapsing_header("Lights"):
        for index, light in enumerate(viewer.session.scene.lights):
            _open_if_refused(viewer, "light", index)
            if imgui.tree_node(f"light[{index}] {type(light).name}##light{index}"):
                _params(viewer, "light", index, shown)
                imgui.tree_pop()
    if "effect" in refused:
        imgui.set_next_item_open(True)
    if imgui.collapsing_header("Effects"):
        for index, effect in enumerate(viewer.session.scene.effects):
            _open_if_refused(viewer, "effect", index)
            if imgui.tree_node(f"{effect.name}##effect{index}"):
                _params(viewer, "effect", index, shown)
                imgui.tree_pop()
    if imgui.collapsing_header("Pass timings", OPEN):
        _timings(viewer)
    if imgui.collapsing_header("Pixel inspector"):
        _inspector(viewer)
    if imgui.collapsing_header("File", OPEN):
        _file(viewer)
    imgui.pop_item_width()
    imgui.end()
    return shown


def _open_if_refused(viewer: Viewer, kind: str, index: int) -> None:
    """A refused value's node opens, so its error is in sight."""
    if any(k == kind and i == index for k, i, _ in viewer.session.refused):
        imgui.set_next_item_open(True)


def _error(text: str, shown: list[str]) -> None:
    imgui.push_text_wrap_pos(0.0)
    imgui.text_colored(RED, text)
    imgui.pop_text_wrap_pos()
    shown.append(text)


def _status(viewer: Viewer, shown: list[str]) -> None:
    width, height = viewer.size
    reduced = "  (reduced)" if viewer.shown_reduced else ""
    imgui.text(f"{viewer.session.scene.source}  {width}x{height}  {viewer.pipeline}{reduced}")
    fps, frame_ms = viewer.shown_rates
    rate = f"{fps:4.0f} fps  " if viewer.running else ""
    imgui.text(f"{rate}frame {frame_ms:.1f} ms  t = {viewer.timeline.time:.3f} s")
    if viewer.render_error:
        _error(viewer.render_error, shown)
    if viewer.session.scene_error:
        _error(viewer.session.scene_error, shown)
    for note in viewer.notes[-2:]:
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(GREY, note)
        imgui.pop_text_wrap_pos()


def _timeline(viewer: Viewer) -> None:
    timeline = viewer.timeline
    if imgui.button("Pause" if timeline.playing else "Play"):
        timeline.toggle()
    imgui.same_line()
    if imgui.button("<"):
        timeline.step(-1)
    imgui.same_line()
    if imgui.button(">"):
        timeline.step(1)
    imgui.same_line()
    if imgui.button("0"):
        timeline.scrub(0.0)
    changed, value = imgui.slider_float("time", timeline.time, 0.0, timeline.duration, "%.3f s")
    if changed:
        timeline.scrub(value)
        viewer.touch()


def _combo(label: str, current: str, items: list[str]) -> tuple[bool, str]:
    index = items.index(current) if current in items else 0
    changed, index = imgui.combo(label, index, items)
    return changed, items[index]


def _pipeline(viewer: Viewer) -> None:
    changed, value = _combo("pipeline", viewer.pipeline, PIPELINES)
    if changed:
        viewer.pipeline = value
    changed, value = _combo("light path", viewer.light_path or LIGHT_PATHS[0], LIGHT_PATHS)
    if changed:
        viewer.light_path = None if value == LIGHT_PATHS[0] else value
    changed, value = _combo("view", viewer.mode, list(MODES))
    if changed:
        viewer.mode = value
    if viewer.mode != "single":
        changed, value = _combo("other side", viewer.other_pipeline, PIPELINES)
        if changed:
            viewer.other_pipeline = value
        changed, value = _combo("other light path", viewer.other_light_path or LIGHT_PATHS[0],
                                LIGHT_PATHS)
        if changed:
            viewer.other_light_path = None if value == LIGHT_PATHS[0] else value
        if viewer.mode == "split":
            _, viewer.split_at = imgui.slider_float("split", viewer.split_at, 0.0, 1.0)
        else:
            _, viewer.gain = imgui.slider_float("gain", viewer.gain, 1.0, 64.0, "%.0fx")
        if viewer.psnr is not None:
            imgui.text(f"{viewer.pipeline} vs {viewer.other_pipeline}: PSNR "
                       f"{describe(viewer.psnr)}")


def _buffer_view(viewer: Viewer) -> None:
    names = ["(final image)", *viewer.buffers]
    changed, value = _combo("buffer", viewer.view_name or names[0], names)
    if changed:
        viewer.view_name = None if value == names[0] else value
    if viewer.view_name:
        _, viewer.exposure = imgui.slider_float("exposure", viewer.exposure, -8.0, 8.0,
                                                "%.1f stops")
        channels = ["all", *viewer.view_channels]
        current = channels[0] if viewer.channel == ALL_CHANNELS else \
            channels[min(viewer.channel + 1, len(channels) - 1)]
        changed, value = _combo("channel", current, channels)
        if changed:
            viewer.channel = ALL_CHANNELS if value == "all" else channels.index(value) - 1


def _params(viewer: Viewer, kind: str, index: int, shown: list[str]) -> None:
    session = viewer.session
    for row in session.fields(kind, index):
        key = row["name"]
        value = session.value(kind, index, key)
        imgui.push_id(f"{kind}{index}.{key}")
        changed, new = _widget(key, value, row)
        if changed:
            session.edit(kind, index, key, new)
            viewer.touch()
        if imgui.is_item_hovered() and row["description"]:
            imgui.set_tooltip(f"{row['description']} ({row['type']})")
        refused = session.refused.get((kind, index, key))
        if refused is not None:
            _error(refused.error, shown)
        imgui.pop_id()


def _widget(key: str, value: Any, row: dict[str, Any]) -> tuple[bool, Any]:
    """The widget for one parameter; (changed, the value given). Ranges are shown, not
    enforced, so a value out of range reaches validation and its error shows."""
    if row["choices"]:
        items = [str(c) for c in row["choices"]]
        if str(value) in items:
            changed, chosen = _combo(key, str(value), items)
            return changed, row["choices"][items.index(chosen)]
    if isinstance(value, bool):
        return imgui.checkbox(key, value)
    if isinstance(value, int):
        return imgui.drag_int(key, value, 0.2)
    if isinstance(value, float) and math.isfinite(value):
        speed = _speed(row, value)
        return imgui.drag_float(key, value, speed, 0.0, 0.0, "%.4g")
    if isinstance(value, tuple | list) and 2 <= len(value) <= 4 and \
            all(isinstance(v, float | int) and not isinstance(v, bool) for v in value):
        # whole numbers stay whole: validation converts nothing
        if all(isinstance(v, int) for v in value):
            drag_int = {2: imgui.drag_int2, 3: imgui.drag_int3, 4: imgui.drag_int4}
            changed, out = drag_int[len(value)](key, list(value), 0.2)
            return changed, tuple(int(v) for v in out)
        values = [float(v) for v in value]
        if len(values) == 3 and any(word in key for word in COLOR_WORDS):
            changed, out = imgui.color_edit3(key, values, imgui.ColorEditFlags_.float |
                                             imgui.ColorEditFlags_.hdr)
        else:
            drag = {2: imgui.drag_float2, 3: imgui.drag_float3, 4: imgui.drag_float4}
            changed, out = drag[len(values)](key, values, _speed(row, max(values, key=abs)))
        return changed, tuple(float(v) for v in out)
    # anything else (a file name, an optional number): its TOML text, applied on Enter
    text = "" if value is None else _toml_text(value)
    changed, text = imgui.input_text(key, text, imgui.InputTextFlags_.enter_returns_true)
    if not changed:
        return False, value
    return True, _parse_toml(text)


def _speed(row: dict[str, Any], value: float) -> float:
    bounds = row["range"] or {}
    low = bounds.get("ge", bounds.get("gt"))
    high = bounds.get("le", bounds.get("lt"))
    if low is not None and high is not None and math.isfinite(high - low):
        return max((high - low) / 500.0, 1e-4)
    return max(abs(value) / 100.0, 1e-3)


def _toml_text(value: Any) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, tuple | list):
        return "[" + ", ".join(_toml_text(v) for v in value) + "]"
    return repr(value)


def _parse_toml(text: str) -> Any:
    """A value typed into a text field: empty is None (the key left out), a TOML value where
    it parses as one (numbers, booleans, arrays), else the text itself (a file name)."""
    text = text.strip()
    if not text:
        return None
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except ValueError:  # not TOML (a number of too many digits too): the text itself
        return text
    return tuple(value) if isinstance(value, list) else value


def _timings(viewer: Viewer) -> None:
    timings = viewer.timings
    if not timings:
        imgui.text_colored(GREY, "(timed on full frames)")
        return
    total = sum(timings.values())
    peak = max(timings.values()) or 1.0
    first = " (first frame: compiling included)" if viewer.timings_first else ""
    imgui.text(f"{len(timings)} passes, {total:.1f} ms{first}")
    for name, ms in timings.items():
        imgui.progress_bar(ms / peak, imgui.ImVec2(150, 0), f"{ms:.2f} ms")
        imgui.same_line()
        imgui.text(name)


def _inspector(viewer: Viewer) -> None:
    imgui.text_colored(GREY, "Ctrl+click a pixel of the frame")
    for line in viewer.inspector:
        imgui.text(line)


def _file(viewer: Viewer) -> None:
    session = viewer.session
    if imgui.button("Reset camera (R)"):
        viewer.reset_camera()
    imgui.same_line()
    changed, fly = imgui.checkbox("fly (F)", session.controller.fly)
    if changed:
        session.controller.fly = fly
    if session.path is not None:
        if imgui.button("Save (Ctrl+S)"):
            viewer.save()
        imgui.same_line()
        if imgui.button("Save with camera (C)"):
            viewer.save(camera=True)
    _, viewer.screenshot_path = imgui.input_text("##shot", viewer.screenshot_path)
    imgui.same_line()
    if imgui.button("Screenshot"):
        _guarded(viewer, lambda: viewer.screenshot())
    _, viewer.record_path = imgui.input_text("##record", viewer.record_path)
    imgui.same_line()
    if imgui.button("Stop" if viewer.recording is not None else "Record"):
        _guarded(viewer, viewer.toggle_recording)


def _guarded(viewer: Viewer, action) -> None:
    try:
        action()
    except Exception as exc:  # noqa: BLE001 - a bad path is shown, not raised
        viewer.note(f"failed: {exc}")
