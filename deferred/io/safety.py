"""Keeping outputs from destroying things (issue #11, "no silent loss"): the files a scene reads,
so no output overwrites one, and signal handling, so an interrupted command removes what it
had half written.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from deferred.errors import InputError

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10: the same parser, as a package
    import tomli as tomllib


class Terminated(KeyboardInterrupt):
    """SIGTERM (or another signal) as an exception. A ``KeyboardInterrupt`` so it unwinds the
    same way Ctrl-C does: through every ``finally`` that removes temporary files, and past
    ``except Exception`` handlers that would otherwise report it as a render failure."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def interrupt_exit_code(exc: BaseException) -> int:
    """The shell's code for a command ended by a signal: 128 + the signal's number."""
    return 128 + (exc.signum if isinstance(exc, Terminated) else signal.SIGINT)


# The signals that asked the running command to stop: kept, because the exception a handler
# raises can be lost (raised inside a ``__del__``, Python prints "Exception ignored" and goes
# on; a library may catch BaseException), and the command must still end without output.
_stop_requests: list[int] = []


def stop_requested() -> BaseException | None:
    """The interrupt a signal asked for while :func:`termination_as_interrupt` was active
    (``KeyboardInterrupt`` or :class:`Terminated`), or ``None``."""
    if not _stop_requests:
        return None
    signum = _stop_requests[0]
    return KeyboardInterrupt() if signum == signal.SIGINT else Terminated(signum)


def raise_if_stop_requested() -> None:
    """Raise the interrupt a signal asked for, where its own exception may have been lost:
    before an output file is renamed into place, so a stopped command leaves none."""
    requested = stop_requested()
    if requested is not None:
        raise requested


@contextmanager
def termination_as_interrupt() -> Iterator[None]:
    """Turn SIGTERM into :class:`Terminated`, and SIGINT into ``KeyboardInterrupt`` as Python
    does, while the block runs, and keep that they came (:func:`raise_if_stop_requested`:
    main thread only, where Python runs signal handlers). Without it SIGTERM kills the process
    on the spot and leaves temporary files and folders behind."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _stop_requests.clear()

    def terminate(signum: int, frame: Any) -> None:
        _stop_requests.append(signum)
        raise Terminated(signum)

    def interrupt(signum: int, frame: Any) -> None:
        _stop_requests.append(signum)
        raise KeyboardInterrupt

    previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, terminate)}
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # not ignored, not set
        previous[signal.SIGINT] = signal.signal(signal.SIGINT, interrupt)
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler if handler is not None else signal.SIG_DFL)
        _stop_requests.clear()  # the command they asked to stop is over


@contextmanager
def signals_deferred() -> Iterator[None]:
    """Hold SIGINT and SIGTERM while the block runs, then deliver the first one: for steps that
    must not stop half way (swapping a folder in: rename the old one away, the new one in).
    Python-level handlers, because the interpreter runs them in the main thread whichever
    thread the kernel delivered the signal to; a no-op outside the main thread."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []

    def hold(signum: int, frame: Any) -> None:
        held.append(signum)

    previous = {}
    for signum in (signal.SIGINT, signal.SIGTERM):
        handler = signal.getsignal(signum)
        if handler is None or handler == signal.SIG_IGN:
            continue  # set outside Python (cannot be restored) or ignored anyway
        previous[signum] = signal.signal(signum, hold)
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        if held:
            signal.raise_signal(held[0])  # its own handler now: KeyboardInterrupt, Terminated


# -- the files a scene reads ---------------------------------------------------------------------

def strings_in(value: Any) -> Iterator[str]:
    """Every string inside nested tables and lists."""
    if isinstance(value, str):
        yield value
    elif isinstance(value, Mapping):
        for item in value.values():
            yield from strings_in(item)
    elif isinstance(value, list | tuple):
        for item in value:
            yield from strings_in(item)


def _is_file(path: Path) -> bool:
    try:
        return path.is_file()
    except (OSError, ValueError):
        return False


def scene_inputs(scene: Any, scene_file: str | Path | None = None) -> list[Path]:
    """The files ``scene`` was made from: the scene file, and every existing file named by a
    string in it (meshes, textures, heightfields, wetness masks, event parameters), found by
    walking the TOML rather than each material's parameter names, so a new material's file
    parameters are covered too; and the strings of each material's parameters, resolved the
    way the material resolves them (scenes built in code); and the files each mesh was read
    from (``MeshData.sources``: an OBJ's material library and its textures, glTF buffers)."""
    found: list[Path] = []
    if scene_file is not None and not str(scene_file).startswith("builtin:"):
        path = Path(scene_file)
        found.append(path)
        try:
            data: Any = tomllib.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):  # undecodable, malformed, a number too long
            data = {}
        for text in strings_in(data):
            candidate = Path(text)
            found.append(candidate if candidate.is_absolute() else path.parent / candidate)
    for obj in getattr(scene, "objects", ()):
        found.extend(getattr(getattr(obj, "mesh", None), "sources", ()))
        material = obj.material
        sets = [material.params, obj.base_params, *(event.params for event in obj.events)]
        for params in sets:
            if params is None:
                continue
            values = params.model_dump() if hasattr(params, "model_dump") else params
            for text in strings_in(values):
                try:
                    found.append(material.resolve_path(text))
                except (TypeError, ValueError):
                    continue
    return [path for path in dict.fromkeys(found) if _is_file(path)]


def same_file(a: Path, b: Path) -> bool:
    """Whether two paths name one file (hard and symbolic links included)."""
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        return False


def check_not_inputs(outputs: Iterable[Path], inputs: Iterable[Path], where: str) -> None:
    """``InputError`` (exit 2) when an output of option ``where`` is one of the ``inputs``:
    the command would replace a file it reads."""
    inputs = list(inputs)
    for output in outputs:
        for source in inputs:
            if same_file(output, source):
                raise InputError(f"would overwrite {source}, a file the scene reads", where)
