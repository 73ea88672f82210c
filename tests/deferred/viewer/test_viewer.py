"""``deferred view`` under moderngl-window's headless window: synthetic mouse and key events,
parameter edits, hot reload of files changed on disk, and frames compared with what
``deferred render`` draws for the same camera, time and parameters."""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import psnr
from locations import ROOT

pytest.importorskip("moderngl_window")
pytest.importorskip("imgui_bundle")

from deferred.cli import main  # noqa: E402
from deferred.io.images import read_image  # noqa: E402
from deferred.render.renderer import Renderer  # noqa: E402
from deferred.scene.loader import load_scene  # noqa: E402

SIZE = (160, 120)
SCENE = """# a scene for the viewer's tests
size = [160, 120]
[camera]
position = [0.0, 1.2, 3.5]
target = [0.0, 0.4, 0.0]
fov = 40.0

[[object]]
name = "floor"
mesh = "builtin:plane"
scale = 6.0
[object.params]
color = [0.5, 0.5, 0.45]  # grey

[[object]]
name = "ball"
mesh = "builtin:sphere"
position = [0.0, 0.5, 0.0]
scale = 0.5
[object.params]
color = [0.8, 0.3, 0.2]
specular_exponent = 32.0

[[light]]
type = "directional"
direction = [-0.5, -1.0, -0.4]
intensity = 1.2

[[light]]
type = "ambient"
color = [0.2, 0.2, 0.25]

[[track]]
target = "object:ball"
keys = [{time = 0.0, position = [0.0, 0.5, 0.0]}, {time = 1.0, position = [0.8, 0.5, 0.0]}]
"""


@pytest.fixture
def scene_file(tmp_path: Path) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(SCENE)
    return path


@pytest.fixture
def make_viewer(gl):
    from deferred.viewer.app import Viewer, ViewerOptions
    from deferred.viewer.session import Session
    from deferred.viewer.window import make_window, window_size

    made = []

    def _make(path, **options):
        session = Session(path)
        window = make_window(window_size(SIZE), headless=True)
        viewer = Viewer(session, window, ViewerOptions(**options))
        made.append((viewer, window))
        return viewer

    yield _make
    for viewer, window in made:
        viewer.close()
        window.destroy()
    gl.make_current()


def rendered(path: Path, time: float = 0.0, gl=None, pipeline: str = "deferred") -> np.ndarray:
    with Renderer(load_scene(path), pipeline, gl=gl) as renderer:
        return renderer.render(time=time).image


def shown(viewer) -> np.ndarray:
    viewer.update(force_full=True)
    return viewer.viewport_image()


def test_orbit_changes_the_view_and_reset_restores_it(scene_file, make_viewer):
    viewer = make_viewer(scene_file)
    before = shown(viewer)
    x, y = 400 + 80, 60  # the middle of the viewport (right of the panels)
    viewer.input.mouse_press(x, y, 1)
    viewer.input.mouse_drag(x + 40, y + 10, 40, 10)
    viewer.input.mouse_release(x + 40, y + 10, 1)
    orbited = shown(viewer)
    assert np.abs(orbited.astype(int) - before).mean() > 2.0
    viewer.input.mouse_scroll(0, 2)  # zoom in
    assert np.abs(shown(viewer).astype(int) - orbited).mean() > 2.0
    viewer.input.shortcut(viewer.input.keys.R)
    np.testing.assert_array_equal(shown(viewer), before)


def test_keys(scene_file, make_viewer, tmp_path):
    from moderngl_window.context.base import KeyModifiers

    viewer = make_viewer(scene_file)
    keys, plain, ctrl = viewer.input.keys, KeyModifiers(), KeyModifiers()
    ctrl.ctrl = True
    home = shown(viewer)

    def press(key, modifiers=plain):
        viewer.input.key_event(key, keys.ACTION_PRESS, modifiers)
        viewer.input.key_event(key, keys.ACTION_RELEASE, modifiers)

    press(keys.SPACE)
    assert viewer.timeline.playing
    press(keys.SPACE)
    press(keys.RIGHT)
    press(keys.RIGHT)
    assert viewer.timeline.time == pytest.approx(2 / 24)
    press(keys.HOME)
    press(keys.TAB)
    assert viewer.mode == "split"
    press(keys.TAB)
    press(keys.TAB)
    assert viewer.mode == "single"
    press(keys.F)  # fly: W moves the eye and the target forward
    viewer.input.key_event(keys.W, keys.ACTION_PRESS, plain)
    viewer.input.fly(0.1)
    viewer.input.key_event(keys.W, keys.ACTION_RELEASE, plain)
    assert np.abs(shown(viewer).astype(int) - home).mean() > 1.0
    press(keys.R)
    np.testing.assert_array_equal(shown(viewer), home)
    viewer.session.edit("object", 1, "specular_exponent", 12.0)
    press(keys.S, ctrl)
    assert "specular_exponent = 12.0" in scene_file.read_text()
    assert "# grey" in scene_file.read_text()


