"""The UV unwrap of a mesh without UVs (deferred.scene.unwrap): its child process is bounded in
time, stops on Ctrl-C, and its failures name the mesh; a sliver beside good triangles gets
finite UVs."""

import multiprocessing
import os
import signal
import threading
import time

import numpy as np
import pytest
from command_line import assert_one_line_error, render_scene

import deferred.scene.meshes
import deferred.scene.unwrap
from deferred.errors import InputError
from deferred.scene.meshes import load_mesh

TETRAHEDRON = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


# -- the unwrap's child process -------------------------------------------------------------------

def _sleep_for_ever(positions, indices):
    time.sleep(3600)  # xatlas lost in a bad mesh: only ending the process stops it


def _crash(positions, indices):
    os.kill(os.getpid(), signal.SIGKILL)  # a segfault or the OOM killer


def _raise(positions, indices):
    raise ValueError("xatlas said no")


def test_unwrap_time_limit(tmp_path, capfd, monkeypatch):
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    # the fork copies the patched module
    monkeypatch.setattr(deferred.scene.unwrap, "_xatlas_parametrize", _sleep_for_ever)
    monkeypatch.setenv("DEFERRED_UNWRAP_TIMEOUT", "0.3")
    start = time.monotonic()
    code, err, out = render_scene(tmp_path, capfd, {"mesh": "tet.obj", "material": "standard"})
    assert time.monotonic() - start < 10.0
    assert_one_line_error(code, err, "object[0].mesh", "tet.obj",
                          "UV unwrap did not finish in 0.3 s; give the mesh UVs or simplify it")
    assert not out.exists()
    assert multiprocessing.active_children() == []


def test_an_unwrap_ended_before_it_set_its_signals_up_prints_nothing(tmp_path, capfd,
                                                                      monkeypatch):
    """DEFERRED_UNWRAP_TIMEOUT=1e-9 printed the child's traceback now and then: a child ended
    before it set its own signal handlers ran the parent's SIGTERM handler. Here the child
    waits before setting them up, every time: the error is still one line."""
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    real_child = deferred.scene.unwrap._unwrap_child

    def slow_to_start(*args):
        time.sleep(2.0)
        real_child(*args)

    monkeypatch.setattr(deferred.scene.unwrap, "_unwrap_child", slow_to_start)
    monkeypatch.setenv("DEFERRED_UNWRAP_TIMEOUT", "0.2")
    code, err, out = render_scene(tmp_path, capfd, {"mesh": "tet.obj", "material": "standard"})
    assert_one_line_error(code, err, "object[0].mesh", "tet.obj",
                          "UV unwrap did not finish in 0.2 s; give the mesh UVs or simplify it")
    assert multiprocessing.active_children() == []


def test_ctrl_c_ends_the_unwrap(tmp_path, monkeypatch):
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    monkeypatch.setattr(deferred.scene.unwrap, "_xatlas_parametrize", _sleep_for_ever)
    main_thread = threading.main_thread().ident
    timer = threading.Timer(0.3, signal.pthread_kill, (main_thread, signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            load_mesh("tet.obj", tmp_path)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 5.0
    assert multiprocessing.active_children() == []


@pytest.mark.parametrize("child, fragment", [(_crash, "died (signal 9"),
                                             (_raise, "ValueError: xatlas said no")])
def test_unwrap_failures_name_the_mesh(tmp_path, monkeypatch, child, fragment):
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    monkeypatch.setattr(deferred.scene.unwrap, "_xatlas_parametrize", child)
    with pytest.raises(InputError, match="UV unwrap failed") as caught:
        load_mesh("tet.obj", tmp_path)
    assert fragment in str(caught.value) and "tet.obj" in str(caught.value)


@pytest.mark.parametrize("value", ["soon", "0", "-1", "nan"])
def test_bad_unwrap_timeout_is_named(tmp_path, monkeypatch, value):
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    monkeypatch.setenv("DEFERRED_UNWRAP_TIMEOUT", value)
    with pytest.raises(InputError, match="DEFERRED_UNWRAP_TIMEOUT must be a number"):
        load_mesh("tet.obj", tmp_path)


def test_a_triangle_too_thin_to_unwrap_beside_good_ones_gets_finite_uvs(tmp_path):
    """A triangle thinner than float32 resolves, alone, is a degenerate mesh to the unwrap (the
    thin.obj case); beside a triangle it charts, the mesh loads with finite UVs everywhere."""
    from deferred.scene.meshes import load_mesh

    path = tmp_path / "sliver.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e-12\nf 1 2 3\nf 4 3 1\n")
    mesh = load_mesh(str(path))
    assert np.isfinite(mesh.uvs).all()
    assert np.ptp(mesh.uvs, axis=0).min() > 0.1  # the good triangle is charted
