"""Workers on a Ray cluster (``--ray [ADDRESS]``, the ``ray`` extra): each worker an actor
holding one :class:`~deferred.farm.worker.FrameWorker` (one GL context, a warm renderer).

Where the cluster has GPUs each actor asks for one (``num_gpus=1``: one worker per GPU) and
renders on the EGL device of the GPU Ray gave it (``DEFERRED_EGL_DEVICE``, Ray's GPU id: EGL
lists NVIDIA's devices in CUDA's order); on CPU-only nodes an actor asks for one CPU and renders
on llvmpipe as a single process does. The scene travels once, by content, through Ray's object
store (:class:`~deferred.farm.bundle.SceneBundle`). An actor that dies (a killed process, a lost
node) is restarted by Ray and the frames it was asked for are asked again
(``max_restarts``/``max_task_retries``); one Ray cannot bring back is :class:`Lost`.
"""

from __future__ import annotations

import os
import signal
import threading
from collections import deque
from collections.abc import Iterator
from typing import Any

from deferred.farm.pools import Event, Idle, Lost
from deferred.farm.worker import FrameFailed, FrameJob, FrameWorker

RESTARTS = 3  # Ray restarts a dead actor, and retries its calls, this many times


class RenderActor:
    """A worker inside a Ray actor."""

    def __init__(self, job: FrameJob, name: str):
        import ray

        gpus = ray.get_gpu_ids()
        if gpus:
            os.environ["DEFERRED_EGL_DEVICE"] = str(int(gpus[0]))
        os.chdir(self._folder())  # nothing resolves against the node's working directory
        self.worker = FrameWorker(job, name)

    @staticmethod
    def _folder() -> str:
        import tempfile

        return tempfile.mkdtemp(prefix="deferred-worker-")

    def frame(self, index: int):
        return self.worker.frame(index)

    def call(self, function, *args):
        """A sweep's task on this worker's machine (``bench --sweep``)."""
        return function(*args)

    def close(self) -> None:
        self.worker.close()


def _connect(address: str | None) -> bool:
    """Join the cluster at ``address`` (or start a local instance); whether this call did."""
    import ray

    if ray.is_initialized():
        return False
    # ray.init makes SIGTERM a sys.exit(15) in the driver: the command's own handlers stay
    # (SIGTERM unwinds as Terminated, exit 143, as without Ray)
    handlers = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    ray.init(address=address, include_dashboard=False, log_to_driver=False)
    for signum, handler in handlers.items():
        if handler is not None and threading.current_thread() is threading.main_thread():
            signal.signal(signum, handler)
    return True


def default_workers() -> int:
    """One worker per GPU in the cluster, else one per node."""
    import ray

    gpus = int(ray.cluster_resources().get("GPU", 0))
    return gpus or max(1, sum(1 for node in ray.nodes() if node.get("Alive")))


def actor_options() -> dict[str, Any]:
    """One GPU per actor where the cluster has GPUs, else one CPU; spread over the nodes."""
    import ray

    resources = {"num_gpus": 1} if ray.cluster_resources().get("GPU", 0) else {"num_cpus": 1}
    return {**resources, "scheduling_strategy": "SPREAD", "max_restarts": RESTARTS,
            "max_task_retries": RESTARTS}


class RayPool:
    """``workers`` actors (by default :func:`default_workers`) on the cluster at ``address``."""

    def __init__(self, job: FrameJob, address: str | None, workers: int | None):
        import ray

        self._started = _connect(address)
        self._remote = ray.remote(RenderActor).options(**actor_options())
        self._job = ray.put(job)  # the scene's bytes once, into the object store
        count = workers or default_workers()
        self.names = [f"worker {n + 1}" for n in range(count)]
        self._actors = {name: self._remote.remote(self._job, name) for name in self.names}
        self._calls: dict[str, deque[tuple[int, Any]]] = {name: deque() for name in self.names}

    def assign(self, worker: str, frames: list[int]) -> None:
        actor = self._actors[worker]
        self._calls[worker].extend((index, actor.frame.remote(index)) for index in frames)

    def idle(self) -> list[str]:
        return [name for name, calls in self._calls.items() if not calls]

    def events(self, timeout: float) -> Iterator[Event]:
        import ray

        heads = {calls[0][1]: name for name, calls in self._calls.items() if calls}
        if not heads:
            return
        ready, _ = ray.wait(list(heads), num_returns=1, timeout=timeout)
        for reference in ready:
            name = heads[reference]
            calls = self._calls[name]
            index, _ = calls.popleft()
            try:
                yield ray.get(reference)
            except ray.exceptions.RayActorError as exc:
                frames = [index, *(later for later, _ in calls)]
                calls.clear()
                self._actors[name] = self._remote.remote(self._job, name)
                yield Lost(name, frames, f"Ray lost the actor: {type(exc).__name__}")
                continue
            except ray.exceptions.RayError as exc:
                yield FrameFailed(index, f"{type(exc).__name__}: {exc}", False, name)
                continue
            if not calls:
                yield Idle(name)

    def close(self) -> None:
        import ray

        for actor in self._actors.values():
            ray.kill(actor)
        if self._started:
            ray.shutdown()


class TaskActor:
    """Runs tasks one at a time on the node it is pinned to."""

    def call(self, function, *args):
        return function(*args)


def run_on_nodes(function, tasks, address: str | None, on_done) -> list:
    """``function(*task)`` for every task, one task at a time on each node of the cluster
    (an actor pinned to each live node): timings taken on a machine doing nothing else of
    ours."""
    import ray
    from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy

    started = _connect(address)
    actors = []
    try:
        for node in ray.nodes():
            if node.get("Alive"):
                strategy = NodeAffinitySchedulingStrategy(node["NodeID"], soft=False)
                actors.append(ray.remote(TaskActor).options(
                    num_cpus=1, scheduling_strategy=strategy, max_restarts=RESTARTS,
                    max_task_retries=RESTARTS).remote())
        queue = deque(enumerate(tasks))
        results: list = [None] * len(tasks)
        running: dict[Any, tuple[int, Any]] = {}
        idle = deque(actors)
        while queue or running:
            while queue and idle:
                actor = idle.popleft()
                number, task = queue.popleft()
                running[actor.call.remote(function, *task)] = (number, actor)
            ready, _ = ray.wait(list(running), num_returns=1)
            for reference in ready:
                number, actor = running.pop(reference)
                results[number] = ray.get(reference)
                idle.append(actor)
                on_done(len(tasks) - len(queue) - len(running), len(tasks))
        return results
    finally:
        for actor in actors:
            ray.kill(actor)
        if started:
            ray.shutdown()
