"""A command's work weighed before it is done (:mod:`deferred.render.cost`): before the scene's
meshes load, what is known of it is refused past the time budget (a lower bound: the work
over the objects' pixels is not known yet); once they load, before the renderer is made, the
whole prediction is refused past the budget or warned of past a minute. While samples or frames
render, :class:`StepClock` estimates the time left from the prediction, then from the steps
measured."""

from __future__ import annotations

import statistics
import time
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING

from deferred.interfaces.work import RenderWork, WorkObject
from deferred.io.cost import Prediction, WorkWarning, check_time
from deferred.render.cost import RENDER_OPTIONS, loaded_objects, predict_render
from deferred.scene.timeline import SceneEvaluator

if TYPE_CHECKING:
    from deferred.scene import Scene

RENDER_REMEDY = ("fewer --samples or --frames, a smaller --size or lighter settings of the key "
                 "named, or a larger budget")


def render_work(size: tuple[int, int], samples: int, times: list[float],
                pipeline: str) -> RenderWork:
    """The work ``deferred render`` asks for, as the cost model counts it."""
    return RenderWork(size=size, samples=samples, frames=len(times),
                      latest_time=max(times, default=0.0), pipeline=pipeline, time_key="--time")


def before_meshes(size: tuple[int, int] | None, samples: int, times: list[float],
                  pipeline: str, command: str = "render"
                  ) -> Callable[[Scene, list[WorkObject]], None]:
    """The check a scene's loader makes before its meshes load (``load_scene``'s
    ``before_meshes``): the work known then (the meshes' triangles from their specs, the
    simulations' steps, the frame's own passes) refused past the budget; ``size`` None is the
    scene's."""

    def check(scene: Scene, objects: list[WorkObject]) -> None:
        frame = size or scene.size
        where = "--size" if size is not None else f"{scene.source}: size"
        prediction = predict_render(render_work(frame, samples, times, pipeline),
                                    scene.lights, scene.effects, objects, where)
        check_time(prediction, command, RENDER_REMEDY, RENDER_OPTIONS)

    return check


def check_render(scene: Scene, size: tuple[int, int], samples: int, times: list[float],
                 pipeline: str, size_given: bool, command: str = "render"
                 ) -> tuple[Prediction, str | None]:
    """The whole prediction of rendering the loaded ``scene``, refused past the budget, and
    the warning to give past :data:`~deferred.io.cost.WARN_SECONDS` (:func:`warn`, once the
    other checks pass) or None."""
    state = SceneEvaluator(scene).evaluate(min(times, default=0.0))
    where = "--size" if size_given else f"{scene.source}: size"
    prediction = predict_render(render_work(size, samples, times, pipeline), state.lights,
                                state.effects, loaded_objects(state, size), where)
    return prediction, check_time(prediction, command, RENDER_REMEDY, RENDER_OPTIONS)


def warn(said: str | None) -> None:
    """Say a long prediction (a :class:`WorkWarning`), once the work is about to start."""
    if said is not None:
        warnings.warn(said, WorkWarning, stacklevel=2)


class StepClock:
    """The time left of ``total`` steps (samples or frames): before two have been measured,
    ``predicted`` seconds a step; then the median of the steps measured after the first
    (which compiles the shaders and settles the simulations)."""

    def __init__(self, total: int, predicted: float, clock: Callable[[], float] =
                 time.perf_counter):
        self.total = total
        self.predicted = predicted
        self.clock = clock
        self.steps: list[float] = []
        self._last = clock()

    def start(self) -> None:
        self._last = self.clock()

    def done(self, count: int) -> float:
        """``count`` steps are done: the seconds left."""
        now = self.clock()
        self.steps.append(now - self._last)
        self._last = now
        measured = self.steps[1:]
        step = statistics.median(measured) if measured else self.predicted
        return max(self.total - count, 0) * step
