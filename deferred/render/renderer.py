"""The renderer: owns GL resources for a scene at a size and runs a pipeline's passes."""

from __future__ import annotations

import math
import numbers
import os
import warnings
import weakref
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from deferred.core.frame import Frame
from deferred.core.graph import PassGraph, PassGraphError
from deferred.core.passes import Phase, RenderPass
from deferred.errors import DeferredError, InputError, RenderError, gl_error
from deferred.gl.context import Features, GLContext, acquire_context, give_back_context
from deferred.gl.resources import Resources
from deferred.gl.shaderlib import ShaderLibrary
from deferred.gl.target_spec import targets_bytes
from deferred.gl.targets import COMPOSITE, FINAL, FrameTargets
from deferred.interfaces.effect import halton
from deferred.interfaces.material import Material
from deferred.io.images import amount, srgb_decode, srgb_encode, write_image
from deferred.io.memory import check_memory
from deferred.io.safety import raise_if_stop_requested
from deferred.lighting.buffer import LIGHT_BUFFER, LightBuffer
from deferred.lighting.lists import (
    LIGHT_LISTS,
    LightLists,
    check_light_limits,
    check_light_radii,
)
from deferred.lighting.paths import resolve_light_path
from deferred.lighting.shadows import (
    OPACITY_SHADOWS_DEFINE,
    SHADOW_ATLAS,
    SHADOWS_DEFINE,
    ShadowAtlas,
    atlas_memory,
    opacity_extent,
    opacity_size,
    scene_casts_shadows,
    scene_has_opacity,
)
from deferred.memo import overrides
from deferred.names import LightVolume, Pipeline
from deferred.params import validate_params
from deferred.render.caches import (
    FrameInputs,
    KeptMaterialInputs,
    ObjectTransforms,
    ShadingTextures,
)
from deferred.render.generated import generated_glsl
from deferred.render.pipeline import PIPELINES, TONEMAPS, check_passes, sort_blended
from deferred.render.temporal import TemporalState, temporal_effect
from deferred.scene.model import Scene, SceneObject, check_size

PassCallback = Callable[[RenderPass, Frame], None]
FULL_FEATURES = Features(storage_buffers=True, compute_shaders=True)


@dataclass
class RenderResult:
    """One frame: ``image`` (H, W, 4) uint8 sRGB, top row first (None: rendered with
    ``readback=False``); ``hdr`` the linear float composite (H, W, 4), read from the GPU when
    first asked for, or before the renderer draws its next frame or is released while the
    result is still held (a result dropped unread costs no read; ``render(hdr=True)`` reads it
    at once); the draw calls, in all and by pass. ``save(path)`` writes the frame (.png the
    image, .exr the composite); in a notebook the result shows as its image."""

    image: np.ndarray | None
    draw_calls: int
    draws_by_pass: dict[str, int]
    gl_call_seconds: float = 0.0  # inside drawing GL calls (FrameStats; time_gl_calls only)
    _hdr: np.ndarray | None = field(default=None, repr=False)
    _read_hdr: Callable[[], np.ndarray] | None = field(default=None, repr=False, compare=False)

    @property
    def hdr(self) -> np.ndarray:
        if self._hdr is None:
            if self._read_hdr is None:
                raise RenderError("this result has no HDR composite (rendered with "
                                  "readback=False)")
            self._hdr = self._read_hdr()
            self._read_hdr = None
        return self._hdr

    def save(self, path: str | Path) -> Path:
        """Write the frame to ``path``: the image as .png, the linear composite as .exr
        (float RGBA). Written whole or not at all; returns the path."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix == ".exr":
            return write_image(path, self.hdr, channels=("R", "G", "B", "A"))
        if suffix != ".png":
            raise InputError(f"saves .png (the image) or .exr (the linear composite), got "
                             f"'{path.name}'", "path")
        if self.image is None:
            raise RenderError("this result has no image (rendered with readback=False)")
        return write_image(path, self.image)

    def _repr_png_(self) -> bytes | None:
        """The image as PNG bytes: how Jupyter shows a result."""
        if self.image is None:
            return None
        from io import BytesIO

        from PIL import Image

        buffer = BytesIO()
        Image.fromarray(np.ascontiguousarray(self.image)).save(buffer, format="PNG")
        return buffer.getvalue()


def strict_default() -> bool:
    """Whether renderers are strict when not told: ``DEFERRED_STRICT=1`` (the tests set it)."""
    return os.environ.get("DEFERRED_STRICT", "") in ("1", "true", "yes")


def check_target_memory(graph: PassGraph, size: tuple[int, int], where: str = "size",
                        held: dict[str, int] | None = None, held_where: str = "scene") -> None:
    """Refuse a frame size whose render targets need more than the memory budget (naming
    ``where``), then a scene whose materials will hold more (``held``:
    :meth:`~deferred.interfaces.material.Material.held_memory`) than what the targets leave
    (naming ``held_where`` and the largest of what they hold)."""
    targets = targets_bytes(graph.targets.values(), *size)
    check_memory(targets, f"{size[0]}x{size[1]} needs {{}} of render targets "
                          f"({len(graph.targets)} targets)", where)
    if held:
        largest = max(held, key=held.__getitem__)
        check_memory(targets + sum(held.values()),
                     f"the materials' textures and state ({len(held)}, the largest "
                     f"{largest}: {amount(held[largest])}) and the render targets at "
                     f"{size[0]}x{size[1]} need {{}}", held_where)


def held_memory(scene: Scene) -> dict[str, int]:
    """What every object's material will hold, by what it is (a shared texture once)."""
    held: dict[str, int] = {}
    for obj in scene.objects:
        held.update(obj.material.held_memory(obj))
    return held


