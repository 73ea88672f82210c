"""The effect interface: scene-wide screen and post passes (pygfx's effect passes).

An effect is a class with a unique ``name`` (the scene file's ``[[effect]] type``), a validated
``Params`` model and ``passes(scene, pipeline)``: the passes it adds, in any phase (typically
``screen``, over the clean G-buffer before any stipple, and ``post``, over the tone-mapped frame),
ranked by ``Order`` within the phase. Parameters become ``u_<field>`` uniforms
(:mod:`deferred.params`), offered to each pass given ``uniforms=self.uniforms``: a pass's program
gets those it declares (each of an effect's programs may use some of them; in strict mode each
parameter must be declared by one of them). ``pipelines`` names the pipelines it applies to
(an effect reading the G-buffer has nothing to read in the forward pipeline). Register with
``@deferred.api.effects.register`` or the entry-point group ``deferred.effects``.

A screen effect that creates the target ``ssao`` (:data:`AMBIENT_OCCLUSION`) feeds the
ambient light, whichever effect it is.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from pydantic import Field

from deferred.core.frame import OfferedUniforms
from deferred.interfaces.work import EFFECT_PIXEL_SECONDS, Per, RenderWork, Work, counted
from deferred.names import Pipeline
from deferred.params import Params, UniformOverrides, params_uniforms, validate_params
from deferred.revision import Revisioned

if sys.version_info >= (3, 11):
    from importlib.resources.abc import Traversable
else:  # Python 3.10
    from importlib.abc import Traversable

if TYPE_CHECKING:
    from deferred.core.frame import Frame
    from deferred.core.passes import RenderPass
    from deferred.core.protocols import SceneLike

AMBIENT_OCCLUSION = "ssao"


def halton(index: int, base: int) -> float:
    """The radical inverse of ``index`` in ``base`` (the Halton sequence's term: sub-pixel
    offsets of temporal effects and accumulated samples)."""
    result, fraction = 0.0, 1.0 / base
    while index > 0:
        result += fraction * (index % base)
        index //= base
        fraction /= base
    return result


@dataclass(frozen=True)
class FrameMoment:
    """What a temporal effect compares between two frames: the time and the camera (with its
    view-projection at the frame's aspect); ``step`` is the time since the frame before it
    (None for the first frame of a history)."""

    time: float
    camera: Any
    view_projection: Any
    step: float | None = None


class EffectParams(Params):
    """Base of every effect's parameter model."""


class GBufferEffectParams(EffectParams):
    """An effect reading the G-buffer (``Effect.reads_gbuffer``): whether it runs in the
    forward pipeline too."""

    forward: bool = Field(False, description="run in the forward pipeline too, over a "
                          "G-buffer its objects' G-buffer passes write first")


class Effect(Revisioned):
    """A scene-level effect (``[[effect]]`` in a scene file): a ``name``, a validated
    ``Params`` model and the passes it adds to a pipeline (:meth:`passes`, in any phase).
    ``pipelines`` names the pipelines it applies to; the others skip it with a warning.
    """

    name: ClassVar[str]
    Params: ClassVar[type[EffectParams]] = EffectParams
    pipelines: ClassVar[tuple[str, ...]] = tuple(Pipeline)
    # Its passes read the G-buffer (depth, normals, surface ids: SSAO, edges). With
    # GBufferEffectParams' ``forward = true`` it runs in the forward pipeline too, which then
    # writes the G-buffer first: the objects' G-buffer passes (geometry phase) and the screen
    # phase run before the lit passes (which then need no depth pre-pass), and a screen
    # effect's ambient occlusion reaches the opaque lit passes.
    reads_gbuffer: ClassVar[bool] = False
    shader_root: ClassVar[Traversable | Path | None] = None
    uniform_overrides: ClassVar[UniformOverrides] = {}
    type_id: ClassVar[int] = 0  # set by the registry
    # A temporal effect (taa) keeps history from frame to frame: the renderer then moves the
    # projection by jitter(index) each frame and passes count samples since the history
    # started (Frame.sample_index), which it starts again where keeps_history says no.
    temporal: ClassVar[bool] = False

    def __init__(self, params: EffectParams | None = None):
        self.params = params if params is not None else self.Params()

    @classmethod
    def from_dict(cls, values: dict[str, Any], where: str | None = None) -> Effect:
        return cls(validate_params(cls.Params, values, where))

    def applies_to(self, pipeline: str) -> bool:
        """Whether the effect runs in ``pipeline``: one of its ``pipelines``, or the forward
        pipeline where it reads the G-buffer and its params say ``forward``."""
        return pipeline in self.pipelines or (
            self.reads_gbuffer and pipeline == Pipeline.FORWARD and
            bool(getattr(self.params, "forward", False)))

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        """``u_<field>`` for every parameter that is a uniform, offered to a pass's program
        (:class:`~deferred.core.frame.OfferedUniforms`: set where the program declares them).
        An override adding values keeps them offered with ``self.offer({...})``."""
        return self.offer(params_uniforms(self.params, self.uniform_overrides))

    def offer(self, values: dict[str, Any]) -> OfferedUniforms:
        """``values`` offered to each pass of the effect: a pass's program gets the ones it
        declares, not an error for the others in strict mode."""
        return OfferedUniforms(values, f"effect {self.name}")

    def passes(self, scene: SceneLike, pipeline: str) -> list[RenderPass]:
        raise NotImplementedError

    def held_memory(self, size: tuple[int, int]) -> dict[str, int]:
        """Bytes the effect holds outside the pass graph's targets at frame ``size`` (a
        history kept from frame to frame), by what they are; counted with the render targets
        against the memory budget. By default nothing."""
        return {}

    def work(self, job: RenderWork) -> list[Work]:
        """The work of the effect's passes in a render ``job``, as the cost model counts it
        (:mod:`deferred.interfaces.work`): by default its passes over every pixel once a
        sample."""
        return [Work(f"effect {self.name}: {counted(job.pixels)} pixels", job.pixels,
                     EFFECT_PIXEL_SECONDS, f"effect {self.name}", Per.SAMPLE)]

    def jitter(self, index: int) -> tuple[float, float]:
        """A temporal effect's sub-pixel offset (x, y in pixels) of sample ``index`` since the
        history started."""
        return (0.0, 0.0)

    def keeps_history(self, previous: FrameMoment, current: FrameMoment) -> bool:
        """A temporal effect's answer to whether ``current`` follows ``previous`` closely
        enough for the history to carry over (no cut, no seek)."""
        return True
