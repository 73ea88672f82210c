"""What a renderer keeps from one frame for the next: the time, the camera and the objects'
models of the last frame rendered, for motion vectors (``u_previous_model``,
``u_previous_view_projection``: ``shaders/common/motion.glsl``) and for a temporal effect's
history (:attr:`deferred.interfaces.effect.Effect.temporal`: taa).

A history starts again (sample index 0, the last frame's matrices forgotten, so nothing moves)
where the scene has no temporal effect or the effect says the frame does not follow the last
(a cut: the camera jumped; a seek: a time that is not the next frame's).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from deferred.interfaces.effect import Effect, FrameMoment

if TYPE_CHECKING:
    from deferred.scene.state import FrameState


@dataclass
class FrameHistory:
    """One frame's place in its history: whether it carries the last frame's history on,
    its sample index since the history started, and the last frame's matrices (this frame's
    own where the history starts)."""

    kept: bool
    index: int
    moment: FrameMoment
    previous_view_projection: np.ndarray
    previous_models: dict[Any, np.ndarray] = field(default_factory=dict)  # by node


def temporal_effect(scene: FrameState) -> Effect | None:
    """The scene's first temporal effect, if any."""
    return next((effect for effect in scene.effects if effect.temporal), None)


class TemporalState:
    """The last frame's time, camera and models (kept by a renderer across frames)."""

    def __init__(self) -> None:
        self.moment: FrameMoment | None = None
        self.index = 0
        self.models: dict[Any, np.ndarray] = {}  # world matrices by node

    def reset(self) -> None:
        """Forget the last frame: the next starts a history (each of render_samples'
        renders stands alone)."""
        self.moment = None

    def begin(self, scene: FrameState, time: float, aspect: float) -> FrameHistory:
        """The frame at ``time``'s place in the history, before it is drawn."""
        camera = scene.camera
        view_projection = np.asarray(camera.projection(aspect)) @ np.asarray(camera.view())
        previous = self.moment
        step = None if previous is None else time - previous.time
        moment = FrameMoment(time, camera, view_projection, step)
        effect = temporal_effect(scene)
        if effect is not None and previous is not None and \
                effect.keeps_history(previous, moment):
            return FrameHistory(True, self.index + 1, moment, previous.view_projection,
                                self.models)
        return FrameHistory(False, 0, replace(moment, step=None), view_projection)

    def end(self, history: FrameHistory, scene: FrameState) -> None:
        """Keep the frame just drawn as the last one (its world matrices are read-only values:
        kept, not copied)."""
        self.moment = history.moment
        self.index = history.index
        self.models = {obj.node: obj.model for obj in scene.objects}