def renderer_holdings(scene: Scene, pipeline: str, size: tuple[int, int]) -> dict[str, int]:
    """What a renderer of ``scene`` holds besides its pass graph's targets: the materials'
    textures and state, the shadow atlas and opacity maps, the effects' histories."""
    held = held_memory(scene)
    if scene_casts_shadows(scene.lights):
        held.update(atlas_memory(scene.shadow_budget, opacity_size(scene, pipeline)))
    for effect in scene.effects:
        held.update(effect.held_memory(size))
    return held


MAX_SAMPLES = 1024  # sub-pixel samples a frame (render_samples)


def halton_offsets(count: int) -> list[tuple[float, float]]:
    """``count`` sub-pixel offsets in [-0.5, 0.5)^2: Halton (2, 3) from index 1, centred."""
    return [(halton(k, 2) - 0.5, halton(k, 3) - 0.5) for k in range(1, count + 1)]


def check_scene_values(scene: Scene) -> None:
    """The scene's own values as a scene file's are checked (a scene built or changed in
    Python skips the loader): the camera, the tone mapping operator, the background and the
    exposure; ``InputError`` naming the attribute."""
    from dataclasses import asdict

    from deferred.scene.loader import CameraModel

    validate_params(CameraModel, asdict(scene.camera), "camera")
    if scene.tonemap not in TONEMAPS:
        raise InputError(f"unknown tone mapping operator {scene.tonemap!r} (choose from "
                         f"{', '.join(TONEMAPS)})", "tonemap")
    background = np.asarray(scene.background, dtype=np.float64)
    if background.shape != (3,) or not np.all(np.isfinite(background)) or np.any(background < 0):
        raise InputError(f"expected three finite numbers >= 0, got {scene.background!r}",
                         "background")
    if not (math.isfinite(scene.exposure) and scene.exposure > 0.0):
        raise InputError(f"expected a finite number > 0, got {scene.exposure!r}", "exposure")


def _restarts(material_cls: type[Material], before: object, after: object) -> bool:
    """Whether new parameters need the material's state made again: one it reads once
    (``timeline_fixed``) changed, or a count that only rises (``timeline_growing``) fell."""
    return any(getattr(before, key) != getattr(after, key)
               for key in material_cls.timeline_fixed) or \
        any(getattr(after, key) < getattr(before, key) for key in material_cls.timeline_growing)


