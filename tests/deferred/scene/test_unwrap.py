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


def _killed(positions, indices):
    os.kill(os.getpid(), signal.SIGKILL)  # the OOM killer


def _segfault(positions, indices):
    os.kill(os.getpid(), signal.SIGSEGV)  # what xatlas does on some meshes


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


@pytest.mark.parametrize("child, fragment", [
    (_killed, "was killed by SIGKILL (signal 9): out of memory?"),
    (_raise, "ValueError: xatlas said no")])
def test_unwrap_failures_name_the_mesh(tmp_path, monkeypatch, child, fragment):
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    monkeypatch.setattr(deferred.scene.unwrap, "_xatlas_parametrize", child)
    with pytest.raises(InputError, match="UV unwrap failed") as caught:
        load_mesh("tet.obj", tmp_path)
    assert fragment in str(caught.value) and "tet.obj" in str(caught.value)


def test_a_crash_of_the_unwrap_is_said_and_each_triangle_gets_a_chart(tmp_path, monkeypatch):
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    monkeypatch.setattr(deferred.scene.unwrap, "_xatlas_parametrize", _segfault)
    with pytest.warns(deferred.scene.unwrap.UnwrapWarning,
                      match="tet.obj: xatlas crashed unwrapping the mesh, SIGSEGV \\(signal 11\\); "
                            "each triangle is a UV chart of its own"):
        mesh = load_mesh("tet.obj", tmp_path)
    assert_charts_apart(mesh)


def assert_charts_apart(mesh):
    """UVs in [0, 1], every triangle its own vertices, no two triangles' UV boxes overlapping."""
    uvs = np.asarray(mesh.uvs, np.float64)
    faces = np.asarray(mesh.indices, np.int64).reshape(-1, 3)
    assert np.isfinite(uvs).all() and uvs.min() >= 0.0 and uvs.max() <= 1.0
    assert len(np.unique(faces)) == faces.size
    boxes = uvs[faces]
    low, high = boxes.min(axis=1), boxes.max(axis=1)
    order = np.argsort(low[:, 0])
    for a, i in enumerate(order):  # a sweep along u
        for j in order[a + 1:]:
            if low[j, 0] >= high[i, 0]:
                break
            assert not (low[j, 1] < high[i, 1] and low[i, 1] < high[j, 1]), (i, j)


def test_the_icosphere_xatlas_crashes_on_renders(tmp_path, capfd):
    """The exact icosphere of 81,920 triangles, without UVs, crashed xatlas (SIGSEGV) and was
    said as "out of memory?": it renders, each triangle a chart (or xatlas' charts, should a
    later xatlas unwrap it)."""
    trimesh = pytest.importorskip("trimesh")
    sphere = trimesh.creation.icosphere(subdivisions=6)
    assert len(sphere.faces) == 81_920
    (tmp_path / "ico.obj").write_text(trimesh.exchange.obj.export_obj(
        sphere, include_normals=False, include_texture=False))
    code, err, out = render_scene(tmp_path, capfd, {"mesh": "ico.obj", "material": "standard"})
    assert code == 0 and out.exists(), err
    assert "out of memory" not in err
    for line in err.strip().splitlines()[:-1]:
        assert line.startswith("warning: ico.obj: xatlas crashed unwrapping the mesh, SIGSEGV")


def test_triangle_charts_of_many_triangles_are_apart():
    trimesh = pytest.importorskip("trimesh")
    sphere = trimesh.creation.icosphere(subdivisions=3)
    vmapping, indices, uvs = deferred.scene.unwrap.triangle_charts(
        np.asarray(sphere.vertices), np.asarray(sphere.faces))

    class Unwrapped:
        pass

    mesh = Unwrapped()
    mesh.uvs, mesh.indices = uvs, indices
    assert_charts_apart(mesh)
    np.testing.assert_array_equal(vmapping.reshape(-1, 3), sphere.faces)
    # one scale for every chart: a triangle's UV edge lengths over its own are the same
    corners = np.asarray(sphere.vertices)[sphere.faces]
    flat = uvs[indices]
    ratio = np.linalg.norm(flat[:, 1] - flat[:, 0], axis=1) / \
        np.linalg.norm(corners[:, 1] - corners[:, 0], axis=1)
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-9)


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
