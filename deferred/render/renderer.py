"""The renderer: renders one scene with one pipeline, frame after frame, on one GL context.

Each frame evaluates the user's scene at the frame's time into an immutable frame state
(:class:`deferred.scene.timeline.SceneEvaluator`): the frame's passes read that state only, and
nothing is written back into the scene. Between frames the renderer compares the state with the
one its passes were built from: a change of structure (objects, meshes, material types, light
types, shadows, effects, background, tone mapping, size; :func:`~deferred.render.setup.
structure_key`) or parameters that add or remove passes build a new :class:`~deferred.render.
setup.RenderSetup` on the same context; parameters that only change values need nothing.
"""

from __future__ import annotations

import math
import numbers
import os
import warnings
import weakref
from collections.abc import Callable

import numpy as np

from deferred.core.frame import Frame
from deferred.core.graph import PassGraph, PassGraphError
from deferred.core.passes import RenderPass
from deferred.errors import InputError, RenderError, gl_error
from deferred.gl.context import GLContext, acquire_context, give_back_context
from deferred.gl.target_spec import targets_bytes
from deferred.gl.targets import COMPOSITE, FINAL
from deferred.interfaces.material import Material
from deferred.interfaces.simulation import advance_simulations
from deferred.io.safety import raise_if_stop_requested
from deferred.lighting.shadows.stagger import check_cascade_updates
from deferred.names import CascadeUpdates, Pipeline
from deferred.render import samples as sampling
from deferred.render.budget import check_target_memory, held_memory, renderer_holdings
from deferred.render.caches import (
    FrameInputs,
    KeptMaterialInputs,
    ObjectTransforms,
    ShadingTextures,
)
from deferred.render.frame_run import PassCallback, prepare_passes, run_passes
from deferred.render.pipeline import PIPELINES, sort_blended
from deferred.render.result import RenderResult
from deferred.render.samples import MAX_SAMPLES, halton, halton_offsets, render_samples
from deferred.render.scene_values import check_scene_values
from deferred.render.setup import (
    FULL_FEATURES,
    RenderSetup,
    SetupPlan,
    object_pass_names,
    structure_key,
)
from deferred.render.temporal import TemporalState, temporal_effect
from deferred.scene.scene import Scene
from deferred.scene.size import check_size
from deferred.scene.state import FrameState
from deferred.scene.timeline import SceneEvaluator

__all__ = ["FULL_FEATURES", "MAX_SAMPLES", "PassCallback", "RenderResult", "Renderer",
           "check_target_memory", "halton", "halton_offsets", "held_memory", "render_scene",
           "renderer_holdings"]

def strict_default() -> bool:
    """Whether renderers are strict when not told: ``DEFERRED_STRICT=1`` (the tests set it)."""
    return os.environ.get("DEFERRED_STRICT", "") in ("1", "true", "yes")


def _restarts(material_cls: type[Material], before: object, after: object) -> bool:
    """Whether new parameters need the material's state made again: one it reads once
    (``timeline_fixed``) changed, or a count that only rises (``timeline_growing``) fell."""
    return any(getattr(before, key) != getattr(after, key)
               for key in material_cls.timeline_fixed) or \
        any(getattr(after, key) < getattr(before, key) for key in material_cls.timeline_growing)


def _frame_time(time: object) -> float:
    if isinstance(time, bool) or not isinstance(time, numbers.Real) or \
            not math.isfinite(time) or time < 0.0:
        raise InputError(f"frame time must be a finite number of seconds >= 0, got {time!r}",
                         "time")
    return float(time)


