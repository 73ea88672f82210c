"""Where a sequence's frames are rendered: in the command's own process (:class:`InlinePool`)
or in worker processes on this machine (:class:`ProcessPool`, ``--workers N``); Ray's actors
are in :mod:`deferred.farm.ray_pool`. Every pool runs chunks (lists of frame numbers) on its
workers, each worker a :class:`~deferred.farm.worker.FrameWorker` keeping its renderer warm
from one chunk to the next, and reports what happened as events:

- a :class:`~deferred.farm.worker.FrameDone` or :class:`~deferred.farm.worker.FrameFailed`
  for each frame, in the chunk's order;
- :class:`Idle` when a worker has finished its chunk;
- :class:`Lost` when a worker died (a kill, a crash, a lost node) with the frames of its chunk
  it had not reported: the driver gives them out again and the pool starts a new worker.

Workers never write the outputs: they send each frame's encoded bytes, and the driver renames
them into place (so no torn file, and no shared file system).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import tempfile
from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass
from multiprocessing.connection import wait
from typing import Any

from deferred.farm.worker import FrameDone, FrameFailed, FrameJob, FrameWorker


@dataclass(frozen=True)
class Idle:
    worker: str


@dataclass(frozen=True)
class Lost:
    worker: str
    frames: list[int]
    reason: str


Event = FrameDone | FrameFailed | Idle | Lost


class InlinePool:
    """One worker: the command's own process (the default, ``--resume`` without workers)."""

    def __init__(self, job: FrameJob):
        self.worker = FrameWorker(job, "local")
        self.names = ["local"]
        self._chunk: deque[int] = deque()

    def assign(self, worker: str, frames: list[int]) -> None:
        self._chunk.extend(frames)

    def idle(self) -> list[str]:
        return [] if self._chunk else self.names

    def events(self, timeout: float) -> Iterator[Event]:
        if self._chunk:
            yield self.worker.frame(self._chunk.popleft())
            if not self._chunk:
                yield Idle("local")

    def close(self) -> None:
        self.worker.close()


def _serve(connection, job: FrameJob, name: str) -> None:
    """A worker process: chunks in, frames out, until told to stop (``None``)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C in a terminal is the driver's
    os.chdir(tempfile.mkdtemp(prefix="deferred-worker-"))  # nothing resolves against the driver's
    worker = FrameWorker(job, name)
    try:
        while True:
            frames = connection.recv()
            if frames is None:
                break
            for index in frames:
                connection.send(worker.frame(index))
            connection.send(Idle(name))
    except (EOFError, BrokenPipeError, ConnectionResetError):
        pass  # the driver is gone
    finally:
        worker.close()


class _Process:
    def __init__(self, context, job: FrameJob, name: str):
        self.name = name
        self.connection, child = context.Pipe()
        self.process = context.Process(target=_serve, args=(child, job, name), daemon=True,
                                       name=f"deferred {name}")
        self.process.start()
        child.close()
        self.chunk: deque[int] = deque()  # frames given and not yet reported
        self.busy = False


class ProcessPool:
    """``count`` worker processes on this machine (spawned: a GL context does not survive a
    fork), each with one GL context; a worker that dies is replaced."""

    def __init__(self, job: FrameJob, count: int):
        self.job = job
        self._context = multiprocessing.get_context("spawn")
        self._made = 0
        self._workers: dict[str, _Process] = {}
        for _ in range(count):
            self._start()
        self.names = list(self._workers)

    def _start(self, name: str | None = None) -> _Process:
        if name is None:
            self._made += 1
            name = f"worker {self._made}"
        worker = _Process(self._context, self.job, name)
        self._workers[name] = worker
        return worker

    def assign(self, worker: str, frames: list[int]) -> None:
        process = self._workers[worker]
        process.chunk.extend(frames)
        process.busy = True
        process.connection.send(list(frames))

    def idle(self) -> list[str]:
        return [name for name, worker in self._workers.items() if not worker.busy]

    def events(self, timeout: float) -> Iterator[Event]:
        by_handle: dict[Any, _Process] = {}
        for worker in self._workers.values():
            if worker.busy:
                by_handle[worker.connection] = worker
                by_handle[worker.process.sentinel] = worker
        if not by_handle:
            return
        for handle in wait(list(by_handle), timeout):
            worker = by_handle[handle]
            if self._workers.get(worker.name) is not worker:
                continue  # lost and replaced already (its pipe and its sentinel both ready)
            try:
                while worker.connection.poll():
                    yield self._received(worker, worker.connection.recv())
            except (EOFError, OSError):
                pass  # the process died: what it sent before is read above
            if not worker.process.is_alive():
                yield self._lost(worker)

    def _received(self, worker: _Process, message: Event) -> Event:
        if isinstance(message, Idle):
            worker.busy = False
        elif worker.chunk and worker.chunk[0] == message.index:
            worker.chunk.popleft()
        return message

    def _lost(self, worker: _Process) -> Lost:
        worker.process.join(timeout=5)
        code = worker.process.exitcode
        reason = f"killed by {signal.Signals(-code).name}" if code is not None and code < 0 \
            else f"exit status {code}"
        frames = list(worker.chunk)
        worker.connection.close()
        self._start(worker.name)  # a fresh process under the same name
        return Lost(worker.name, frames, reason)

    def close(self) -> None:
        """Stop every worker: asked first, then terminated."""
        for worker in self._workers.values():
            try:
                worker.connection.send(None)
            except (OSError, ValueError):
                pass
        for worker in self._workers.values():
            worker.process.join(timeout=2 if not worker.busy else 0)
            if worker.process.is_alive():
                worker.process.terminate()
                worker.process.join(timeout=5)
            if worker.process.is_alive():
                worker.process.kill()
                worker.process.join()
            worker.connection.close()
