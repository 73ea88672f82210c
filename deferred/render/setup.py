"""What a renderer builds for a scene's structure: the checked pass graph and, on a GL
context, the programs, render targets, GPU resources, light buffer and lists and the shadow
atlas. A renderer holds one :class:`RenderSetup` and builds another where the scene's
structure changes (:func:`structure_key`).

:class:`SetupPlan` is the part made before any GL object exists (the pass graph, the
generated GLSL, the memory budget), so bad input never leaves a context behind.
"""

from __future__ import annotations

from collections.abc import Hashable

from deferred.core.graph import PassGraph, PassGraphError
from deferred.core.passes import Phase, RenderPass
from deferred.errors import gl_error
from deferred.gl.context import Features, GLContext
from deferred.gl.resources import Resources
from deferred.gl.shaderlib import ShaderLibrary
from deferred.gl.targets import FrameTargets
from deferred.interfaces.shading import (
    SPLIT_DEFINE,
    TRANSMISSION_DEFINE,
    scene_splits_light,
    scene_transmits,
)
from deferred.lighting.buffer import LIGHT_BUFFER, LightBuffer
from deferred.lighting.lists import (
    LIGHT_LISTS,
    LightLists,
    check_light_limits,
    check_light_radii,
)
from deferred.lighting.paths import resolve_light_path
from deferred.lighting.shadows.atlas import (
    PCSS_DEFINE,
    SHADOW_ATLAS,
    SHADOWS_DEFINE,
    ShadowAtlas,
    check_records_fit,
    records_defines,
)
from deferred.lighting.shadows.opacity import (
    OPACITY_SHADOWS_DEFINE,
    opacity_extent,
    opacity_size,
    scene_has_opacity,
)
from deferred.lighting.shadows.plan import scene_casts_shadows
from deferred.lighting.shadows.transmittance import (
    TRANSMITTANCE_DEFINE,
    scene_has_transparent_casters,
)
from deferred.names import LightVolume
from deferred.render.budget import check_target_memory, renderer_holdings
from deferred.render.generated import generated_glsl
from deferred.render.pipeline import PIPELINES, check_passes
from deferred.render.skinning import Skinning
from deferred.scene.state import FrameState

FULL_FEATURES = Features(storage_buffers=True, compute_shaders=True)


def structure_key(state: FrameState, pipeline: str, light_path_arg: str | None,
                  size_arg: tuple[int, int] | None) -> Hashable:
    """What the passes, targets and programs are built from, apart from parameters: which
    objects (their meshes, their materials' types), which lights and effects, whether a
    light casts shadows, whether a material draws opacity maps and their size (with the
    lights' shadow resolutions), whether a caster draws transmittance maps, and the shadow
    budget (the shadow pass, the atlas and the SHADOWS, OPACITY_SHADOWS and
    SHADOW_TRANSMITTANCE defines), the clear colour, the tone mapping operator, the
    light path and the size asked for. Membership is by identity: which objects are there."""
    return (tuple((obj.node, id(obj.mesh), type(obj.material), obj.label)
                  for obj in state.objects),
            tuple(map(type, state.lights)), scene_casts_shadows(state.lights),
            opacity_size(state, pipeline), scene_has_transparent_casters(state),
            state.shadow_budget,
            tuple(map(id, state.effects)),
            state.background if isinstance(state.background, str) else tuple(state.background),
            state.tonemap,
            state.light_path if light_path_arg is None else None,
            state.size if size_arg is None else None)


def object_pass_names(obj) -> list[str]:
    """The names of the passes ``obj``'s material gives it (another list: another graph)."""
    return [p.name for phase in Phase for p in obj.material.passes(phase, obj)]


class SetupPlan:
    """The checked pass graph for ``state`` on the light path asked for (or tiled, until the
    context says what it can run), the generated GLSL, the shader roots and the memory it all
    needs, counted against the budget: everything checked before a GL object is made."""

    def __init__(self, state: FrameState, pipeline: str, requested: str | None,
                 size: tuple[int, int], size_where: str):
        self.state = state
        self.pipeline_name = pipeline
        self.requested = requested
        self.size = size
        self.provisional = resolve_light_path(pipeline, requested, FULL_FEATURES)
        self.graph: PassGraph = check_passes(PIPELINES[pipeline](self.provisional).build(state))
        held = renderer_holdings(state, pipeline, size)
        self.held_bytes = sum(held.values())
        check_target_memory(self.graph, size, size_where, held, state.source)
        self.light_types = state.light_types()
        self.shading_models = state.shading_models()
        self.generated = generated_glsl(self.light_types, self.shading_models,
                                        state.gbuffer_layout(),
                                        [obj.material for obj in state.objects])
        classes = [*(type(obj.material) for obj in state.objects), *self.light_types,
                   *self.shading_models, *(type(effect) for effect in state.effects)]
        self.roots = [cls.shader_root for cls in classes if cls.shader_root is not None]


