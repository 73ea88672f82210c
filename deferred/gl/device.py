"""The device: the GL state a frame sets, its framebuffers, its draws and dispatches, their
barriers and timing.

A frame makes one :class:`Device` and sets fixed-function state, binds framebuffers and draws
through it, so it knows what GL holds and sets nothing twice (a pass that changes other GL
state, the light volumes' depth clamp, restores it): a pass stating the state the
last one did, or asking for the framebuffer still bound, costs a comparison (one program drawing
many objects). It also counts the draws (:class:`FrameStats`) and, when asked, the CPU time of
the GL calls that draw (the bench's ``gl_call_seconds``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import moderngl

from deferred.gl.blend import IndexedBlend, PassBlend, blend_outputs, shared_blend
from deferred.gl.meshes import MeshData
from deferred.gl.resources import Resources
from deferred.gl.targets import FrameTargets

DEPTH_FUNCS = {"less": "<", "lequal": "<=", "gequal": ">=", "greater": ">", "equal": "==",
               "always": "1"}


@dataclass
class FrameStats:
    draw_calls: int = 0
    draws_by_pass: dict[str, int] = field(default_factory=dict)
    # CPU seconds of this thread inside the GL calls that do the drawing (draws, dispatches,
    # clears, framebuffer binds, copies; llvmpipe runs vertex work and binning there, and a
    # framebuffer bind hands the last one's scene to the rasteriser): the bench subtracts them
    # from the frame's thread time to get the framework's own CPU time
    gl_call_seconds: float = 0.0


class Device:
    """One frame's GL state cache, framebuffers, draws and their timing (module docstring)."""

    def __init__(self, ctx: moderngl.Context, targets: FrameTargets, resources: Resources,
                 time_gl_calls: bool = False):
        self.ctx = ctx
        self.targets = targets
        self.resources = resources
        self.stats = FrameStats()
        self.time_gl_calls = time_gl_calls  # FrameStats.gl_call_seconds
        # what this frame set last: a pass stating the same is not set again (set_state)
        self._state: tuple | None = None
        self._framebuffers: dict[tuple, tuple[moderngl.Framebuffer, tuple]] = {}
        # whether GL's depth mask is the bound framebuffer's: a clear through another
        # framebuffer (moderngl's clear) sets GL's and binds this one back without it
        self._depth_mask_known = False
        # the last framebuffer request set in full, (key, depth_write, framebuffer, viewport):
        # the same request again, with nothing changed since, sets nothing (use_framebuffer)
        self._bound: tuple | None = None
        self._indexed_blend: IndexedBlend | None = None  # loaded at the first per-output state

    # -- timing ----------------------------------------------------------------------------------
    def gl_call(self, call: Callable[[], Any]) -> Any:
        """Run a drawing GL call, its time counted apart (``FrameStats.gl_call_seconds``)
        when the frame measures it."""
        if not self.time_gl_calls:
            return call()
        start = time.thread_time()
        try:
            return call()
        finally:
            self.stats.gl_call_seconds += time.thread_time() - start

    def count_draw(self) -> None:
        """Count a draw call (passes drawing by other means than the device call it)."""
        self.stats.draw_calls += 1

    # -- targets and framebuffers ------------------------------------------------------------
    def clear(self, name: str) -> None:
        """Clear target ``name`` to its declared value."""
        self.gl_call(lambda: self.targets.clear(name))
        self._depth_mask_known = False
        self._bound = None

    def use_framebuffer(self, colors: tuple[str, ...], depth: str | None = None,
                        depth_write: bool = True) -> moderngl.Framebuffer:
        """Bind the framebuffer of these targets with this depth mask and its full viewport."""
        key = (colors, depth)
        bound = self._bound
        # one pass of many objects after another: the same request, still bound, no clear
        # since, and the framebuffer's mask and viewport as this frame left them (a pass may
        # have set them on it): nothing to look up or set
        if bound is not None and bound[0] == key and bound[1] == depth_write:
            fbo = bound[2]
            if self.ctx.fbo is fbo and fbo.depth_mask == depth_write and \
                    fbo.viewport == bound[3]:
                return fbo
        known = self._framebuffers.get(key)
        if known is None:  # once a frame: the targets' scissor is set on it then
            fbo = self.targets.framebuffer(colors, depth)
            known = self._framebuffers[key] = (fbo, (0, 0, *fbo.size))
        fbo, full = known
        if self.ctx.fbo is not fbo:  # binding a framebuffer ends llvmpipe's scene: GL work
            self.gl_call(fbo.use)  # which sets GL's depth mask to the framebuffer's
            self._depth_mask_known = True
        # the framebuffer keeps its mask: set only when it changes, not a GL call a draw
        if fbo.depth_mask != depth_write or not self._depth_mask_known:
            fbo.depth_mask = depth_write
            self._depth_mask_known = True
        if fbo.viewport != full:
            fbo.viewport = full
        self._bound = (key, depth_write, fbo, full)
        return fbo

    # -- fixed-function state ----------------------------------------------------------------
    def set_state(self, depth_test: bool = False, depth_func: str = "less",
                  cull: str | None = None, blend: PassBlend = None,
                  depth_offset: tuple[float, float] = (0.0, 0.0)) -> None:
        """Set the fixed-function state a pass needs; every pass states all of it. The frame
        sets GL state only here and in :meth:`set_depth_offset`, so a pass stating what the
        last one did sets nothing (one program drawing many objects). ``blend`` is any form
        :mod:`deferred.gl.blend` takes; a tuple gives each draw buffer of the bound
        framebuffer its own state."""
        state = (depth_test, depth_func, cull, blend, depth_offset)
        if state == self._state:
            return
        self._state = state
        self.ctx.polygon_offset = depth_offset
        flags = moderngl.NOTHING
        if depth_test:
            flags |= moderngl.DEPTH_TEST
            self.ctx.depth_func = DEPTH_FUNCS[depth_func]
        if cull:
            flags |= moderngl.CULL_FACE
            self.ctx.cull_face = cull
        if blend is None:
            self.ctx.enable_only(flags)
            return
        if isinstance(blend, str) or not isinstance(blend, (tuple, list)):
            states = blend_outputs(blend, 1)
        else:
            states = blend_outputs(blend, len(blend))
        shared, single = shared_blend(states)
        if shared and single is None:
            self.ctx.enable_only(flags)
            return
        flags |= moderngl.BLEND
        if shared:  # one state for every draw buffer: GL's plain calls
            self.ctx.blend_func = single.factors
            self.ctx.blend_equation = single.equations
            self.ctx.enable_only(flags)
            return
        self.ctx.enable_only(flags)  # blending on for every buffer, then each buffer's own
        if self._indexed_blend is None:
            self._indexed_blend = IndexedBlend(self.ctx)
        self._indexed_blend.apply(states)

    def set_depth_offset(self, depth_offset: tuple[float, float]) -> None:
        """Change only the depth offset (``glPolygonOffset``) of the state the pass set, for
        draws of one pass that differ in it (the root shell)."""
        if self._state is None or self._state[4] != depth_offset:
            self.ctx.polygon_offset = depth_offset
        if self._state is not None:
            self._state = (*self._state[:4], depth_offset)

    # -- draws -------------------------------------------------------------------------------
    def draw_mesh(self, mesh: MeshData, program: moderngl.Program, instances: int = 1) -> None:
        vertex_array = self.resources.gpu_mesh(mesh).vertex_array(program)
        if self.time_gl_calls:  # gl_call inlined: no closure a draw
            start = time.thread_time()
            vertex_array.render(moderngl.TRIANGLES, instances=instances)
            self.stats.gl_call_seconds += time.thread_time() - start
        else:
            vertex_array.render(moderngl.TRIANGLES, instances=instances)
        self.stats.draw_calls += 1

    def draw_fullscreen(self, program: moderngl.Program, instances: int = 1) -> None:
        vao = self.resources.fullscreen_vertex_array(program)
        self.gl_call(lambda: vao.render(moderngl.TRIANGLES, vertices=3, instances=instances))
        self.stats.draw_calls += 1

    # -- compute -----------------------------------------------------------------------------
    def dispatch(self, shader: moderngl.ComputeShader, groups: tuple[int, int, int]) -> None:
        """Run ``shader`` over ``groups`` work groups (timed as a drawing call; a pass counts
        its dispatches as draws itself, with :meth:`count_draw`)."""
        self.gl_call(lambda: shader.run(*groups))

    def barrier(self) -> None:
        """Make what shaders wrote to images and buffers visible to the GL work after it."""
        self.ctx.memory_barrier()
