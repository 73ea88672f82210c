"""Running one frame's passes: each pass's ``prepare`` once, then the passes in order, with the
GL error flag read once a run of passes of one kind and phase (the frame names the pass that
failed)."""

from __future__ import annotations

from collections.abc import Callable

from deferred.core.frame import Frame
from deferred.core.passes import RenderPass
from deferred.errors import DeferredError, RenderError, gl_error
from deferred.io.safety import raise_if_stop_requested
from deferred.memo import overrides

PassCallback = Callable[[RenderPass, Frame], None]


def prepare_passes(frame: Frame, passes: list[RenderPass]) -> None:
    """Each pass's ``prepare`` (asked of each class once a frame whether it has one, not of
    each pass: a pass an object), naming the pass in a failure."""
    preparing = {cls for cls in {type(p) for p in passes}
                 if overrides(cls, RenderPass, "prepare")}
    for render_pass in passes:
        if type(render_pass) not in preparing:
            continue  # nothing to prepare (most passes: skipping them saves a GL error read)
        try:
            render_pass.prepare(frame)
        except DeferredError:
            raise
        except Exception as exc:  # noqa: BLE001 - a plugin's prepare: say which pass
            raise RenderError(f"pass {render_pass.name}: preparing: "
                              f"{type(exc).__name__}: {exc}") from exc
        error = frame.ctx.error
        if error != "GL_NO_ERROR":
            raise gl_error(f"pass {render_pass.name}: preparing", error,
                           (frame.width, frame.height))


def run_passes(frame: Frame, passes: list[RenderPass], before_pass: PassCallback | None,
               on_pass: PassCallback | None) -> None:
    """Run ``passes`` in order; ``before_pass`` / ``on_pass`` are called around each. The GL
    error flag is read once a run of passes of one kind and phase (the objects' G-buffer
    passes, say), not once a pass: :meth:`Frame.check_errors` names the pass. Hooks look at
    each pass, so with them each is checked."""
    unchecked: list[RenderPass] = []
    hooked = before_pass is not None or on_pass is not None
    for index, render_pass in enumerate(passes):
        raise_if_stop_requested()  # a signal lost in a pass's library or a __del__
        if before_pass:
            before_pass(render_pass, frame)
        try:
            frame.run_pass(render_pass, check_errors=hooked)
        except Exception:
            if unchecked:  # the raised error is the one to report: drop the earlier flag
                _ = frame.ctx.error  # reading it clears it
            raise
        if not hooked:
            unchecked.append(render_pass)
            following = passes[index + 1] if index + 1 < len(passes) else None
            if following is None or type(following) is not type(render_pass) or \
                    following.phase != render_pass.phase:
                frame.check_errors(unchecked)
                unchecked = []
        if on_pass:
            on_pass(render_pass, frame)
    frame.current_pass = None