class RenderSetup:
    """The GL side of a :class:`SetupPlan` on ``gl`` (see the module documentation). Made
    whole or not at all: a constructor that fails releases what it made."""

    def __init__(self, plan: SetupPlan, gl: GLContext):
        self.plan = plan
        self.graph = plan.graph
        self.shading_models = plan.shading_models
        self.held_bytes = plan.held_bytes
        try:
            self._build(plan, gl)
        except BaseException:
            self.release()
            raise

    def _build(self, plan: SetupPlan, gl: GLContext) -> None:
        state, ctx, features = plan.state, gl.ctx, gl.features
        self.light_path = resolve_light_path(plan.pipeline_name, plan.requested, features)
        volume_lights = sum(1 for light in state.lights if light.volume != LightVolume.FULLSCREEN)
        check_light_limits(self.light_path, plan.size, volume_lights, len(state.lights),
                           gl.max_texture_size, f"{state.source}: light")
        check_light_radii(self.light_path, state.lights, f"{state.source}: light")
        self.pipeline = PIPELINES[plan.pipeline_name](self.light_path)
        if self.light_path != plan.provisional:
            self.graph = check_passes(self.pipeline.build(state))
        defines = dict(self.pipeline.shader_defines(state))
        if scene_splits_light(plan.shading_models):
            defines[SPLIT_DEFINE] = "1"
        if scene_transmits(plan.shading_models):
            defines[TRANSMISSION_DEFINE] = "1"
        if scene_casts_shadows(state.lights):
            defines[SHADOWS_DEFINE] = "1"
            defines.update(records_defines(state.shadow_budget.max_shadowed_lights))
            if any(light.casts_shadows and light.params.shadow_filter == "pcss"
                   for light in state.lights):
                defines[PCSS_DEFINE] = "1"
        if scene_has_opacity(state, plan.pipeline_name):
            defines[OPACITY_SHADOWS_DEFINE] = "1"
        if scene_has_transparent_casters(state):
            defines[TRANSMITTANCE_DEFINE] = "1"
        self.shaders = ShaderLibrary(ctx, features.glsl_version(), defines)
        for root in plan.roots:
            self.shaders.add_root(root)
        for name, text in plan.generated.items():
            self.shaders.set_virtual_file(name, text)
        self.targets = FrameTargets(ctx, *plan.size)
        self.declare_targets()
        self.resources = Resources(ctx)
        self.skinning = Skinning(ctx, self.shaders, self.resources)
        self.light_buffer = LightBuffer(ctx)
        self.light_lists = LightLists(ctx) if features.compute_shaders else None
        budget = state.shadow_budget
        if scene_casts_shadows(state.lights):
            check_records_fit(ctx, budget.max_shadowed_lights, f"{state.source}: shadows")
        self.shadow_atlas = ShadowAtlas(
            ctx, budget.atlas_size, budget.max_shadowed_lights,
            opacity_size(state, plan.pipeline_name), opacity_extent(state),
            opacity_extent(state) if scene_has_transparent_casters(state) else 0,
            budget.allocation) \
            if scene_casts_shadows(state.lights) else None
        # The per-frame GPU resources every frame is given: by name on its blackboard (for the
        # passes that fill or read them), and those that bind themselves to every program as
        # its binding sources. A new global resource is one more entry here.
        self.blackboard = {LIGHT_BUFFER: self.light_buffer, LIGHT_LISTS: self.light_lists,
                           SHADOW_ATLAS: self.shadow_atlas}
        self.binding_sources = [source for source in (self.light_buffer, self.light_lists,
                                                      self.shadow_atlas)
                                if source is not None]
        self.checked_framebuffers: dict = {}  # Frame.use_framebuffer's, for the setup's life
        error = ctx.error
        if error != "GL_NO_ERROR":  # the targets did not fit
            raise gl_error("creating the render targets", error, plan.size)

    def declare_targets(self) -> None:
        for name, spec in self.graph.targets.items():
            self.targets.declare(name, spec)

    def insert_pass(self, render_pass: RenderPass, before: str | None,
                    after: str | None) -> None:
        """Insert ``render_pass`` before or after the pass named so; the graph is checked again
        (and left as it was if the new pass does not fit) and new targets are created."""
        index = self.graph.index(before if before is not None else after)
        passes = list(self.graph.passes)
        passes.insert(index if before is not None else index + 1, render_pass)
        graph = check_passes(passes)
        for name, spec in graph.targets.items():
            if name in self.targets and not self.targets.specs[name].same_format(spec):
                raise PassGraphError(f"pass {render_pass.name}: target '{name}' exists with "
                                     "another format")
        self.graph = graph
        self.declare_targets()

    def release(self) -> None:
        """Every GL object made here (a constructor that failed part way made only some)."""
        for name in ("skinning", "light_buffer", "light_lists", "shadow_atlas", "resources",
                     "targets", "shaders"):
            part = self.__dict__.pop(name, None)
            if part is not None:
                part.release()
