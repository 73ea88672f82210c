"""Issue #22, the Python API's misuse: a renderer released twice, or used after its release; a
size or a time that is not one; registries asked from two threads at once. Each is one clear
error naming the argument, and nothing else breaks."""

from __future__ import annotations

import sys
import threading

import pytest

from deferred.errors import InputError, RenderError
from deferred.interfaces.registry import Registry
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SCENE = {"size": [32, 24], "object": [{"mesh": "builtin:sphere"}],
         "light": [{"type": "directional"}]}


def test_a_renderer_released_twice_breaks_no_later_renderer():
    """The second release used to give the context back to the pool again, which released the
    context the first release had pooled: every later Renderer() in the process then failed."""
    scene = scene_from_dict(SCENE)
    renderer = Renderer(scene)
    renderer.render()
    renderer.release()
    renderer.release()
    with Renderer(scene) as fresh:
        assert fresh.render().image.shape == (24, 32, 4)
    with pytest.raises(RenderError, match=r"^this renderer was released; make a new one$"):
        renderer.render()
    with pytest.raises(RenderError, match="released"):
        renderer.read_final()


@pytest.mark.parametrize("size", ["64x36", (64.5, 36), (64, 36, 1), (True, 36), 64, None,
                                  (0, 36), (64, 20000), (), 0])
def test_a_size_that_is_not_one_is_named(size):
    scene = scene_from_dict(SCENE)
    if size is None:  # the scene's own size is used: no error
        Renderer(scene).release()
        return
    with pytest.raises(InputError) as raised:
        Renderer(scene, size=size).release()
    message = str(raised.value)
    assert message.startswith("size: ") and "\n" not in message
    assert ("whole pixels" in message) or ("impossible" in message)


@pytest.mark.parametrize("time", [-1, -1e-9, float("nan"), float("inf"), "1", True])
def test_a_frame_time_that_is_not_one_is_named(gl, time):
    with Renderer(scene_from_dict(SCENE), gl=gl) as renderer:
        with pytest.raises(InputError, match=r"^time: frame time must be a finite number of "
                                             r"seconds >= 0, got "):
            renderer.render(time=time)
        assert renderer.render(time=0.0).image is not None  # still renders


SLOW_CATALOGUE = 'BUILTINS = {"slow": "slow_builtins.slow:Slow"}\n'
SLOW_MODULE = """
import time


class Slow:
    name = "slow"


time.sleep(0.3)  # a module that takes a while to import, as the built-ins do the first time
"""


def test_a_numpy_size_is_a_size():
    import numpy as np

    with Renderer(scene_from_dict(SCENE), size=np.array([40, 20])) as renderer:
        assert renderer.size == (40, 20) and renderer.render().image.shape == (20, 40, 4)


def test_two_threads_asking_a_registry_first_both_find_its_builtins(tmp_path, monkeypatch):
    """The first ask imports the built-in; a second thread asking meanwhile waits for it (it
    used to find the built-ins marked loaded and half empty: "unknown material 'standard'"),
    and the class is registered once, with the catalogue's id."""
    (tmp_path / "slow_builtins").mkdir()
    (tmp_path / "slow_builtins" / "__init__.py").write_text(SLOW_CATALOGUE)
    (tmp_path / "slow_builtins" / "slow.py").write_text(SLOW_MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    registry = Registry("thing", "deferred.test_things", "slow_builtins")
    found, errors = [], []

    def ask() -> None:
        try:
            found.append(registry.get("slow"))
        except Exception as exc:  # noqa: BLE001 - collected for the assertion
            errors.append(exc)

    threads = [threading.Thread(target=ask) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    monkeypatch.delitem(sys.modules, "slow_builtins.slow")
    monkeypatch.delitem(sys.modules, "slow_builtins")
    assert errors == [] and len(found) == 4 and len(set(found)) == 1
    assert found[0].name == "slow" and found[0].type_id == 1


def test_non_finite_vertex_colours_are_refused():
    import numpy as np

    from deferred.scene.geometry import build_mesh

    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    colours = np.full((3, 4), 0.5)
    colours[1, 0] = np.nan
    with pytest.raises(InputError, match=r"^tri: mesh has non-finite vertex colours"):
        build_mesh("tri", positions, np.array([[0, 1, 2]]), colors=colours)
