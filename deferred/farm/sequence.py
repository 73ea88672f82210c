"""A sequence rendered by workers (``deferred render --workers N``, ``--ray``, ``--resume``):
the frames planned into chunks, the chunks given to idle workers, each finished frame renamed
into place by the driver and recorded in the manifest, a video assembled from the finished
frames after the last one.

A frame is written only whole (a temporary file, then a rename) and recorded after it is in
place, so a run stopped at any moment (Ctrl-C, a killed worker, a lost node) leaves complete
frames, and ``--resume`` renders only the ones the manifest does not vouch for. A worker lost
mid-chunk has its unfinished frames given to another worker (at most :data:`MAX_ATTEMPTS`
times each); a frame that fails for a reason of its own (bad input at its time) stops the run
with its number and the message.
"""

from __future__ import annotations

import math
import shutil
import time
from collections import Counter, deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from deferred.errors import InputError, RenderError
from deferred.farm.manifest import Manifest, manifest_header, manifest_path
from deferred.farm.pools import Idle, Lost
from deferred.farm.worker import FrameDone, FrameFailed, FrameJob
from deferred.io.images import write_bytes
from deferred.io.paths import expand_pattern
from deferred.io.progress import Progress
from deferred.io.safety import signals_deferred

MAX_ATTEMPTS = 3  # a frame whose worker dies this often stops the run
CHUNKS_PER_WORKER = 4  # chunks are small enough to balance the workers and retry little


class Pool(Protocol):
    names: list[str]

    def assign(self, worker: str, frames: list[int]) -> None: ...
    def idle(self) -> list[str]: ...
    def events(self, timeout: float): ...
    def close(self) -> None: ...


@dataclass
class SequenceResult:
    written: list[Path]  # every frame file, or the one video
    frame_ms: list[float]  # the frames rendered by this run (none if every one was done)
    skipped: int  # frames a resumed run found done
    light_path: str = ""  # the workers' renderers'


def plan_chunks(pending: list[int], workers: int, temporal: bool) -> list[list[int]]:
    """The frames to render as chunks, in order: runs of consecutive frames, each at most
    ``len(pending) / (workers * CHUNKS_PER_WORKER)`` long. A scene with a temporal effect is
    one chunk: its history chains each frame to the one before, so a later chunk would draw
    every frame before it again."""
    if not pending:
        return []
    if temporal:
        return [list(pending)]
    size = max(1, math.ceil(len(pending) / (workers * CHUNKS_PER_WORKER)))
    chunks: list[list[int]] = []
    for index in pending:
        last = chunks[-1] if chunks else None
        if last is not None and last[-1] == index - 1 and len(last) < size:
            last.append(index)
        else:
            chunks.append([index])
    return chunks


def make_pool(job: FrameJob, workers: int | None, ray: str | None) -> Pool:
    """The workers ``--workers`` and ``--ray`` ask for: Ray actors, local processes, or this
    process."""
    if ray is not None:
        from deferred.farm.ray_pool import RayPool

        return RayPool(job, ray or None, workers)
    if workers is not None:
        from deferred.farm.pools import ProcessPool

        return ProcessPool(job, workers)
    from deferred.farm.pools import InlinePool

    return InlinePool(job)


def frames_pattern(out: Path, kind: str) -> Path:
    """Where the frames go: the sequence's own pattern, or for a video a folder beside it
    (``OUT.mp4.frames/frame_000000.png``), removed once the video is written."""
    if kind == "sequence":
        return out
    return out.with_name(out.name + ".frames") / "frame_######.png"


def render_sequence(job: FrameJob, out: Path, kind: str, make_pool: Callable[[], Pool],
                    progress: Progress, resume: bool, temporal: bool) -> SequenceResult:
    """Render every frame of ``job`` to ``out`` (a ``#`` pattern or a video) on the workers
    ``make_pool()`` starts (after the frames a resumed run finds done are counted)."""
    pattern = frames_pattern(out, kind)
    pattern.parent.mkdir(exist_ok=True)
    manifest = Manifest(manifest_path(pattern),
                        manifest_header(job.bundle.digest, job.options()), resume)
    try:
        files = [expand_pattern(pattern, index) for index in range(len(job.times))]
        pending = [index for index, file in enumerate(files)
                   if not (resume and manifest.finished(index, file, job.times[index]))]
        skipped = len(files) - len(pending)
        if resume and skipped:
            progress.note(f"resuming: {skipped} of {len(files)} frames are done, "
                          f"{len(pending)} to render")
        frame_ms: list[float] = []
        light_path = [""]
        if pending:
            progress.status("starting the workers")
            pool = make_pool()
            try:
                frame_ms = _drive(pool, job, files, pending, manifest, progress, temporal,
                                  out.name, light_path)
            finally:
                pool.close()
    finally:
        manifest.close()
    if kind == "sequence":
        return SequenceResult(files, frame_ms, skipped, light_path[0])
    progress.status(f"writing {out.name}")
    _assemble(out, job.fps, files)
    shutil.rmtree(pattern.parent, ignore_errors=True)
    return SequenceResult([out], frame_ms, skipped, light_path[0])