class Renderer:
    """Renders one scene with one pipeline; reuse it for many frames, then ``release()``.

    ``strict`` turns a uniform set by name that a program does not declare into an error
    (default: the ``DEFERRED_STRICT`` environment variable). ``light_path`` chooses how lights
    reach the pixels (:mod:`deferred.lighting.paths`; default: the scene's ``light_path``, else
    the fastest the context allows).

    The scene may change between frames: objects, lights and effects added or removed
    (``Scene.add_object``, ``add_light``, ``remove``), materials' parameters
    (``SceneObject.set_params``), the camera, the background, the tone mapping operator. Each
    frame picks the changes up; where they change what the passes are built from (another
    object, light type or effect, parameters that add or remove passes, the background, which
    is the clear value of targets, the operator, a define), the renderer builds its passes,
    targets and programs again on the same context first (:meth:`render`).
    """

    def __init__(self, scene: Scene, pipeline: str = Pipeline.DEFERRED,
                 size: tuple[int, int] | None = None, gl: GLContext | None = None,
                 strict: bool | None = None, light_path: str | None = None):
        self._released = False
        if pipeline not in PIPELINES:
            raise InputError(f"unknown pipeline '{pipeline}' (choose from "
                             f"{', '.join(PIPELINES)})", "pipeline")
        check_scene_values(scene)
        self.scene = scene
        self._camera_checked = scene.camera
        self.pipeline_name = pipeline
        self._size_arg, self._light_path_arg = size, light_path  # for a rebuild
        self._times_checked: tuple[float, tuple] | None = None  # check_times' last pass
        self._inserted: list[tuple[RenderPass, str | None, str | None]] = []  # insert_pass's
        self.strict = strict_default() if strict is None else strict
        given = size is not None
        self.size = check_size(size if given else scene.size,
                               "size" if given else f"{scene.source}: size")
        # The pass graph and the generated GLSL are built and checked before any GL object
        # exists: bad input never leaves a context behind. The light path is checked by name
        # now and against the context's features once it exists; the provisional graph (the
        # requested path, else tiled) only changes where the context cannot run that path.
        requested = light_path if light_path is not None else scene.light_path
        provisional = resolve_light_path(pipeline, requested, FULL_FEATURES)
        self.graph: PassGraph = check_passes(PIPELINES[pipeline](provisional).build(scene))
        # where the frame size came from, for errors about it
        self.size_where = "size" if given else f"{scene.source}: size"
        # counted again only when parameters change: the scene's files are read for it
        held = renderer_holdings(scene, pipeline, self.size)
        self._held_bytes = sum(held.values())
        check_target_memory(self.graph, self.size, self.size_where, held, scene.source)
        light_types = scene.light_types()
        shading_models = self.shading_models = scene.shading_models()
        self.object_transforms = ObjectTransforms()  # kept across frames
        self.kept_inputs = KeptMaterialInputs()  # materials' inputs, kept across frames
        self.temporal = TemporalState()  # the last frame's time, camera and models
        generated = generated_glsl(light_types, shading_models, scene.gbuffer_layout(),
                                   [obj.material for obj in scene.objects])
        roots = [cls.shader_root for cls in [
            *(type(obj.material) for obj in scene.objects), *light_types, *shading_models,
            *(type(effect) for effect in scene.effects)] if cls.shader_root is not None]
        self._owns_context = gl is None
        self.gl = gl or acquire_context()
        self.gl.make_current()
        try:
            self._build(scene, pipeline, requested, provisional, roots, generated)
        except BaseException:
            # nothing made here outlives a failed constructor, and the context goes back
            self._release_partial()
            raise
        self._frame_number = 0
        self._pending_hdr: weakref.ref[RenderResult] | None = None
        self._note_scene()

    # -- following the scene -------------------------------------------------------------------
    def _scene_structure(self) -> tuple:
        """What the passes, targets and programs are built from, apart from parameters: which
        objects (their meshes, their materials' types), which lights and effects, whether a
        light casts shadows, whether a material draws opacity maps and their size (with the
        lights' shadow resolutions) and the shadow budget (the shadow pass, the atlas and the
        SHADOWS and OPACITY_SHADOWS defines), the clear colour, the tone mapping operator, the
        light path and the size asked for."""
        scene = self.scene
        return (tuple((id(obj), id(obj.mesh), type(obj.material)) for obj in scene.objects),
                tuple(map(type, scene.lights)), scene_casts_shadows(scene.lights),
                opacity_size(scene, self.pipeline_name), scene.shadow_budget,
                tuple(map(id, scene.effects)),
                tuple(scene.background), scene.tonemap,
                scene.light_path if self._light_path_arg is None else None,
                scene.size if self._size_arg is None else None)

    @staticmethod
    def _object_passes(obj: SceneObject) -> list[str]:
        return [p.name for phase in Phase for p in obj.material.passes(phase, obj)]

    def _note_scene(self) -> None:
        """Keep what the passes were built from (after a frame: the timeline's parameters)."""
        self._structure = self._scene_structure()
        self._params_seen = {id(obj): obj.material.params for obj in self.scene.objects}
        if not hasattr(self, "_passes_seen") or self._frame_number == 0:
            self._passes_seen = {id(obj): self._object_passes(obj) for obj in self.scene.objects}

    def _follow_scene(self) -> None:
        """Rebuild before a frame where the scene changed in what the passes are built from;
        parameters that only change values (uniforms, defines) need nothing here."""
        changed = self._scene_structure() != self._structure
        exposure = self.scene.exposure
        if changed or self.scene.camera is not self._camera_checked or \
                not (isinstance(exposure, float | int) and math.isfinite(exposure) and
                     exposure > 0.0):
            check_scene_values(self.scene)
            self._camera_checked = self.scene.camera
        if not changed:
            edited = {}
            for obj in self.scene.objects:
                params = obj.material.params
                if params is self._params_seen.get(id(obj)):
                    continue
                passes = self._object_passes(obj)
                seen = self._params_seen.get(id(obj))
                if passes != self._passes_seen.get(id(obj)) or \
                        (seen is not None and _restarts(type(obj.material), seen, params)):
                    changed = True
                    break
                edited[id(obj)] = params
            if edited and not changed:
                self._count_held_memory()  # an edited texture or mask size may not fit
                self._params_seen.update(edited)  # seen once they are known to fit
        if changed:
            self._rebuild()

    def _count_held_memory(self) -> None:
        """Count what the renderer holds again and check it against the budget."""
        held = renderer_holdings(self.scene, self.pipeline_name, self.size)
        check_target_memory(self.graph, self.size, self.size_where, held, self.scene.source)
        self._held_bytes = sum(held.values())

    def _rebuild(self) -> None:
        """A renderer built afresh for the scene on this one's context takes this one's place
        (this one is left as it was if that fails); passes inserted with insert_pass are
        inserted again."""
        replacement = type(self)(self.scene, self.pipeline_name, self._size_arg, gl=self.gl,
                                 strict=self.strict, light_path=self._light_path_arg)
        try:
            for render_pass, before, after in self._inserted:
                try:
                    replacement.insert_pass(render_pass, before=before, after=after)
                except PassGraphError as exc:
                    raise PassGraphError(f"pass {render_pass.name}, inserted with insert_pass, "
                                         f"no longer fits the changed scene: {exc}") from None
        except BaseException:
            replacement.release()
            raise
        owns, inserted, frame_number = self._owns_context, self._inserted, self._frame_number
        self._release_parts()
        self.__dict__.update(replacement.__dict__)
        replacement._released = True  # its parts are this renderer's now
        self._owns_context, self._inserted = owns, inserted
        self._frame_number = frame_number + 1  # results of earlier frames cannot read these

    def _build(self, scene: Scene, pipeline: str, requested: str | None, provisional: str,
               roots: list, generated: dict[str, str]) -> None:
        ctx = self.gl.ctx
        features = self.gl.features
        self.light_path = resolve_light_path(pipeline, requested, features)
        volume_lights = sum(1 for light in scene.lights if light.volume != LightVolume.FULLSCREEN)
        check_light_limits(self.light_path, self.size, volume_lights, len(scene.lights),
                           self.gl.max_texture_size, f"{scene.source}: light")
        check_light_radii(self.light_path, scene.lights, f"{scene.source}: light")
        self.pipeline = PIPELINES[pipeline](self.light_path)
        if self.light_path != provisional:
            self.graph = check_passes(self.pipeline.build(scene))
        defines = dict(self.pipeline.shader_defines())
        if scene_casts_shadows(scene.lights):
            defines[SHADOWS_DEFINE] = "1"
        if scene_has_opacity(scene, pipeline):
            defines[OPACITY_SHADOWS_DEFINE] = "1"
        self.shaders = ShaderLibrary(ctx, features.glsl_version(), defines)
        for root in roots:
            self.shaders.add_root(root)
        for name, text in generated.items():
            self.shaders.set_virtual_file(name, text)
        self.targets = FrameTargets(ctx, *self.size)
        self._declare_targets()
        self.resources = Resources(ctx)
        self.light_buffer = LightBuffer(ctx)
        self.light_lists = LightLists(ctx) if features.compute_shaders else None
        budget = scene.shadow_budget
        self.shadow_atlas = ShadowAtlas(ctx, budget.atlas_size, budget.max_shadowed_lights,
                                        opacity_size(scene, pipeline), opacity_extent(scene)) \
            if scene_casts_shadows(scene.lights) else None
        # The per-frame GPU resources every frame is given: by name on its blackboard (for the
        # passes that fill or read them), and those that bind themselves to every program as
        # its binding sources. A new global resource is one more entry here.
        self.blackboard = {LIGHT_BUFFER: self.light_buffer, LIGHT_LISTS: self.light_lists,
                           SHADOW_ATLAS: self.shadow_atlas}
        self.binding_sources = [source for source in (self.light_buffer, self.light_lists,
                                                      self.shadow_atlas)
                                if source is not None]
        self.checked_framebuffers: dict = {}  # Frame.use_framebuffer's, for the renderer's life
        self.last_frame: Frame | None = None
        error = ctx.error
        if error != "GL_NO_ERROR":  # the targets did not fit
            raise gl_error("creating the render targets", error, self.size)

    def _release_partial(self) -> None:
        self.release()  # an owned context is released instead where it holds a GL error
        if not self._owns_context:
            _ = self.gl.ctx.error  # reading clears it: the caller's next renderer starts clean

    def memory_bytes(self) -> int:
        """What the renderer holds as the memory budget counts it: its render targets and the
        materials' textures and state, the shadow maps and the effects' histories
        (:func:`renderer_holdings`, counted again when parameters change)."""
        return targets_bytes(self.graph.targets.values(), *self.size) + self._held_bytes

    @property
    def passes(self) -> list[RenderPass]:
        return self.graph.passes

    def _declare_targets(self) -> None:
        for name, spec in self.graph.targets.items():
            self.targets.declare(name, spec)

    def insert_pass(self, render_pass: RenderPass, *, before: str | None = None,
                    after: str | None = None) -> None:
        """Insert ``render_pass`` before or after the pass named so; the graph is checked again
        (and left as it was if the new pass does not fit) and new targets are created."""
        self._check_alive()
        if (before is None) == (after is None):
            raise TypeError("insert_pass needs exactly one of before= or after=")
        index = self.graph.index(before if before is not None else after)
        passes = list(self.graph.passes)
        passes.insert(index if before is not None else index + 1, render_pass)
        graph = check_passes(passes)
        for name, spec in graph.targets.items():
            if name in self.targets and not self.targets.specs[name].same_format(spec):
                raise PassGraphError(f"pass {render_pass.name}: target '{name}' exists with "
                                     "another format")
        self.graph = graph
        self.gl.make_current()
        self._declare_targets()
        self._inserted.append((render_pass, before, after))

    def render(self, on_pass: PassCallback | None = None,
               before_pass: PassCallback | None = None, readback: bool = True,
               time: float = 0.0, time_gl_calls: bool = False,
               hdr: bool = False, jitter: tuple[float, float] | None = None,
               sample_index: int | None = None) -> RenderResult:
        """Run every pass once for the frame at ``time`` (seconds: the scene's timeline is
        applied first, and passes see it as ``frame.time``). ``on_pass``/``before_pass`` are
        called around each pass; ``readback=False`` skips reading the images back (timing
        loops); ``hdr=True`` reads the float composite now (else when ``result.hdr`` is first
        asked for); ``jitter`` moves the image by a fraction of a pixel (x, y; see
        :meth:`render_samples`; by default none, or a temporal effect's (taa) for the frame's
        sample since its history started); ``sample_index`` picks per-sample patterns (the
        stipple's parity; by default that sample, else 0); ``time_gl_calls`` measures the CPU
        time of the drawing GL calls (``RenderResult.gl_call_seconds``, for the bench: two
        clock reads per call).

        Changes to the scene since the last frame are picked up first: objects, lights and
        effects added or removed, a material or mesh replaced, parameters that add or remove
        passes, a new background, tone mapping operator or size rebuild the passes and
        targets (recompiling programs; simulations start over) on the same context."""
        self._check_alive()
        raise_if_stop_requested()  # a signal a library swallowed ends the command here
        if hdr and not readback:
            raise ValueError("hdr=True reads the composite back: not with readback=False")
        if isinstance(time, bool) or not isinstance(time, numbers.Real) or \
                not math.isfinite(time) or time < 0.0:
            raise InputError(f"frame time must be a finite number of seconds >= 0, got {time!r}",
                             "time")
        time = float(time)
        self._keep_pending_hdr()
        self._follow_scene()
        self.check_times([time], "time")
        self.scene.apply_timeline(time)
        # a camera the tracks moved was checked as they made it (Scene.camera_at): a track's
        # camera is not checked again, and no move of the camera, a light or an object rebuilds
        self._camera_checked = self.scene.camera
        self.gl.make_current()
        ctx = self.gl.ctx
        stale = ctx.error  # reading clears it: errors from here on are this frame's
        if stale != "GL_NO_ERROR":
            warnings.warn(f"GL error {stale} left by code outside the renderer", stacklevel=2)
        self.shaders.forget_uniform_values()  # code between frames may have written them
        self.kept_inputs.start_frame(self.scene)
        history = self.temporal.begin(self.scene, time, self.size[0] / self.size[1])
        effect = temporal_effect(self.scene)
        if jitter is None:
            # a frame starting a history is not moved: a still with taa is the frame itself
            jitter = effect.jitter(history.index) if effect is not None and history.index > 0 \
                else (0.0, 0.0)
        if sample_index is None:
            sample_index = history.index if effect is not None else 0
        inputs = FrameInputs(self.scene, self.object_transforms, self.kept_inputs, self.strict,
                             history.previous_models)
        frame = Frame(self.gl, self.shaders, self.targets, self.resources, self.scene, inputs,
                      strict=self.strict, time=time, time_gl_calls=time_gl_calls,
                      blackboard=self.blackboard, binding_sources=self.binding_sources,
                      checked_framebuffers=self.checked_framebuffers,
                      jitter=(float(jitter[0]), float(jitter[1])), sample_index=sample_index,
                      history_kept=history.kept,
                      previous_view_projection=history.previous_view_projection)
        shading = ShadingTextures.of(self.shading_models, frame)  # the models' samplers, if any
        if shading is not None:
            frame.binding_sources.insert(0, shading)
        slots = None
        if self.shadow_atlas is not None:
            slots = self.shadow_atlas.update(self.scene, frame.view, frame.width / frame.height,
                                             frame.projection)
        self.light_buffer.upload(self.scene.lights, frame.view, frame.projection, slots)
        self._check_gl("uploading the lights")
        # asked of each class once a frame, not of each pass (a pass an object)
        preparing = {cls for cls in {type(p) for p in self.passes}
                     if overrides(cls, RenderPass, "prepare")}
        for render_pass in self.passes:
            if type(render_pass) not in preparing:
                continue  # nothing to prepare (most passes: skipping them saves a GL error read)
            try:
                render_pass.prepare(frame)
            except DeferredError:
                raise
            except Exception as exc:  # noqa: BLE001 - a plugin's prepare: say which pass
                raise RenderError(f"pass {render_pass.name}: preparing: "
                                  f"{type(exc).__name__}: {exc}") from exc
            self._check_gl(f"pass {render_pass.name}: preparing")
        self.gl.park()  # whatever framebuffer was bound may have been released since
        # The GL error flag is read once a run of passes of one kind and phase (the objects'
        # G-buffer passes, say), not once a pass: Frame.check_errors names the pass. Hooks
        # look at each pass, so with them each is checked.
        unchecked: list[RenderPass] = []
        # blended passes far to near for this frame's camera and transforms
        passes = sort_blended(self.passes, self.scene)
        hooked = before_pass is not None or on_pass is not None
        for index, render_pass in enumerate(passes):
            raise_if_stop_requested()  # a signal lost in a pass's library or a __del__
            if before_pass:
                before_pass(render_pass, frame)
            try:
                frame.run_pass(render_pass, check_errors=hooked)
            except Exception:
                if unchecked:  # the raised error is the one to report: drop the earlier flag
                    _ = self.gl.ctx.error  # reading it clears it
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
        if self.strict:
            inputs.check_material_uniforms()
        self.last_frame = frame
        self.temporal.end(history, self.scene)
        self._frame_number += 1
        self._note_scene()
        result = RenderResult(self.read_final() if readback else None, frame.stats.draw_calls,
                              dict(frame.stats.draws_by_pass), frame.stats.gl_call_seconds)
        if readback:
            if hdr:
                result._hdr = self.read_hdr()
            else:
                result._read_hdr = self._hdr_reader(self._frame_number)
                self._pending_hdr = weakref.ref(result)
        return result

    def render_samples(self, samples: int, time: float = 0.0) -> RenderResult:
        """The frame at ``time`` averaged over ``samples`` renders, each moved by a sub-pixel
        offset of the Halton (2, 3) sequence: the image averaged in linear light (its sRGB
        decoded, then encoded again) and the float composite averaged, converging to a
        supersampled frame (a box filter over the pixel). One sample is :meth:`render`."""
        if isinstance(samples, bool) or not isinstance(samples, numbers.Integral) or \
                not 1 <= samples <= MAX_SAMPLES:
            raise InputError(f"must be a whole number 1..{MAX_SAMPLES}, got {samples!r}",
                             "samples")
        if samples == 1:
            return self.render(time=time, hdr=True)
        light = composite = None
        for index, jitter in enumerate(halton_offsets(samples)):
            # each sample its own parity of the stipple pattern (sample_index), which the
            # average integrates (Revie's 1-in-4 pattern covers every pixel over four)
            # each sample alone: a temporal effect's history would average the samples twice
            self.temporal.reset()
            result = self.render(time=time, hdr=True, jitter=jitter, sample_index=index)
            decoded = srgb_decode(result.image.astype(np.float64) / 255.0)
            light = decoded if light is None else light + decoded
            composite = result.hdr.astype(np.float64) if composite is None \
                else composite + result.hdr
        image = np.clip(np.rint(srgb_encode(light / samples) * 255.0), 0, 255).astype(np.uint8)
        return RenderResult(image, result.draw_calls * samples,
                            {name: count * samples for name, count in result.draws_by_pass.items()},
                            _hdr=(composite / samples).astype(np.float32))

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
        """Every material's :meth:`~deferred.interfaces.material.Material.check_time` for the
        latest of ``times``: an animation is refused before its first frame, not part way.
        The work a check weighs grows with the time (steps from 0, droplets fallen by then),
        so a time passed covers every earlier one while the checked objects' parameters and
        events are the same: a frame at such a time checks nothing again."""
        if not times:
            return
        self.scene.check_tracks(times)  # every frame's camera and lights, not just the last
        latest = max(times)
        objects = self.scene.objects
        checking = {cls for cls in {type(obj.material) for obj in objects}
                    if overrides(cls, Material, "check_time", "check_time_for")}
        checked = [obj for obj in objects if type(obj.material) in checking]
        state = tuple((id(obj), id(obj.material), id(obj.material.params),
                       id(getattr(obj, "base_params", None)), id(getattr(obj, "events", None)))
                      for obj in checked)
        if self._times_checked is not None and self._times_checked[1] == state and \
                latest <= self._times_checked[0]:
            return
        for obj in checked:  # most materials have no check
            obj.material.check_time_for(obj, latest, where)
        self._times_checked = (latest, state)

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
        for name in ("kept_inputs", "light_buffer", "light_lists", "shadow_atlas", "resources",
                     "targets", "shaders"):
            part = getattr(self, name, None)
            if part is not None:
                part.release()

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
