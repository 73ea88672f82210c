"""Independent tasks (``bench --sweep``'s grid points) on local worker processes or on the
nodes of a Ray cluster, placed so that timings stay honest:

- on a Ray cluster, one actor per node, pinned to it, runs one task at a time: a machine times
  one point at a time, as ``deferred bench`` does alone;
- locally, ``workers`` processes each pinned to its own share of the CPU cores
  (``os.sched_setaffinity``) with llvmpipe's threads set to that share (``LP_NUM_THREADS``):
  points timed side by side, each on cores of its own (:func:`placement` says which, for the
  report).

Results come back in the order of the tasks; ``on_done(done, total)`` is called as each ends.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from typing import Any


def core_sets(workers: int) -> list[list[int]]:
    """This process's cores split into ``workers`` disjoint sets (at least one core each)."""
    cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else \
        list(range(os.cpu_count() or 1))
    share = max(1, len(cores) // workers)
    return [cores[(n * share) % len(cores):(n * share) % len(cores) + share]
            for n in range(workers)]


def placement(workers: int | None, ray: str | None) -> str:
    """How the tasks' timings were taken, for the report."""
    if ray is not None:
        return "Ray: one task at a time on each node"
    if workers is None:
        return "one task at a time in this process"
    sets = core_sets(workers)
    return (f"{workers} local workers side by side, each pinned to {len(sets[0])} core"
            f"{'s' if len(sets[0]) != 1 else ''} of its own (LP_NUM_THREADS={len(sets[0])})")


def _pin(cores: Any) -> None:
    chosen = cores.get()
    os.environ["LP_NUM_THREADS"] = str(len(chosen))  # read when the GL context is made
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, chosen)


def run_tasks(function: Callable[..., Any], tasks: Sequence[tuple], workers: int | None,
              ray: str | None, on_done: Callable[[int, int], None]) -> list[Any]:
    """``function(*task)`` for every task: here, on pinned local workers, or on Ray's nodes."""
    if ray is not None:
        from deferred.farm.ray_pool import run_on_nodes

        return run_on_nodes(function, tasks, ray or None, on_done)
    if workers is None:
        results = []
        for task in tasks:
            results.append(function(*task))
            on_done(len(results), len(tasks))
        return results
    context = multiprocessing.get_context("spawn")
    cores = context.Queue()
    for chosen in core_sets(workers):
        cores.put(chosen)
    results: list[Any] = [None] * len(tasks)
    with ProcessPoolExecutor(workers, mp_context=context, initializer=_pin,
                             initargs=(cores,)) as pool:
        futures = {pool.submit(function, *task): n for n, task in enumerate(tasks)}
        pending, done = set(futures), 0
        try:
            while pending:
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for future in finished:
                    results[futures[future]] = future.result()
                    done += 1
                    on_done(done, len(tasks))
        except BaseException:
            for future in pending:
                future.cancel()
            raise
    return results
