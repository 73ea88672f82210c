"""Shared fixtures: one headless GL context for the session, helpers to render small scenes."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

TESTS = Path(__file__).parent
sys.path.insert(0, str(TESTS / "fixtures"))


@pytest.fixture(scope="session")
def gl():
    from deferred.errors import RenderError
    from deferred.gl.context import create_context

    try:
        context = create_context()
    except RenderError as exc:
        pytest.skip(f"no headless GL context: {exc}")
    yield context
    context.release()


@pytest.fixture
def render(gl):
    """render(scene, pipeline='deferred', size=None, light_path=None) -> (RenderResult, Renderer)
    released later."""
    from deferred.render.renderer import Renderer

    made = []

    def _render(scene, pipeline="deferred", size=None, light_path=None, **kwargs):
        renderer = Renderer(scene, pipeline, size, gl=gl, light_path=light_path)
        made.append(renderer)
        kwargs.setdefault("hdr", kwargs.get("readback", True))  # tests compare it later
        return renderer.render(**kwargs), renderer

    yield _render
    for renderer in made:
        renderer.release()


def psnr(a: np.ndarray, b: np.ndarray, peak: float = 1.0) -> float:
    mse = float(np.mean((np.asarray(a, np.float64) - np.asarray(b, np.float64)) ** 2))
    return float("inf") if mse == 0.0 else 10.0 * np.log10(peak * peak / mse)


def pytest_configure(config):
    os.environ.setdefault("DEFERRED_GL_BACKEND", "egl")
    # The tests run strict: a uniform set by name that no program declares is an error.
    os.environ.setdefault("DEFERRED_STRICT", "1")


@pytest.fixture(scope="module")
def local_ray():
    """A local Ray instance of two CPUs for the tests of a module that ask for it (``--ray``,
    the ray extra; skipped without it), stopped after them: its processes do not load the
    tests after. Here, not in a conftest of the farm tests' own: a second module named
    conftest would shadow this one for the test modules that import ``psnr`` from it."""
    import signal

    ray = pytest.importorskip("ray")
    handlers = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield ray
    ray.shutdown()
    for signum, handler in handlers.items():  # ray.init made SIGTERM a sys.exit
        signal.signal(signum, handler)