def _drive(pool: Pool, job: FrameJob, files: list[Path], pending: list[int],
           manifest: Manifest, progress: Progress, temporal: bool, name: str,
           light_path: list[str]) -> list[float]:
    queue = deque(plan_chunks(pending, len(pool.names), temporal))
    if temporal and len(pool.names) > 1:
        progress.note("the scene has a temporal effect (taa): each frame blends the ones before "
                      "it, so one worker renders them in order")
    outstanding = set(pending)
    attempts: Counter[int] = Counter()
    frame_ms: list[float] = []
    rates = _Rates()
    progress.count(len(pending), "frames", f"rendering {name} on {_workers(pool)}")
    while outstanding:
        for worker in pool.idle():
            if not queue:
                break
            pool.assign(worker, queue.popleft())
            rates.started(worker)
        for event in pool.events(0.5):
            if isinstance(event, FrameDone) and event.index in outstanding:
                with signals_deferred():  # a frame in place is a frame recorded
                    write_bytes(files[event.index], event.data)
                    manifest.record(event.index, files[event.index], job.times[event.index],
                                    event.data)
                outstanding.discard(event.index)
                frame_ms.append(event.ms)
                light_path[0] = event.light_path
                rates.done(event.worker)
                progress.advance(len(pending) - len(outstanding),
                                 f"rendering {name} on {_workers(pool)}{rates.describe()}")
            elif isinstance(event, FrameFailed):
                at = job.times[event.index]
                error = InputError if event.bad_input else RenderError
                raise error(f"frame {event.index} (t = {at:g} s): {event.message}")
            elif isinstance(event, Lost):
                _requeue(event, queue, outstanding, attempts, progress)
            elif isinstance(event, Idle):
                rates.stopped(event.worker)
    return frame_ms


def _requeue(event: Lost, queue: deque[list[int]], outstanding: set[int],
             attempts: Counter[int], progress: Progress) -> None:
    frames = [index for index in event.frames if index in outstanding]
    if not frames:
        return
    for index in frames:
        attempts[index] += 1
    first = frames[0]
    if attempts[first] >= MAX_ATTEMPTS:
        raise RenderError(f"frame {first}: its worker died {attempts[first]} times rendering "
                          f"it ({event.reason})")
    progress.note(f"{event.worker} died ({event.reason}) before frame {first}: "
                  f"{len(frames)} frames given out again")
    queue.appendleft(frames)


def _workers(pool: Pool) -> str:
    count = len(pool.names)
    return "this process" if pool.names == ["local"] else \
        f"{count} worker{'s' if count != 1 else ''}"


class _Rates:
    """Each worker's frames per second while it had work."""

    def __init__(self) -> None:
        self.busy: dict[str, float] = {}
        self.since: dict[str, float] = {}
        self.frames: Counter[str] = Counter()

    def started(self, worker: str) -> None:
        self.since.setdefault(worker, time.monotonic())

    def stopped(self, worker: str) -> None:
        since = self.since.pop(worker, None)
        if since is not None:
            self.busy[worker] = self.busy.get(worker, 0.0) + time.monotonic() - since

    def done(self, worker: str) -> None:
        self.frames[worker] += 1

    def describe(self) -> str:
        now = time.monotonic()
        rates = []
        for worker, frames in sorted(self.frames.items()):
            busy = self.busy.get(worker, 0.0) + now - self.since.get(worker, now)
            if busy > 0.0:
                rates.append(f"{frames / busy:.2f}")
        return f" ({' '.join(rates)} frames/s each)" if len(rates) > 1 else ""


def _assemble(out: Path, fps: float, files: list[Path]) -> None:
    """The video from the finished frames (renamed into place whole by the writer)."""
    import numpy as np
    from PIL import Image

    from deferred.io.video import AnimationWriter

    with AnimationWriter(out, fps) as writer:
        for file in files:
            with Image.open(file) as image:
                writer.write(np.asarray(image.convert("RGBA")))
