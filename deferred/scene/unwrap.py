"""UVs for a mesh that has none: an xatlas unwrap in a child process with a time limit
(``UNWRAP_TIMEOUT_S``, environment variable ``DEFERRED_UNWRAP_TIMEOUT``), so a mesh that defeats
xatlas is an error after that time and Ctrl-C stops it (inside xatlas, the interpreter never sees
the signal).
"""
from __future__ import annotations

import math
import multiprocessing
import os
import signal
import sys
import time
import warnings

import numpy as np

from deferred.errors import InputError

UNWRAP_TIMEOUT_S = 60.0
UNWRAP_TIMEOUT_ENV = "DEFERRED_UNWRAP_TIMEOUT"


def unwrap_vertices(positions: np.ndarray, normals: np.ndarray, colors: np.ndarray | None,
            indices: np.ndarray, name: str = "mesh"):
    """Generate UVs with an xatlas unwrap (vertices on seams are split)."""
    vmapping, new_indices, uvs = unwrap_uvs(positions, indices, name)
    # xatlas leaves the corners of triangles too thin for it (relative to float32) without a
    # chart: NaN. Such a triangle covers no texel; they take (0, 0). None charted: degenerate.
    charted = np.isfinite(uvs).all(axis=1)
    if not charted.any():
        raise InputError(f"mesh is degenerate: the UV unwrap found no triangle with an area "
                         f"among its {len(indices):,} (give the mesh UVs)", name)
    uvs = np.where(charted[:, None], uvs, 0.0)
    vmapping = vmapping.astype(np.int64)
    colors = None if colors is None else np.asarray(colors)[vmapping]
    return (positions[vmapping], normals[vmapping], colors,
            new_indices.astype(np.int64), uvs.astype(np.float64))


def unwrap_timeout() -> float:
    """Seconds an unwrap may take: ``DEFERRED_UNWRAP_TIMEOUT`` or ``UNWRAP_TIMEOUT_S``."""
    text = os.environ.get(UNWRAP_TIMEOUT_ENV)
    if text is None or not text.strip():
        return UNWRAP_TIMEOUT_S
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    if not (math.isfinite(seconds) and seconds > 0.0):
        raise InputError(f"environment variable {UNWRAP_TIMEOUT_ENV} must be a number of "
                         f"seconds greater than 0, got '{text}'")
    return seconds


def _xatlas_parametrize(positions: np.ndarray, indices: np.ndarray):
    import xatlas

    return xatlas.parametrize(positions, indices)


def _die_with_parent(parent: int) -> None:
    """Linux: the kernel kills this process when its parent dies, even by SIGKILL (the OOM
    killer), which leaves no ``finally`` to end a hung unwrap."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:  # the parent died before prctl: nobody waits for the result
        os._exit(1)


def _unwrap_child(connection, positions: np.ndarray, indices: np.ndarray,
                  parent: int) -> None:
    """The unwrap process: xatlas, then the arrays (or the error) back through the pipe."""
    # Ctrl-C is the parent's to handle (it ends this process), and so is SIGTERM: a handler
    # forked from the parent (deferred.io.safety's) would turn the parent's terminate()
    # into an exception here. xatlas' ASSERT lines and a traceback from here would break the
    # command line's one-line errors.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _die_with_parent(parent)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)
    sys.stdout = sys.stderr = open(os.devnull, "w")  # noqa: SIM115 - the process's whole life
    try:
        result = ("ok", _xatlas_parametrize(positions, indices))
    except Exception as exc:  # noqa: BLE001 - reported by the parent, naming the mesh
        result = ("error", f"{type(exc).__name__}: {exc}")
    connection.send(result)
    connection.close()


def _process_context():
    # fork: the child starts at once with the arrays already in its memory (spawn imports numpy
    # and xatlas again); spawn where fork is missing or unsafe (macOS).
    if sys.platform != "darwin" and "fork" in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("fork")
    return multiprocessing.get_context("spawn")


def unwrap_uvs(positions: np.ndarray, indices: np.ndarray,
               name: str = "mesh") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """xatlas' ``(vmapping, indices, uvs)`` for a mesh, computed in a child process.

    xatlas can run for ever on a bad mesh and, inside C++, ignores Ctrl-C: the child is ended
    after :func:`unwrap_timeout` seconds (an ``InputError`` naming ``name``) or when the wait
    here is interrupted. A crash of the child is an ``InputError`` too.
    """
    limit = unwrap_timeout()
    context = _process_context()
    receiver, sender = context.Pipe(duplex=False)
    child = context.Process(target=_unwrap_child, daemon=True, name=f"unwrap {name}",
                            args=(sender, np.ascontiguousarray(positions, dtype=np.float32),
                                  np.ascontiguousarray(indices, dtype=np.uint32), os.getpid()))
    try:
        with warnings.catch_warnings():
            # Python 3.12+ warns that forking a threaded process (GL drivers, BLAS) may
            # deadlock the child; ours runs numpy and xatlas only, and the time limit bounds it.
            warnings.filterwarnings("ignore", message=".*fork.*", category=DeprecationWarning)
            child.start()
        sender.close()  # the child holds the only writing end: its exit ends the wait below
        deadline = time.monotonic() + limit
        # short polls: a pending Ctrl-C is raised here at the latest a quarter second later
        while not receiver.poll(min(0.25, max(0.0, deadline - time.monotonic()))):
            if time.monotonic() >= deadline:
                raise InputError(f"UV unwrap did not finish in {limit:g} s; give the mesh UVs "
                                 f"or simplify it", name)
        try:
            status, payload = receiver.recv()
        except EOFError:
            child.join(5.0)
            code = child.exitcode
            how = f"signal {-code}" if code is not None and code < 0 else f"exit code {code}"
            raise InputError(f"UV unwrap failed: the unwrapping process died ({how}; out of "
                             f"memory?); give the mesh UVs or simplify it", name) from None
        child.join(2.0)  # it only has to exit now
        if status != "ok":
            raise InputError(f"UV unwrap failed: {payload}; give the mesh UVs", name)
        return payload
    finally:
        receiver.close()
        if child.is_alive():  # out of time, interrupted, or the wait itself failed
            # SIGKILL: it holds nothing to clean up, and a child stopped before it set its
            # signals up would take SIGTERM through the parent's handler and print a traceback
            child.kill()
        child.join()