def test_the_viewport_is_the_frame_render_draws_for_the_same_camera(scene_file, make_viewer,
                                                                     tmp_path, gl):
    viewer = make_viewer(scene_file)
    viewer.input.mouse_press(480, 60, 1)
    viewer.input.mouse_drag(455, 50, -25, -10)
    viewer.input.mouse_release(455, 50, 1)
    viewer.input.mouse_press(480, 60, 2)  # pan
    viewer.input.mouse_drag(485, 58, 5, -2)
    viewer.input.mouse_release(485, 58, 2)
    image = shown(viewer)
    moved = tmp_path / "moved.toml"
    viewer.session.save(moved, camera=True)
    assert "# a scene for the viewer's tests" in moved.read_text()  # comments kept
    out = tmp_path / "render.png"
    assert main(["render", str(moved), "-o", str(out)]) == 0
    expected = np.rint(read_image(out) * 255).astype(np.uint8)
    np.testing.assert_array_equal(image[..., :3], expected[..., :3])


def test_headless_screenshot_holds_the_panels_and_the_frame(scene_file, tmp_path):
    out = tmp_path / "window.png"
    assert main(["view", str(scene_file), "--headless", "--screenshot", str(out),
                 "--time", "0.5"]) == 0
    window = np.rint(read_image(out) * 255).astype(np.uint8)
    assert window.shape[:2] == (640, 400 + SIZE[0])
    frame = tmp_path / "frame.png"
    assert main(["render", str(scene_file), "-o", str(frame), "--time", "0.5"]) == 0
    expected = np.rint(read_image(frame) * 255).astype(np.uint8)
    np.testing.assert_array_equal(window[:SIZE[1], 400:, :3], expected[..., :3])
    panel = window[:, :400, :3].astype(int)
    assert panel.std() > 10  # the panels drew text and widgets


def test_headless_screenshot_of_a_buffer_view_is_render_view(scene_file, tmp_path):
    out = tmp_path / "window.png"
    assert main(["view", str(scene_file), "--headless", "--screenshot", str(out),
                 "--view", "normal"]) == 0
    frame = tmp_path / "normal.png"
    assert main(["render", str(scene_file), "-o", str(frame), "--view", "normal"]) == 0
    window = np.rint(read_image(out) * 255).astype(np.uint8)
    expected = np.rint(read_image(frame) * 255).astype(np.uint8)
    np.testing.assert_array_equal(window[:SIZE[1], 400:, :3], expected[..., :3])