class Renderer:
    """Renders one scene with one pipeline; reuse it for many frames, then ``release()``.

    ``strict`` turns a uniform set by name that a program does not declare into an error
    (default: the ``DEFERRED_STRICT`` environment variable). ``light_path`` chooses how lights
    reach the pixels (:mod:`deferred.lighting.paths`; default: the scene's ``light_path``, else
    the fastest the context allows). ``cascade_updates``: ``"every_frame"`` or ``"staggered"``
    (a frame then reads far cascades drawn by the frames before it;
    :mod:`deferred.lighting.shadows.stagger`); default: the scene's, else every frame.

    The scene may change between frames: objects, groups, lights and effects added or removed
    (``Scene.add_object``, ``add_light``, ``remove``), materials' parameters
    (``SceneObject.set_params``), placements and parents, the camera, the background, the tone
    mapping operator. Each frame picks the changes up; where they change what the passes are
    built from (another object, light type or effect, parameters that add or remove passes,
    the background, which is the clear value of targets, the operator, a define), the renderer
    builds its passes, targets and programs again on the same context first (:meth:`render`).
    The renderer never writes to the scene: ``state`` is the scene as its last frame drew it.

    ``hold_shadow_sizes`` (the live viewer's) keeps shadow maps' sizes by coverage within a
    margin from frame to frame (a frame then depends on those before it: off for renders).
    """

    hold_shadow_sizes = False

    def __init__(self, scene: Scene, pipeline: str = Pipeline.DEFERRED,
                 size: tuple[int, int] | None = None, gl: GLContext | None = None,
                 strict: bool | None = None, light_path: str | None = None,
                 cascade_updates: str | None = None):
        self._released = False
        self.cascade_updates = check_cascade_updates(cascade_updates, "cascade_updates")
        if pipeline not in PIPELINES:
            raise InputError(f"unknown pipeline '{pipeline}' (choose from "
                             f"{', '.join(PIPELINES)})", "pipeline")
        check_scene_values(scene)
        self.scene = scene
        self._scene_checked = scene.revision
        self.pipeline_name = pipeline
        self._size_arg, self._light_path_arg = size, light_path  # for a rebuild
        self._times_checked: tuple[float, tuple] | None = None  # check_times' last pass
        self._inserted: list[tuple[RenderPass, str | None, str | None]] = []  # insert_pass's
        self.strict = strict_default() if strict is None else strict
        given = size is not None
        # where the frame size came from, for errors about it
        self.size_where = "size" if given else f"{scene.source}: size"
        self.size = check_size(size if given else scene.size, self.size_where)
        self.evaluator = SceneEvaluator(scene)
        self.state: FrameState = self.evaluator.evaluate(0.0)
        # The pass graph and the generated GLSL are built and checked before any GL object
        # exists: bad input never leaves a context behind.
        plan = self._plan(self.state)
        self._owns_context = gl is None
        self.gl = gl or acquire_context()
        self.gl.make_current()
        try:
            self._setup = RenderSetup(plan, self.gl)
        except BaseException:
            # nothing made here outlives a failed constructor, and the context goes back
            self._release_partial()
            raise
        self._start_over()
        self._frame_number = 0
        self._camera_values: dict | None = None  # the last frame's (Frame: kept_camera_values)
        self._pending_hdr: weakref.ref[RenderResult] | None = None
        self._note_built(self.state)

    def _plan(self, state: FrameState) -> SetupPlan:
        requested = self._light_path_arg if self._light_path_arg is not None else \
            state.light_path
        return SetupPlan(state, self.pipeline_name, requested, self.size, self.size_where)

    def _start_over(self) -> None:
        """What frames keep from one to the next, empty: transforms, materials' inputs, the
        temporal history."""
        self.object_transforms = ObjectTransforms()
        self.kept_inputs = KeptMaterialInputs()
        self.temporal = TemporalState()  # the last frame's time, camera and models
        self.last_frame: Frame | None = None

    # -- the parts of the setup, by name ---------------------------------------------------------
    graph: PassGraph = property(lambda self: self._setup.graph)  # type: ignore[assignment]
    pipeline = property(lambda self: self._setup.pipeline)
    light_path = property(lambda self: self._setup.light_path)
    shaders = property(lambda self: self._setup.shaders)
    targets = property(lambda self: self._setup.targets)
    resources = property(lambda self: self._setup.resources)
    light_buffer = property(lambda self: self._setup.light_buffer)
    light_lists = property(lambda self: self._setup.light_lists)
    shadow_atlas = property(lambda self: self._setup.shadow_atlas)
    blackboard = property(lambda self: self._setup.blackboard)
    binding_sources = property(lambda self: self._setup.binding_sources)
    shading_models = property(lambda self: self._setup.shading_models)

    @property
    def passes(self) -> list[RenderPass]:
        return self._setup.graph.passes

    # -- following the scene -------------------------------------------------------------------
    def _note_built(self, state: FrameState) -> None:
        """Keep what the passes were built from."""
        self._structure = structure_key(state, self.pipeline_name, self._light_path_arg,
                                        self._size_arg)
        self._params_seen = {obj.node: obj.params for obj in state.objects}
        self._passes_seen = {obj.node: object_pass_names(obj) for obj in state.objects}

    def _follow(self, state: FrameState) -> None:
        """Rebuild before a frame where the scene changed in what the passes are built from;
        parameters that only change values (uniforms, defines) need nothing here."""
        if structure_key(state, self.pipeline_name, self._light_path_arg,
                         self._size_arg) != self._structure:
            self._rebuild(state)
            return
        edited = {}
        for obj in state.objects:
            params = obj.params
            seen = self._params_seen.get(obj.node)
            if params is seen:
                continue
            if object_pass_names(obj) != self._passes_seen.get(obj.node) or \
                    (seen is not None and _restarts(type(obj.material), seen, params)):
                self._rebuild(state)
                return
            edited[obj.node] = params
        if edited:
            self._count_held_memory(state)  # an edited texture or mask size may not fit
            self._params_seen.update(edited)  # seen once they are known to fit

    def _count_held_memory(self, state: FrameState) -> None:
        """Count what the renderer holds again and check it against the budget."""
        held = renderer_holdings(state, self.pipeline_name, self.size)
        check_target_memory(self.graph, self.size, self.size_where, held, state.source)
        self._setup.held_bytes = sum(held.values())

    def _rebuild(self, state: FrameState) -> None:
        """A setup built afresh for the scene on this renderer's context takes the place of
        the one it has (which is kept if that fails); passes inserted with insert_pass are
        inserted again; what frames kept starts over (simulations too)."""
        setup = RenderSetup(self._plan(state), self.gl)
        try:
            for render_pass, before, after in self._inserted:
                try:
                    setup.insert_pass(render_pass, before, after)
                except PassGraphError as exc:
                    raise PassGraphError(f"pass {render_pass.name}, inserted with insert_pass, "
                                         f"no longer fits the changed scene: {exc}") from None
        except BaseException:
            setup.release()
            raise
        self._release_parts()
        self._setup = setup
        self._start_over()
        self._frame_number += 1  # results of earlier frames cannot read these targets
        self._note_built(state)

    def _release_partial(self) -> None:
        self.release()  # an owned context is released instead where it holds a GL error
        if not self._owns_context:
            _ = self.gl.ctx.error  # reading clears it: the caller's next renderer starts clean

    def memory_bytes(self) -> int:
        """What the renderer holds as the memory budget counts it: its render targets and the
        materials' textures and state, the shadow maps and the effects' histories
        (:func:`renderer_holdings`, counted again when parameters change)."""
        return targets_bytes(self.graph.targets.values(), *self.size) + self._setup.held_bytes

    def insert_pass(self, render_pass: RenderPass, *, before: str | None = None,
                    after: str | None = None) -> None:
        """Insert ``render_pass`` before or after the pass named so; the graph is checked again
        (and left as it was if the new pass does not fit) and new targets are created."""
        self._check_alive()
        if (before is None) == (after is None):
            raise TypeError("insert_pass needs exactly one of before= or after=")
        self.gl.make_current()
        self._setup.insert_pass(render_pass, before, after)
        self._inserted.append((render_pass, before, after))

    # -- frames --------------------------------------------------------------------------------
    def state_at(self, time: float) -> FrameState:
        """The scene evaluated at ``time``, the renderer made ready to draw it: the times'
        checks (:meth:`check_times`), the scene's values where the user changed them, a
        rebuild where its structure changed."""
        if self.scene.revision != self._scene_checked:
            check_scene_values(self.scene)
            self._scene_checked = self.scene.revision
        self.check_times([time], "time")
        state = self.evaluator.evaluate(time)
        self._follow(state)
        return state

    def render(self, on_pass: PassCallback | None = None,
               before_pass: PassCallback | None = None, readback: bool = True,
               time: float = 0.0, time_gl_calls: bool = False,
               hdr: bool = False, jitter: tuple[float, float] | None = None,
               sample_index: int | None = None) -> RenderResult:
        """Run every pass once for the frame at ``time`` (seconds: the scene is evaluated at
        that time, and passes see it as ``frame.time`` and ``frame.scene``, the frame state).
        ``on_pass``/``before_pass`` are called around each pass; ``readback=False`` skips
        reading the images back (timing loops); ``hdr=True`` reads the float composite now
        (else when ``result.hdr`` is first asked for); ``jitter`` moves the image by a
        fraction of a pixel (x, y within +-1, :meth:`render_samples`; by default none, or a
        temporal effect's (taa) for the frame's sample since its history started); ``sample_index``
        picks per-sample patterns (the stipple's parity; by default that sample, else 0);
        ``time_gl_calls`` measures the CPU time of the drawing GL calls
        (``RenderResult.gl_call_seconds``, for the bench: two clock reads per call).

        Changes to the scene since the last frame are picked up first: objects, lights and
        effects added or removed, a material or mesh replaced, parameters that add or remove
        passes, a new background, tone mapping operator or size rebuild the passes and
        targets (recompiling programs; simulations start over) on the same context."""
        self._check_alive()
        raise_if_stop_requested()  # a signal a library swallowed ends the command here
        if hdr and not readback:
            raise ValueError("hdr=True reads the composite back: not with readback=False")
        time = _frame_time(time)
        jitter = sampling.check_jitter(jitter)
        self._keep_pending_hdr()
        state = self.state_at(time)
        self.gl.make_current()
        stale = self.gl.ctx.error  # reading clears it: errors from here on are this frame's
        if stale != "GL_NO_ERROR":
            warnings.warn(f"GL error {stale} left by code outside the renderer", stacklevel=2)
        try:
            frame, history = self._begin_frame(state, time, jitter, sample_index,
                                               time_gl_calls)
            advance_simulations(frame)
            prepare_passes(frame, self.passes)
            self.gl.park()  # whatever framebuffer was bound may have been released since
            self._setup.skinning.run(state)  # draws (captured): needs a complete framebuffer
            run_passes(frame, sort_blended(self.passes, state), before_pass, on_pass)
        finally:
            self.shaders.end_frame()
        if self.strict:
            frame.inputs.check_material_uniforms()
        self.last_frame, self.state = frame, state
        self.temporal.end(history, state)
        self._frame_number += 1
        return self._result(frame, readback, hdr)

    def simulate(self, time: float) -> None:
        """Bring the scene's simulations to ``time`` as a frame at ``time`` would, drawing
        nothing: a frame rendered apart from those before it (``deferred.farm``) first replays
        the times a single renderer would have drawn, so its simulations step alike."""
        self._check_alive()
        state = self.state_at(_frame_time(time))
        self.gl.make_current()
        try:
            advance_simulations(self._begin_frame(state, time, None, None, False)[0])
        finally:
            self.shaders.end_frame()

    def _begin_frame(self, state: FrameState, time: float,
                     jitter: tuple[float, float] | None, sample_index: int | None,
                     time_gl_calls: bool):
        """The frame of ``state``, its place in the temporal history, the lights uploaded."""
        self.shaders.start_frame(forget=self.strict)  # ended by _end_frame
        self.kept_inputs.start_frame(state)
        history = self.temporal.begin(state, time, self.size[0] / self.size[1])
        effect = temporal_effect(state)
        if jitter is None:
            # a frame starting a history is not moved: a still with taa is the frame itself
            jitter = effect.jitter(history.index) if effect is not None and history.index > 0 \
                else (0.0, 0.0)
        if sample_index is None:
            sample_index = history.index if effect is not None else 0
        inputs = FrameInputs(state, self.object_transforms, self.kept_inputs, self.strict,
                             history.previous_models)
        setup = self._setup
        frame = Frame(self.gl, setup.shaders, setup.targets, setup.resources, state, inputs,
                      strict=self.strict, time=time, time_gl_calls=time_gl_calls,
                      blackboard=setup.blackboard, binding_sources=setup.binding_sources,
                      checked_framebuffers=setup.checked_framebuffers,
                      jitter=(float(jitter[0]), float(jitter[1])), sample_index=sample_index,
                      history_kept=history.kept,
                      previous_view_projection=history.previous_view_projection,
                      kept_camera_values=self._camera_values)
        self._camera_values = frame.camera_values
        # the shading models' and the light types' samplers
        shading = ShadingTextures.of(setup.shading_models, frame, setup.plan.light_types)
        if shading is not None:
            frame.binding_sources.insert(0, shading)
        slots = None
        if setup.shadow_atlas is not None:
            slots = setup.shadow_atlas.update(
                state, frame.view, frame.width / frame.height, frame.projection,
                self.hold_shadow_sizes, self.cascade_updates
                or state.shadow_budget.cascade_updates or CascadeUpdates.EVERY_FRAME)
        setup.light_buffer.upload(list(state.lights), frame.view, frame.projection, slots)
        self._check_gl("uploading the lights")
        return frame, history

    def _result(self, frame: Frame, readback: bool, hdr: bool) -> RenderResult:
        stats = frame.stats
        result = RenderResult(self.read_final() if readback else None, stats.draw_calls,
                              dict(stats.draws_by_pass), stats.gl_call_seconds)
        if readback:
            if hdr:
                result._hdr = self.read_hdr()
            else:
                result._read_hdr = self._hdr_reader(self._frame_number)
                self._pending_hdr = weakref.ref(result)
        return result

    def render_samples(self, samples: int, time: float = 0.0,
                       on_sample: Callable[[int], None] | None = None) -> RenderResult:
        """The frame at ``time`` averaged over ``samples`` renders, each moved by a sub-pixel
        offset of the Halton (2, 3) sequence: the image averaged in linear light (its sRGB
        decoded, then encoded again) and the float composite averaged, converging to a
        supersampled frame (a box filter over the pixel). One sample is :meth:`render`.
        ``on_sample(done)`` is called after each sample."""
        return render_samples(self, samples, time, on_sample)

    def _keep_pending_hdr(self) -> None:
        """Read the last frame's HDR composite into its result before the targets are drawn
        over or released, where the caller still holds the result and has not read it (a
        result no one holds costs nothing)."""
        pending, self._pending_hdr = self._pending_hdr, None
        result = pending() if pending is not None else None
        if result is not None and result._read_hdr is not None:
            result._hdr = self.read_hdr()
            result._read_hdr = None

    def _hdr_reader(self, frame_number: int) -> Callable[[], np.ndarray]:
        def read() -> np.ndarray:
            if self._released or self._frame_number != frame_number:
                raise RenderError("the HDR composite of this frame is gone: the renderer has "
                                  "rendered again or been released since; read result.hdr "
                                  "first, or render(hdr=True)")
            return self.read_hdr()
        return read

    def check_times(self, times: list[float], where: str = "--time") -> None:
        """Every simulated object's :meth:`~deferred.interfaces.simulation.Simulation.check_time`
        for the latest of ``times``: an animation is refused before its first frame, not part
        way.
        The work a check weighs grows with the time (steps from 0, droplets fallen by then),
        so a time passed covers every earlier one while the checked objects' revisions are
        the same: a frame at such a time checks nothing again."""
        if not times:
            return
        self.scene.check_tracks(times)  # every frame's camera and lights, not just the last
        latest = max(times)
        objects = self.scene.objects
        checked = [obj for obj in objects if obj.material.simulation is not None]
        revisions = tuple((obj, obj.revision, obj.material.revision) for obj in checked)
        if self._times_checked is not None and self._times_checked[1] == revisions and \
                latest <= self._times_checked[0]:
            return
        if checked:
            self.evaluator.check_simulation_times(latest, where)
        self._times_checked = (latest, revisions)

    def _check_gl(self, stage: str) -> None:
        error = self.gl.ctx.error
        if error != "GL_NO_ERROR":
            raise gl_error(stage, error, self.size)

    def read_final(self) -> np.ndarray:
        self._check_alive()
        self.gl.make_current()  # another renderer's context may be current
        data = np.frombuffer(self.targets[FINAL].read(alignment=1), dtype=np.uint8)
        return data.reshape(self.size[1], self.size[0], 4)[::-1].copy()

    def read_hdr(self) -> np.ndarray:
        self._check_alive()
        self.gl.make_current()  # another renderer's context may be current
        return self.targets.read(COMPOSITE)[::-1].copy()

    def _check_alive(self) -> None:
        if self._released:
            raise RenderError("this renderer was released; make a new one")

    def release(self) -> None:
        """Release every GL object of the renderer and give its context back; releasing
        again does nothing."""
        if self._released:
            return
        try:
            self._keep_pending_hdr()
        except Exception:  # noqa: BLE001 - a context already lost: the result says so if read
            pass
        self._released = True
        try:
            self._release_parts()
        finally:
            if self._owns_context:  # whatever failed above, the context goes back
                give_back_context(self.gl)

    def _release_parts(self) -> None:
        """Every GL object the renderer made (a constructor that failed part way made only
        some), not the context."""
        self.gl.make_current()
        self.gl.park()
        kept = getattr(self, "kept_inputs", None)
        if kept is not None:
            kept.release()
        setup = getattr(self, "_setup", None)
        if setup is not None:
            setup.release()

    def __enter__(self) -> Renderer:
        return self

    def __exit__(self, *exc) -> None:
        self.release()


def render_scene(scene: Scene, pipeline: str = Pipeline.DEFERRED,
                 size: tuple[int, int] | None = None, gl: GLContext | None = None,
                 time: float = 0.0) -> RenderResult:
    """Render one frame of ``scene`` at ``time`` with a renderer made and released for it (the
    result holds the image and the HDR composite both)."""
    with Renderer(scene, pipeline, size, gl) as renderer:
        return renderer.render(time=time, hdr=True)
