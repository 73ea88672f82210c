"""A sweep weighed before it runs: the memory of the renderers it keeps alive at once and the
time of all its frames, against the memory and time budgets.

Interleaved (``--interleave``), a shell count's points are timed together, every point's
renderer alive at once. Each renderer holds its targets and what the budget counts
(``Renderer.memory_bytes``) and more that it does not see: its compiled programs and the
driver's state for them (:func:`~deferred.render.budget.renderer_overhead`). The points are
counted at the most lights their light path is swept with (an upper bound of each) before any
is made, and timed in as few groups as fit the memory budget: a sweep that cannot hold every
renderer at once interleaves fewer, rather than outgrowing the machine.

The time is the model's (``deferred.render.cost``): each point's set-up, then its warm-up
frames and, each round, its frames timed back to back for ``round_ms`` (one to
``ROUND_FRAMES``), one with its passes fenced, one of CPU time and one with timer queries, a
frame at the model's time of one sample of that point. Past the time budget the sweep is
refused naming ``--runs``, the option that multiplies it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from deferred.gl.target_spec import targets_bytes
from deferred.interfaces.work import RenderWork
from deferred.io.cost import Per, Prediction, Work
from deferred.io.memory import memory_budget
from deferred.render.budget import renderer_overhead
from deferred.render.cost import SPHERE_LIGHT_PIXEL_SECONDS, loaded_objects, predict_render
from deferred.render.setup import SetupPlan
from deferred.scene.scene import Scene
from deferred.scene.timeline import SceneEvaluator

ROUND_FRAMES = 5  # the most frames a point renders back to back in a round
FENCED_FRAMES = 3  # each round: the passes fenced, the CPU time, the timer queries
BENCH_REMEDY = "fewer --runs, --lights or --light-paths, a smaller --size, or a larger budget"

Point = tuple[int, str, str]  # (lights, pipeline, light path)


def point_bytes(scene: Scene, pipeline: str, light_path: str, size: tuple[int, int]) -> int:
    """What a renderer of ``scene`` holds, as its plan counts it (no GL object is made): its
    targets, what the budget counts besides, and its programs' overhead. A point past the
    budget alone is refused here, as its renderer would be."""
    state = SceneEvaluator(scene).evaluate(0.0)
    plan = SetupPlan(state, pipeline, light_path, size, "--size")
    return targets_bytes(plan.graph.targets.values(), *size) + plan.held_bytes + \
        renderer_overhead(state)


def interleaved_groups(points: Sequence[Point], largest_scene: Scene,
                       size: tuple[int, int]) -> tuple[list[list[Point]], int]:
    """``points`` in as few groups as the memory budget holds at once (each point counted as
    its light path's renderer with every light of the sweep, ``largest_scene``), and the
    bytes of all of them together."""
    sizes: dict[tuple[str, str], int] = {}
    for _, pipeline, path in points:
        if (pipeline, path) not in sizes:
            sizes[pipeline, path] = point_bytes(largest_scene, pipeline, path, size)
    budget = memory_budget()
    groups: list[list[Point]] = [[]]
    held = 0
    for point in points:
        needed = sizes[point[1], point[2]]
        if groups[-1] and held + needed > budget:
            groups.append([])
            held = 0
        groups[-1].append(point)
        held += needed
    return groups, sum(sizes[p[1], p[2]] for p in points)


def round_frames(frame_seconds: float, round_ms: float) -> int:
    """Frames a point renders in a round: timed ones back to back until they make
    ``round_ms`` (one to ``ROUND_FRAMES``), and the fenced ones."""
    timed = 1 if round_ms <= 0.0 else min(ROUND_FRAMES, max(1, math.ceil(
        round_ms / 1000.0 / max(frame_seconds, 1e-6))))
    return timed + FENCED_FRAMES


def predict_sweep(scene: Scene, points: Sequence[Point], shell_counts: int,
                  size: tuple[int, int], runs: int, warmup: int, round_ms: float) -> Prediction:
    """The sweep's time: each point's set-up, warm-up and rounds at the model's frame time
    (its scene's own objects, lights and effects, and its extra point lights), for each of
    ``shell_counts`` shell counts (counted at the scene's own)."""
    state = SceneEvaluator(scene).evaluate(0.0)
    base = predict_render(RenderWork(size=size), state.lights, state.effects,
                          loaded_objects(state, size))
    # the context, the programs, a simulation settling: once a renderer
    setup = sum(work.seconds for work in base.works if work.per is Per.RENDER)
    pixels = size[0] * size[1]
    works = []
    for lights, pipeline, path in points:
        frame = base.sample_seconds() + lights * pixels * SPHERE_LIGHT_PIXEL_SECONDS
        frames = warmup + runs * round_frames(frame, round_ms)
        works.append(Work(f"{pipeline} ({path}), {lights:,} lights: {frames:,} frames",
                          shell_counts * (setup + frames * frame), 1.0, "--runs", Per.RENDER))
    return Prediction(tuple(works))
