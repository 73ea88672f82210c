"""UVs for a mesh that has none: an xatlas unwrap in a child process with a time limit
(``UNWRAP_TIMEOUT_S``, environment variable ``DEFERRED_UNWRAP_TIMEOUT``), so a mesh that defeats
xatlas is an error after that time and Ctrl-C stops it (inside xatlas, the interpreter never sees
the signal).

xatlas crashes (SIGSEGV in a worker thread) on some meshes whatever their size: the exact
icosphere of 81,920 triangles and UV spheres of 124,500, where a UV sphere of 158,400 and a
torus of 180,000 unwrap. No size bound makes it safe, so a crashed child is said by its signal
and the mesh gets a chart per triangle instead (:func:`triangle_charts`: numpy, no library
that could crash), with a warning naming the mesh. A child killed (SIGKILL: the out-of-memory
killer) is an error.
"""
from __future__ import annotations

import faulthandler
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
    faulthandler.disable()  # a crash is the parent's to say (python -X faulthandler, pytest)
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
            return _after_death(child.exitcode, positions, indices, name)
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


# Signals a crash ends a process with (a bug in xatlas), not a lack of memory: the mesh is then
# unwrapped a triangle a chart
CRASH_SIGNALS = frozenset({signal.SIGSEGV, signal.SIGBUS, signal.SIGFPE, signal.SIGILL,
                           signal.SIGABRT})


class UnwrapWarning(UserWarning):
    """xatlas crashed on a mesh: it has a UV chart per triangle instead."""


def _after_death(code: int | None, positions: np.ndarray, indices: np.ndarray,
                 name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The unwrap of a mesh whose unwrapping process ended without an answer: a chart per
    triangle after a crash (with a warning), else an ``InputError`` saying how it ended."""
    how = signal_name(-code) if code is not None and code < 0 else f"exit code {code}"
    if code is not None and code < 0 and -code in CRASH_SIGNALS:
        warnings.warn(f"{name}: xatlas crashed unwrapping the mesh, {how}; each triangle is "
                      "a UV chart of its own instead (give the mesh UVs for charts that span "
                      "triangles)", UnwrapWarning, stacklevel=4)
        return triangle_charts(positions, indices)
    ended = f"was killed by {how}: out of memory?" if code == -signal.SIGKILL else \
        f"ended by {how}" if code is not None and code < 0 else f"ended with {how}"
    raise InputError(f"UV unwrap failed: the unwrapping process {ended}; give the mesh UVs or "
                     "simplify it", name)


def signal_name(number: int) -> str:
    """``SIGSEGV (signal 11)``, or ``signal N`` for a number no signal has."""
    try:
        return f"{signal.Signals(number).name} (signal {number})"
    except ValueError:
        return f"signal {number}"


def triangle_charts(positions: np.ndarray, indices: np.ndarray,
                    gap: float = 0.25) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(vmapping, indices, uvs)`` as xatlas gives them, each triangle its own chart: laid
    flat at its true shape, one scale for all (the texel density of the mesh is uniform), in
    shelves of rising height sorted tallest first, ``gap`` times the mean chart height apart,
    in [0, 1]^2. Vectorised numpy: it cannot crash, and takes about a second a million
    triangles."""
    faces = np.asarray(indices, dtype=np.int64).reshape(-1, 3)
    corners = np.asarray(positions, dtype=np.float64)[faces]
    edge1 = corners[:, 1] - corners[:, 0]
    edge2 = corners[:, 2] - corners[:, 0]
    length1 = np.linalg.norm(edge1, axis=1)
    along = edge1 / np.maximum(length1, 1e-30)[:, None]
    x2 = (edge2 * along).sum(axis=1)
    y2 = np.linalg.norm(edge2 - x2[:, None] * along, axis=1)
    flat = np.zeros((len(faces), 3, 2))
    flat[:, 1, 0] = length1
    flat[:, 2, 0], flat[:, 2, 1] = x2, y2
    flat[:, :, 0] -= flat[:, :, 0].min(axis=1, keepdims=True)  # the corner x2 < 0 at 0
    width, height = flat[:, :, 0].max(axis=1), flat[:, 2, 1]
    spacing = gap * max(float(height.mean()), float(width.mean()), 1e-30)
    cell_width, cell_height = width + spacing, height + spacing
    order = np.argsort(-cell_height, kind="stable")
    # shelves of about the atlas' side: a chart starting past a shelf's end opens the next
    side = math.sqrt(float((cell_width * cell_height).sum()))
    start = np.cumsum(cell_width[order]) - cell_width[order]
    shelf = (start // max(side, 1e-30)).astype(np.int64)
    shelf_start = np.searchsorted(shelf, np.arange(shelf[-1] + 1))
    x = start - start[shelf_start][shelf]
    shelf_heights = cell_height[order][shelf_start]  # the tallest chart of each shelf: its first
    y = (np.cumsum(shelf_heights) - shelf_heights)[shelf]
    offsets = np.zeros((len(faces), 2))
    offsets[order, 0], offsets[order, 1] = x, y
    placed = flat + offsets[:, None, :]
    extent = max(float(placed[..., 0].max()), float(placed[..., 1].max()), 1e-30) + spacing
    uvs = ((placed + 0.5 * spacing) / extent).reshape(-1, 2)
    vmapping = faces.reshape(-1)
    new_indices = np.arange(len(vmapping), dtype=np.int64).reshape(-1, 3)
    return vmapping, new_indices, uvs
