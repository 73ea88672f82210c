"""``deferred view`` where no window can open: exit 2 and one line naming --headless and Xvfb,
no raw backend warning."""

from __future__ import annotations

import sys

import pytest
from command_line import assert_one_line_error, run

pytest.importorskip("moderngl_window")
pytest.importorskip("imgui_bundle")

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="DISPLAY is an X11 / Wayland variable")


def test_no_display_is_an_environment_error_naming_headless(monkeypatch, capfd):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv("DEFERRED_VIEW_WINDOW", raising=False)
    code, _, err = run(capfd, "view")
    assert_one_line_error(code, err, "no display", "--headless", "Xvfb")
    assert "b'" not in err and "render failed" not in err


def test_a_display_that_does_not_answer_is_said_in_one_line(monkeypatch, capfd):
    pytest.importorskip("glfw")
    monkeypatch.setenv("DISPLAY", ":77")  # no X server listens there
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv("DEFERRED_VIEW_WINDOW", raising=False)
    code, _, err = run(capfd, "view")
    assert_one_line_error(code, err, "cannot open a glfw window (X11: Failed to open display :77)",
                          "--headless", "Xvfb")
    assert "b'" not in err
