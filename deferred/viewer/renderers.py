"""The renderers the viewer draws with, on the window's own GL context: one per pipeline,
light path and size (the full frame, the reduced one while interacting, the split's other
side), made when first needed and kept, so switching back costs nothing. They follow the
scene's edits themselves (:class:`~deferred.render.renderer.Renderer`); a shader edit drops
them all (:meth:`RendererPool.release`), and the next frame compiles again."""

from __future__ import annotations

import time as clock

import moderngl

from deferred.gl.context import GLContext, detect_features
from deferred.names import CascadeUpdates
from deferred.render.renderer import Renderer
from deferred.scene.scene import Scene

Key = tuple[str, str | None, tuple[int, int], int]


class RendererPool:
    def __init__(self, ctx: moderngl.Context):
        self.gl = GLContext(ctx, detect_features(ctx))
        self.renderers: dict[Key, Renderer] = {}
        self.scenes: dict[Key, Scene] = {}

    def get(self, scene: Scene, pipeline: str, light_path: str | None,
            size: tuple[int, int]) -> Renderer:
        key = (pipeline, light_path, size, id(scene))
        renderer = self.renderers.get(key)
        if renderer is None:
            # interactive: far cascades drawn in turn while the camera moves, unless the
            # scene says otherwise (deferred.lighting.shadows.stagger)
            renderer = Renderer(scene, pipeline, size, gl=self.gl, light_path=light_path,
                                cascade_updates=scene.shadow_budget.cascade_updates
                                or CascadeUpdates.STAGGERED)
            renderer.hold_shadow_sizes = True  # live: a size's edge costs no redraw a frame
            self.renderers[key] = renderer
            self.scenes[key] = scene  # held: its id stays unique while the key lives
        return renderer

    def keep_only(self, *scenes: Scene) -> None:
        """Release the renderers of every other scene (one read again replaces the last)."""
        kept = {id(scene) for scene in scenes}
        for key in [k for k in self.renderers if k[3] not in kept]:
            self.renderers.pop(key).release()
            self.scenes.pop(key)

    def release(self) -> None:
        for renderer in self.renderers.values():
            renderer.release()
        self.renderers.clear()
        self.scenes.clear()


def timed_render(renderer: Renderer, time: float) -> dict[str, float]:
    """Render the frame at ``time``, each pass timed by the wall clock around ``ctx.finish()``
    (GL timer queries read nothing on llvmpipe): pass name -> ms."""
    ctx = renderer.gl.ctx
    times: dict[str, float] = {}
    started: list[float] = []

    def before(render_pass, frame) -> None:
        ctx.finish()
        started.append(clock.perf_counter())

    def after(render_pass, frame) -> None:
        ctx.finish()
        times[render_pass.name] = times.get(render_pass.name, 0.0) + \
            (clock.perf_counter() - started[-1]) * 1000.0

    renderer.render(readback=False, time=time, before_pass=before, on_pass=after)
    return times

