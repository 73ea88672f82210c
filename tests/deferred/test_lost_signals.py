"""Issue #22: a signal whose exception is lost still ends the command with 128 + its number and
no output. Python swallows an exception raised inside a ``__del__`` ("Exception ignored in
..."), and so do libraries that catch BaseException; a SIGTERM landing in a moderngl
``__del__`` let a dump carry on and exit 0."""

from __future__ import annotations

import os
import signal

import pytest

import deferred.render.renderer as renderer_module
from deferred.cli import main


class SignalsInItsDel:
    """Sends the process a signal from its ``__del__``: the handler's exception is lost."""

    def __init__(self, signum: int):
        self.signum = signum

    def __del__(self):
        os.kill(os.getpid(), self.signum)


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # the lost ones
@pytest.mark.parametrize("signum, code, word", [(signal.SIGTERM, 143, "terminated"),
                                                (signal.SIGINT, 130, "interrupted")])
@pytest.mark.parametrize("command", ["render", "dump"])
def test_a_signal_lost_in_a_del_still_stops_the_command_without_output(
        tmp_path, capfd, monkeypatch, signum, code, word, command):
    real = renderer_module.Renderer.render

    def render(self, *args, **kwargs):
        result = real(self, *args, **kwargs)
        SignalsInItsDel(signum)  # made and collected at once: the signal lands in __del__
        return result

    monkeypatch.setattr(renderer_module.Renderer, "render", render)
    out = tmp_path / ("out.png" if command == "render" else "dump")
    assert main([command, "-o", str(out), "--size", "32x18"]) == code
    err = capfd.readouterr().err
    assert err.strip().splitlines()[-1] == word, err
    assert not out.exists() and list(tmp_path.iterdir()) == []