def test_bad_view_options_are_one_line_errors(scene_file, tmp_path, capsys):
    assert main(["view", str(scene_file), "--headless"]) == 2
    assert main(["view", str(scene_file), "--headless", "--screenshot",
                 str(tmp_path / "a.png"), "--view", "nothing"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == "error: --view: unknown view 'nothing' (see --view help)"
    assert not (tmp_path / "a.png").exists()


def test_a_parameter_edit_equals_rendering_the_edited_scene_file(scene_file, make_viewer,
                                                                 tmp_path, gl):
    viewer = make_viewer(scene_file)
    before = shown(viewer)
    assert viewer.session.edit("object", 1, "color", (0.2, 0.5, 0.9)) is None
    assert viewer.session.edit("object", 1, "specular_exponent", 8.0) is None
    assert viewer.session.edit("light", 0, "intensity", 2.0) is None
    after = shown(viewer)
    assert np.abs(after.astype(int) - before).mean() > 1.0
    edited = tmp_path / "edited.toml"
    viewer.session.save(edited)
    text = edited.read_text()
    assert "# grey" in text and "specular_exponent = 8.0" in text
    assert psnr(after[..., :3], rendered(edited, gl=gl)[..., :3], 255.0) >= 50.0


def test_an_invalid_edit_shows_its_error_and_keeps_the_last_good_frame(scene_file,
                                                                       make_viewer):
    viewer = make_viewer(scene_file)
    good = shown(viewer)
    error = viewer.session.edit("object", 1, "specular_exponent", -5.0)
    assert error is not None and "params.specular_exponent" in error
    assert viewer.session.value("object", 1, "specular_exponent") == -5.0  # shown as typed
    np.testing.assert_array_equal(shown(viewer), good)
    viewer.draw()  # the object's node opens to show it
    assert viewer.session.errors() == [error]
    assert error in viewer.panel_errors
    assert viewer.session.edit("object", 1, "specular_exponent", 16.0) is None
    assert viewer.session.errors() == []


def test_a_failing_panel_is_noted_and_the_next_frame_draws(scene_file, make_viewer,
                                                            monkeypatch):
    from deferred.viewer import panels

    viewer = make_viewer(scene_file)
    shown(viewer)

    def broken(viewer):
        raise ValueError("broken panel")

    monkeypatch.setattr(panels, "_timeline", broken)
    viewer.draw()  # the panel window is left open part way: imgui closes it
    assert viewer.notes[-1] == "panel failed: ValueError: broken panel"
    monkeypatch.undo()
    viewer.draw()
    assert viewer.window_image()[:, :400].std() > 10


def test_scrubbing_to_t_equals_render_at_t(scene_file, make_viewer, gl):
    viewer = make_viewer(scene_file)
    start = shown(viewer)
    viewer.timeline.scrub(0.75)
    scrubbed = shown(viewer)
    assert np.abs(scrubbed.astype(int) - start).mean() > 1.0
    np.testing.assert_array_equal(scrubbed, rendered(scene_file, 0.75, gl))
    viewer.timeline.step(-6)  # 6 frames at 24 fps back: 0.5 s
    np.testing.assert_array_equal(shown(viewer), rendered(scene_file, 0.5, gl))


@pytest.mark.slow
def test_scrubbing_back_through_a_simulation_equals_render_at_t(make_viewer, gl):
    scene = ROOT / "examples" / "shell_fur" / "wet_wind.toml"
    viewer = make_viewer(scene, size=SIZE)
    viewer.timeline.scrub(1.5)
    viewer.update(force_full=True)
    viewer.timeline.scrub(0.75)  # back: the strands and the drying start again from 0
    scrubbed = shown(viewer)
    with Renderer(load_scene(scene), size=SIZE, gl=gl) as renderer:
        np.testing.assert_array_equal(scrubbed, renderer.render(time=0.75).image)


def test_split_and_difference_views_report_psnr(scene_file, make_viewer, gl):
    viewer = make_viewer(scene_file, split="forward")
    split = shown(viewer)
    assert viewer.psnr is not None and viewer.psnr >= 40.0  # standard material: they agree
    deferred_image = rendered(scene_file, gl=gl)
    np.testing.assert_array_equal(split, deferred_image)  # the slot holds the left side
    viewer.draw()
    window = viewer.window_image()[:SIZE[1], 400:400 + SIZE[0]]
    half = SIZE[0] // 2
    np.testing.assert_array_equal(window[:, : half - 1], deferred_image[:, : half - 1, :3])
    forward_image = rendered(scene_file, gl=gl, pipeline="forward")
    np.testing.assert_array_equal(window[:, half + 2:], forward_image[:, half + 2:, :3])
    viewer.mode = "difference"
    viewer.update(force_full=True)
    viewer.draw()
    difference = viewer.window_image()[:SIZE[1], 400:400 + SIZE[0]].astype(int)
    expected = np.minimum(np.abs(deferred_image[..., :3].astype(int) - forward_image[..., :3])
                          * 4, 255)
    assert np.abs(difference - expected).max() <= 2


def test_interaction_draws_reduced_frames_and_refines_when_idle(scene_file, make_viewer):
    from deferred.viewer.app import INTERACTION_SECONDS

    viewer = make_viewer(scene_file, reduce=2)
    now = [100.0]
    viewer.now = lambda: now[0]  # the viewer's clock, not the wall's
    shown(viewer)
    viewer.input.mouse_press(480, 60, 1)
    viewer.input.mouse_drag(490, 60, 10, 0)
    assert viewer.last_input == 100.0
    assert viewer.update()
    assert viewer.shown_reduced and viewer.main.texture.size == (80, 60)
    now[0] += INTERACTION_SECONDS / 2  # input still recent: the reduced frame stands
    assert not viewer.update()
    now[0] += INTERACTION_SECONDS  # input stopped
    assert viewer.update()
    assert not viewer.shown_reduced and viewer.main.texture.size == SIZE


TAA_SCENE = SCENE + '\n[[effect]]\ntype = "taa"\nstill_samples = 4\n'


def test_playing_steps_whole_frames_and_taa_keeps_its_history(tmp_path, make_viewer):
    """Playing, the clock moves by whole frames (1 / fps) whatever the window's frame times,
    and taa's history carries on from frame to frame (no restart each frame)."""
    path = tmp_path / "taa.toml"
    path.write_text(TAA_SCENE)
    viewer = make_viewer(path)
    now = [100.0]
    viewer.now = lambda: now[0]
    viewer._last_tick = now[0]
    shown(viewer)
    viewer.timeline.toggle()
    wall, times = 0.0, []
    for seconds in (0.03, 0.02, 0.05, 0.035, 0.09, 0.045):
        now[0] += seconds
        wall += seconds
        viewer.tick()
        frames = viewer.timeline.time * viewer.timeline.fps
        assert frames == pytest.approx(round(frames), abs=1e-9)  # a whole frame
        assert round(frames) == int(wall * viewer.timeline.fps + 1e-9)
        times.append(viewer.timeline.time)
        if viewer.timeline.time > 0.0:  # a frame after the first
            assert viewer.full_renderer().last_frame.history_kept
    assert len(set(times)) > 3  # it played


def test_a_still_camera_with_taa_draws_until_its_samples_are_in_then_stops(scene_file, tmp_path,
                                                                          make_viewer):
    """Nothing changing, the viewer draws again while taa's history has fewer than
    still_samples (4) frames, then draws nothing more; without taa it draws nothing more."""
    path = tmp_path / "taa.toml"
    path.write_text(TAA_SCENE)
    viewer = make_viewer(path)
    first = shown(viewer)
    drawn = 0
    while viewer.update() and drawn < 10:
        drawn += 1
    assert drawn == 3
    assert viewer.full_renderer().last_frame.sample_index == 3
    assert not np.array_equal(viewer.viewport_image(), first)  # samples accumulated
    assert not viewer.update()
    viewer.timeline.step()  # a new frame: the history continues, drawn again to converge
    assert viewer.update()
    plain = make_viewer(scene_file)
    shown(plain)
    assert not plain.update()


def test_pixel_inspector_lists_the_passes_of_a_clicked_pixel(scene_file, make_viewer):
    viewer = make_viewer(scene_file)
    shown(viewer)
    viewer.input.mouse_press(400 + 80, 60, 1, ctrl=True)  # the ball
    assert viewer.inspector[0].startswith("pixel 80,60 (top-down) of 160x120")
    assert any("ball.gbuffer" in line for line in viewer.inspector)


def test_scene_file_reload_and_error(scene_file, make_viewer):
    viewer = make_viewer(scene_file)
    good = shown(viewer)
    text = scene_file.read_text()
    scene_file.write_text(text.replace("specular_exponent = 32.0", "specular_exponent = -1.0"))
    _bump(scene_file)
    viewer.poll_files(force=True)
    assert "object[1].params.specular_exponent" in viewer.session.scene_error
    np.testing.assert_array_equal(shown(viewer), good)
    scene_file.write_text(text.replace("[0.8, 0.3, 0.2]", "[0.1, 0.8, 0.2]"))
    _bump(scene_file)
    viewer.poll_files(force=True)
    assert viewer.session.scene_error is None
    assert np.abs(shown(viewer).astype(int) - good).mean() > 1.0


def _bump(path: Path) -> None:
    stamp = time.time() + 5.0
    os.utime(path, (stamp, stamp))


@pytest.fixture
def checker_plugin(tmp_path):
    """A material whose GLSL root is a copy the test may edit."""
    from plugin_material import CheckerMaterial

    from deferred.interfaces import registry

    root = tmp_path / "glsl"
    shutil.copytree(Path(CheckerMaterial.shader_root), root)
    material = type("EditableChecker", (CheckerMaterial,),
                    {"name": "test_checker", "shader_root": root})
    registry.materials.register(material)
    yield root / "materials" / "test_checker" / "surface.glsl"
    registry.materials.unregister("test_checker")


def test_a_glsl_edit_with_an_error_shows_file_and_line_and_recovers(tmp_path, make_viewer,
                                                                    checker_plugin):
    scene = tmp_path / "checker.toml"
    scene.write_text(SCENE.replace('name = "ball"\nmesh = "builtin:sphere"',
                                   'name = "ball"\nmesh = "builtin:sphere"\n'
                                   'material = "test_checker"')
                     .replace("color = [0.8, 0.3, 0.2]\nspecular_exponent = 32.0",
                              "squares = 4"))
    viewer = make_viewer(scene)
    good = shown(viewer)
    source = checker_plugin.read_text()
    lines = source.splitlines()
    broken_line = next(i for i, line in enumerate(lines) if "s.specular_intensity" in line)
    lines[broken_line] = "    s.specular_intensity = 0.0 +;"
    checker_plugin.write_text("\n".join(lines) + "\n")
    _bump(checker_plugin)
    viewer.poll_files(force=True)
    assert not shown(viewer).size == 0
    assert viewer.render_error is not None
    assert f"materials/test_checker/surface.glsl:{broken_line + 1}" in viewer.render_error
    np.testing.assert_array_equal(viewer.viewport_image(), good)
    viewer.draw()
    assert viewer.render_error in viewer.panel_errors
    checker_plugin.write_text(source)
    _bump(checker_plugin)
    viewer.poll_files(force=True)
    np.testing.assert_array_equal(shown(viewer), good)
    assert viewer.render_error is None


def test_screenshot_and_recording(scene_file, make_viewer, tmp_path):
    viewer = make_viewer(scene_file)
    image = shown(viewer)
    written = viewer.screenshot(tmp_path / "shot.png")
    np.testing.assert_array_equal(np.rint(read_image(written) * 255).astype(np.uint8)[..., :3],
                                  image[..., :3])
    viewer.toggle_recording(str(tmp_path / "clip.gif"))
    for _ in range(3):
        viewer.timeline.advance(1 / 24)
        viewer.update(force_full=True)
    viewer.toggle_recording()
    from PIL import Image

    with Image.open(tmp_path / "clip.gif") as gif:
        assert gif.n_frames == 3


REAL_WINDOW = """
import sys
from deferred.viewer.app import Viewer, ViewerOptions
from deferred.viewer.window import make_window, window_size
from deferred.viewer.session import Session
size = (160, 120)
try:
    window = make_window(window_size(size), headless=False)
except RuntimeError as exc:
    print(f"no window: {exc}")
    sys.exit(3)
viewer = Viewer(Session(sys.argv[1]), window, ViewerOptions())
viewer.update(force_full=True)
viewer.draw()
image = viewer.window_image()
assert image[:120, 400:].std() > 5, "an empty frame"
window.swap_buffers()
viewer.input.mouse_press(480, 60, 1)
viewer.input.mouse_drag(500, 60, 20, 0)  # a reduced frame: another renderer after a draw
viewer.input.mouse_release(500, 60, 1)
assert viewer.update() and viewer.shown_reduced
assert viewer.render_error is None, viewer.render_error
viewer.draw()
assert viewer.ctx.error == "GL_NO_ERROR"
viewer.screenshot(sys.argv[2], window=True)
viewer.close()
window.destroy()
"""


def test_real_window_under_xvfb(scene_file, tmp_path):
    """One real (glfw) window, where a display is there (CI runs the tests under Xvfb where
    it installs). In a process of its own: Mesa refuses a GLX context in a process that holds
    EGL ones (the tests' context), as ``deferred view`` never does."""
    import subprocess
    import sys

    if not os.environ.get("DISPLAY"):
        pytest.skip("no X display (run under xvfb-run to open a real window)")
    out = tmp_path / "window.png"
    done = subprocess.run([sys.executable, "-c", REAL_WINDOW, str(scene_file), str(out)],
                          capture_output=True, text=True, timeout=300)
    if done.returncode == 3:
        pytest.skip(done.stdout.strip())
    assert done.returncode == 0, done.stderr[-3000:]
    window = np.rint(read_image(out) * 255).astype(np.uint8)
    assert window.shape[:2] == (640, 560)
    assert window[:SIZE[1], 400:].std() > 5


def test_unchanged_panels_are_copied_not_drawn_again(scene_file, make_viewer, monkeypatch):
    """The panels' layer (deferred.viewer.imgui_gl.PanelLayer): the window is the same image
    whether the panels are drawn or copied from the last drawing; an edit the panels show
    draws them again."""
    from deferred.viewer import app

    viewer = make_viewer(scene_file)
    viewer.update(force_full=True)
    viewer.draw()
    viewer.draw()  # imgui settles its layout over the first frames
    drawn = viewer.panel_layer.drawn
    viewer.draw()
    assert viewer.panel_layer.drawn == drawn  # nothing changed: copied
    copied = viewer.window_image()
    # the same window, imgui's triangles drawn straight into it
    monkeypatch.setattr(app.PanelLayer, "draw", lambda self, *args: False)
    viewer.draw()
    np.testing.assert_array_equal(viewer.window_image(), copied)
    monkeypatch.undo()
    viewer.timeline.scrub(0.5)  # the panel's time changes
    viewer.update(force_full=True)
    viewer.draw()
    assert viewer.panel_layer.drawn == drawn + 1
    assert not np.array_equal(viewer.window_image()[:, :400], copied[:, :400])
