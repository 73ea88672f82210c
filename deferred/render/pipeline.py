"""The deferred and forward pipelines: each builds the ordered pass list for a scene.

Deferred (Revie 2.1): geometry -> screen -> stipple -> lighting -> material -> post -> output.
Forward: one lit pass per object (every light looped per fragment), then the materials' forward
passes, then the same post. Both see the scene only through the material, light and effect
interfaces.

Within a phase, passes run by ``Order`` rank; at one rank the pipeline's own passes come first,
then scene-wide passes (effects, materials' ``scene_passes``) in scene order, then the objects':
opaque ones in scene order, blended ones (volumes, transparent surfaces) far to near, so object
order never changes the image. A scene-wide pass that several materials contribute under one
name (a shared technique's) runs once.
"""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from deferred import names
from deferred.core.frame import OfferedUniforms
from deferred.core.graph import PassGraph, compile_graph
from deferred.core.passes import (
    ClearPass,
    CopyPass,
    FullscreenPass,
    ObjectPass,
    Order,
    Phase,
    RenderPass,
    compose_runs,
    copy_pass,
    same_passes,
    without_brackets,
)
from deferred.errors import InputError
from deferred.gbuffer.layout import (
    DEPTH,
    GBUFFER_TARGETS,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    surfaces_need_depth,
)
from deferred.gl.targets import (
    COMPOSITE,
    COMPOSITE_SPEC,
    DIFFUSE_LIGHT,
    DIFFUSE_LIGHT_SPEC,
    FINAL,
    FINAL_SPEC,
    LIGHT_ACCUMULATION,
    LIGHT_ACCUMULATION_SPEC,
)
from deferred.interfaces.effect import AMBIENT_OCCLUSION
from deferred.interfaces.shading import scene_splits_light
from deferred.interfaces.techniques import ForwardLitPass
from deferred.lighting.culling import LightCullPass, list_shading_pass
from deferred.lighting.shadows.caster_pass import ShadowPass
from deferred.lighting.shadows.plan import scene_casts_shadows
from deferred.lighting.volumes import LightTypePass, surface_pass
from deferred.memo import overrides
from deferred.names import ENVIRONMENT_BACKGROUND
from deferred.scene.state import FrameState, ObjectState

# what the pass graph checks beyond the core's rules: the G-buffer's
GRAPH_RULES = (surfaces_need_depth,)


def check_passes(passes: list[RenderPass]) -> PassGraph:
    """The checked pass graph of ``passes`` (:func:`deferred.core.graph.compile_graph` with
    :data:`GRAPH_RULES`)."""
    return compile_graph(passes, GRAPH_RULES)


TONEMAPS = {"none": 0, "reinhard": 1, "aces": 2}

PIPELINE_PASS, SCENE_PASS, OBJECT_PASS = 0, 1, 2  # groups within one Order rank


def clear_colour(scene: FrameState) -> tuple[float, float, float]:
    """What the frame is cleared to behind the scene: the background colour, or black where
    a pass draws the environment there (:func:`environment_background_pass`)."""
    if isinstance(scene.background, str):
        return (0.0, 0.0, 0.0)
    return tuple(scene.background)


def environment_background_pass(phase: Phase, target: str, order: int) -> RenderPass:
    """The environment light's map behind the scene (``background = "environment"``): drawn
    on the far plane where the depth test "lequal" finds nothing nearer, into ``target``
    (alpha 0, as the background colour)."""
    return FullscreenPass(f"{phase.value}.environment_background", phase,
                          "lighting/environment_background.frag", {}, (target,),
                          defines={"FULLSCREEN_AT_FAR": "1"}, depth=DEPTH, depth_test=True,
                          depth_func="lequal", order=order)


def tonemap_pass(scene: FrameState, snapshot: CopyPass | None = None) -> RenderPass:
    """Exposure, the scene's tone mapping operator (fixed when the passes are built, as the
    background is) and sRGB encoding; with ``snapshot`` (a copy of the final image the post
    phase takes before anything writes it: FXAA's source) that copy too, as a second output."""
    creates = {FINAL: FINAL_SPEC}
    defines = {"TONEMAP": str(TONEMAPS[scene.tonemap])}
    if snapshot is not None:
        creates[snapshot.target] = snapshot.creates[snapshot.target]
        defines["WRITE_SNAPSHOT"] = "1"
    return FullscreenPass(
        "post.tonemap", Phase.POST, "post/tonemap.frag", {"u_source": COMPOSITE},
        tuple(creates), creates=creates, order=Order.FIRST, defines=defines,
        uniforms=lambda frame: {"u_exposure": frame.scene.exposure})


def post_passes(scene: FrameState, wide: list[RenderPass]) -> list[RenderPass]:
    """The post phase: the tone mapping first, which makes the first copy of the final image
    the phase takes before any other pass writes it (one full-screen pass fewer)."""
    post = phase_passes(scene, Phase.POST, [tonemap_pass(scene)], wide)
    folded = leading_snapshots(post[1:], FINAL)[:1]
    if not folded:
        return post
    return [tonemap_pass(scene, folded[0]),
            *(p for p in post[1:] if not any(p is f for f in folded))]


def scene_passes(scene: FrameState, pipeline: str) -> list[RenderPass]:
    """Scene-wide passes of every phase: the effects' (those applying to ``pipeline``), then the
    materials' (once per material class, shared names once)."""
    passes: list[RenderPass] = []
    for effect in scene.effects:
        if effect.applies_to(pipeline):
            passes += effect.passes(scene, pipeline)
        else:
            hint = " (forward = true runs it there, over a G-buffer written first)" \
                if effect.reads_gbuffer and pipeline == names.Pipeline.FORWARD else ""
            warnings.warn(f"effect {effect.name} applies to the {', '.join(effect.pipelines)} "
                          f"pipeline only; skipped in the {pipeline} pipeline{hint}",
                          stacklevel=2)
    by_class: dict[type, list] = {}
    for obj in scene.objects:
        by_class.setdefault(type(obj.material), []).append(obj)
    if pipeline == names.Pipeline.FORWARD:
        phases = [Phase.GEOMETRY, Phase.SCREEN, Phase.FORWARD] if forward_gbuffer(scene) else \
            [Phase.FORWARD]
    else:
        phases = [Phase.GEOMETRY, Phase.SCREEN, Phase.STIPPLE, Phase.LIGHTING, Phase.MATERIAL]
    shared: dict[str, RenderPass] = {}
    for cls, objects in by_class.items():
        for phase in [*phases, Phase.POST]:
            for render_pass in cls.scene_passes(objects, phase):
                first = shared.get(render_pass.name)
                if first is None:
                    shared[render_pass.name] = render_pass
                    passes.append(render_pass)
                elif type(first) is not type(render_pass) or \
                        first.describe() != render_pass.describe():
                    raise InputError(f"two materials add different scene passes named "
                                     f"'{render_pass.name}'", f"material {cls.name}")
    return passes


def forward_gbuffer(scene: FrameState) -> bool:
    """Whether the forward pipeline writes the G-buffer first: an effect reading it runs there
    (``Effect.reads_gbuffer`` with ``forward``)."""
    return any(effect.reads_gbuffer and effect.applies_to(names.Pipeline.FORWARD)
               for effect in scene.effects)


def camera_distance(scene: FrameState, obj: ObjectState) -> float:
    """How far in front of the camera the centre of ``obj``'s bounds is (its view depth)."""
    low, high = obj.mesh.bounds()
    centre = obj.model @ np.append((low + high) / 2.0, 1.0)
    return float(-(scene.camera.view() @ centre)[2])


def sort_blended(passes: list[RenderPass], scene: FrameState) -> list[RenderPass]:
    """``passes`` with each run of blended object passes (volumes, transparent surfaces) of
    one phase and rank put far to near for the camera and transforms of this frame (the
    order the passes were built in holds the first frame's), and each composition's begin
    and end passes around the runs of its members (:func:`compose_runs`): the same list
    where it already is so."""
    bare = without_brackets(passes)
    index_of = {obj.node: k for k, obj in enumerate(scene.objects)}
    out = bare
    start = 0
    while start < len(bare):
        first = bare[start]
        end = start + 1
        if _blended_object_pass(first):
            while end < len(bare) and _blended_object_pass(bare[end]) and \
                    bare[end].phase == first.phase and bare[end].order == first.order:
                end += 1
            if end - start > 1:
                run = bare[start:end]
                distances = {p.node: camera_distance(scene, scene.object_state(p.node))
                             for p in run}
                ordered = sorted(run, key=lambda p: (-distances[p.node],
                                                     index_of.get(p.node, 0)))
                if ordered != run:
                    if out is bare:
                        out = list(bare)
                    out[start:end] = ordered
        start = end
    if bare is passes:
        return out
    out = compose_runs(out, brackets=passes)
    return passes if same_passes(out, passes) else out


def leading_snapshots(passes: list[RenderPass], source: str = COMPOSITE) -> list[CopyPass]:
    """The copies of ``source`` among ``passes`` (in order) that run before any of them writes
    it: ``source`` as the pass before them made it (a composition's own copy, ``brackets``,
    runs where its members are: never one)."""
    found = []
    for render_pass in passes:
        if isinstance(render_pass, CopyPass) and render_pass.source == source and \
                render_pass.brackets is None:
            found.append(render_pass)
        elif source in render_pass.writes:
            break
    return found


def _blended_object_pass(render_pass: RenderPass) -> bool:
    return render_pass.order >= Order.VOLUME and render_pass.order != Order.LAST and \
        getattr(render_pass, "node", None) is not None


def phase_passes(scene: FrameState, phase: Phase, fixed: list[RenderPass],
                 scene_wide: list[RenderPass]) -> list[RenderPass]:
    """Every pass of ``phase``: the pipeline's own (``fixed``), the scene-wide ones of this
    phase and the objects', ranked as the module documentation says."""
    keyed = [((p.order, PIPELINE_PASS, 0.0, k), p) for k, p in enumerate(fixed)]
    keyed += [((p.order, SCENE_PASS, 0.0, k), p) for k, p in enumerate(scene_wide)
              if p.phase == phase]
    for index, obj in enumerate(scene.objects):
        distance = camera_distance(scene, obj)
        for render_pass in obj.material.passes(phase, obj):
            blended = render_pass.order >= Order.VOLUME
            keyed.append(((render_pass.order, OBJECT_PASS, -distance if blended else 0.0, index),
                          render_pass))
    # a composition's begin and end passes around its members (once: each frame's order splits
    # them into runs, sort_blended)
    return compose_runs([render_pass for _, render_pass in sorted(keyed,
                                                                  key=lambda item: item[0])],
                        split=False)


class Pipeline:
    """A pipeline for one light path (:mod:`deferred.lighting.paths`)."""

    name = ""
    light_paths: tuple[str, ...] = ()

    def __init__(self, light_path: str | None = None):
        self.light_path = light_path or names.LightPath.TILED
        if self.light_path not in self.light_paths:
            raise InputError(f"the {self.name} pipeline has no light path '{self.light_path}' "
                             f"(choose from {', '.join(self.light_paths)})", "light_path")

    def build(self, scene: FrameState) -> list[RenderPass]:
        raise NotImplementedError

    def shader_defines(self, scene: FrameState) -> dict[str, str]:
        """Defines every program of this pipeline gets for ``scene`` (the light path's)."""
        return {}

    def passes(self, scene: FrameState) -> list[RenderPass]:
        """The pass list for ``scene``, checked (:func:`check_passes`)."""
        return check_passes(self.build(scene)).passes


class DeferredPipeline(Pipeline):
    name = names.Pipeline.DEFERRED
    light_paths = names.LIGHT_PATHS[names.Pipeline.DEFERRED]

    def build(self, scene: FrameState) -> list[RenderPass]:
        layout = scene.gbuffer_layout()
        wide = scene_passes(scene, self.name)
        clear = ClearPass("gbuffer.clear", Phase.GEOMETRY, layout.targets)
        shadows = [ShadowPass(Phase.GEOMETRY)] if scene_casts_shadows(scene.lights) else []
        passes = phase_passes(scene, Phase.GEOMETRY, [*shadows, clear], wide)
        passes += phase_passes(scene, Phase.SCREEN, [], wide)
        passes += phase_passes(scene, Phase.STIPPLE, [], wide)
        occlusion = AMBIENT_OCCLUSION if any(AMBIENT_OCCLUSION in p.creates for p in passes) \
            else None
        environment = scene.background == ENVIRONMENT_BACKGROUND
        split = scene_splits_light(scene.shading_models())
        material = phase_passes(scene, Phase.MATERIAL, [], wide)
        folded: list[CopyPass] = []  # the material phase's copies the lighting pass makes
        if self.light_path == names.LightPath.VOLUMES:
            # the light accumulation starts as 0 on surfaces and the background elsewhere
            # (its clear); each light type's pass adds into it
            background = surface_pass("lighting.background", "lighting/background.frag",
                                      {"u_normal_exponent_id": NORMAL_EXPONENT_ID},
                                      {LIGHT_ACCUMULATION: LIGHT_ACCUMULATION_SPEC},
                                      clear_colour(scene))
            lights = [background, *(LightTypePass(cls, occlusion, layout.color_targets, split)
                                    for cls in scene.light_types())]
            if split:
                lights.insert(0, ClearPass("lighting.diffuse_clear", Phase.LIGHTING, {
                    DIFFUSE_LIGHT: replace(DIFFUSE_LIGHT_SPEC, clear=(0.0, 0.0, 0.0, 0.0))}))
            composite = False
        else:
            # One pass shades every light and writes the background where there is no surface.
            # Where no other pass writes the light accumulation, the composition starts as the
            # light accumulation: the same pass writes both (no copy pass), and the snapshot
            # of the composition the material phase takes before its first write to it.
            clustered = self.light_path == names.LightPath.CLUSTERED
            # lists from the near plane where transparent surfaces in front of the opaque
            # ones read them too (tiled: the G-buffer's depth bounds would miss them)
            from_near = lit_transparent(scene)
            composite = not environment and not split and not any(
                LIGHT_ACCUMULATION in p.writes
                for p in phase_passes(scene, Phase.LIGHTING, [], wide))
            if composite:
                folded = leading_snapshots(material)[:1]
            lights = [LightCullPass(f"lighting.cull_{'clusters' if clustered else 'tiles'}",
                                    Phase.LIGHTING, clustered, from_near=from_near),
                      list_shading_pass(f"lighting.{self.light_path}", clustered,
                                        layout.color_targets, occlusion,
                                        clear_colour(scene), composite=composite,
                                        split=split,
                                        snapshots={p.target: p.creates[p.target]
                                                   for p in folded})]
        if environment:  # behind the lit surfaces, after every light
            lights.append(environment_background_pass(Phase.LIGHTING, LIGHT_ACCUMULATION,
                                                      Order.LAST))
        passes += phase_passes(scene, Phase.LIGHTING, lights, wide)
        if not composite:
            material = phase_passes(scene, Phase.MATERIAL, [copy_pass(
                "material.composite_copy", Phase.MATERIAL, LIGHT_ACCUMULATION, COMPOSITE,
                COMPOSITE_SPEC, order=Order.FIRST)], wide)
        passes += [p for p in material if not any(p is f for f in folded)]
        passes += post_passes(scene, wide)
        return passes

    def shader_defines(self, scene: FrameState) -> dict[str, str]:
        """On the tiled and clustered paths, where transparent surfaces are lit after the
        opaque scene (glass), ``forward_lighting`` loops each point's list (LISTED_LIGHTS)
        rather than every light of the frame."""
        if self.light_path == names.LightPath.VOLUMES or not lit_transparent(scene):
            return {}
        defines = {"LISTED_LIGHTS": "1"}
        if self.light_path == names.LightPath.CLUSTERED:
            defines["LIGHT_LISTS_CLUSTERED"] = "1"
        return defines


def lit_transparent(scene: FrameState) -> bool:
    """Whether the deferred pipeline lights transparent surfaces in its material phase (a
    pass marked ``transparent``: glass)."""
    return any(p.transparent for obj in scene.objects
               for p in obj.material.passes(Phase.MATERIAL, obj))


class ForwardPipeline(Pipeline):
    name = names.Pipeline.FORWARD
    light_paths = names.LIGHT_PATHS[names.Pipeline.FORWARD]

    def build(self, scene: FrameState) -> list[RenderPass]:
        wide = scene_passes(scene, self.name)
        gbuffer = forward_gbuffer(scene)
        shadows = [ShadowPass(Phase.GEOMETRY if gbuffer else Phase.FORWARD)] \
            if scene_casts_shadows(scene.lights) else []
        creates = {COMPOSITE: replace(COMPOSITE_SPEC, clear=(*clear_colour(scene), 0.0))}
        passes: list[RenderPass] = []
        fixed: list[RenderPass] = []
        if gbuffer:
            # the G-buffer an effect reads (SSAO, edges), written by the objects' G-buffer
            # passes, then the screen phase: its depth is the lit passes' too
            clear = ClearPass("gbuffer.clear", Phase.GEOMETRY, scene.gbuffer_layout().targets)
            passes = phase_passes(scene, Phase.GEOMETRY, [*shadows, clear], wide)
            passes += phase_passes(scene, Phase.SCREEN, [], wide)
            shadows = []
        else:
            creates[DEPTH] = GBUFFER_TARGETS[DEPTH]
        if self.light_path == names.LightPath.TILED:  # Forward+: depth pre-pass, tiled culling
            if not gbuffer:
                creates[LINEAR_DEPTH] = GBUFFER_TARGETS[LINEAR_DEPTH]
                fixed += [depth_prepass(p) for obj in scene.objects
                          for p in obj.material.passes(Phase.FORWARD, obj)
                          if isinstance(p, ForwardLitPass) and not p.transparent]
            fixed.append(LightCullPass("forward.cull_tiles", Phase.FORWARD, clustered=False,
                                       from_near=True))
        clear = ClearPass("forward.clear", Phase.FORWARD, creates)
        if scene.background == ENVIRONMENT_BACKGROUND:  # after the opaque surfaces
            fixed.append(environment_background_pass(Phase.FORWARD, COMPOSITE, Order.OPAQUE + 1))
        forward = phase_passes(scene, Phase.FORWARD, [*shadows, clear, *fixed], wide)
        if any(AMBIENT_OCCLUSION in p.creates for p in passes):
            for render_pass in forward:  # the opaque surfaces the occlusion was found for
                if isinstance(render_pass, ForwardLitPass) and not render_pass.transparent:
                    render_pass.read_occlusion()
        passes += forward
        passes += post_passes(scene, wide)
        return passes

    def shader_defines(self, scene: FrameState) -> dict[str, str]:
        return {"FORWARD_PLUS": "1"} if self.light_path == names.LightPath.TILED else {}


class DepthPrepass(ObjectPass):
    """Forward+'s depth pre-pass twin of an object's lit pass ``lit``: the same vertex stage,
    constants, uniforms and textures (a vertex stage displacing by a texture, shell_fur's
    strands, puts the depth where the lit pass draws), depth and linear depth only."""

    fragment = "forward/depth_prepass.frag"
    colors = (LINEAR_DEPTH,)
    order = Order.FIRST
    lit: ForwardLitPass | None = None

    def prepare(self, frame) -> None:
        self.lit.prepare(frame)  # a twin of the graph's lit pass: what its hooks read

    def uniforms(self, frame) -> dict:
        # those of its stages: the lit pass's and its inputs'
        return OfferedUniforms(self.lit.gather_uniforms(frame, self.object(frame)))

    def textures(self, frame) -> dict:
        # the lit pass's target reads are not the pre-pass's (it runs before their makers)
        if self.lit.samples:
            return {}
        return OfferedUniforms(self.lit.gather_textures(frame, self.object(frame)))

    def draw(self, frame, program) -> None:
        self.lit.draw(frame, program)  # what the lit pass draws (a material's own geometry)


def depth_prepass(lit: ForwardLitPass) -> RenderPass:
    """Forward+'s depth pre-pass twin of ``lit`` (its faces: a double-sided surface's back
    faces too): a plain object pass of its vertex stage and constants where those are all it
    sets (most materials: no hooks asked at each draw), else
    a :class:`DepthPrepass`."""
    # an object's lit pass is <label>.forward; a material's other lit passes keep their names
    stem = lit.name.removesuffix(".forward") if lit.name == f"{lit.node.label}.forward" \
        else lit.name
    name = f"{stem}.depth_prepass"
    if lit._hooks_unchanged and not lit.inputs and lit.shape is None and \
            not overrides(type(lit), RenderPass, "prepare") and \
            not overrides(type(lit), ObjectPass, "draw"):
        return ObjectPass(name, Phase.FORWARD, lit, vertex=lit.vertex,
                          fragment=DepthPrepass.fragment, colors=DepthPrepass.colors,
                          constants=lit.constants, cull=lit.cull, order=Order.FIRST)
    return DepthPrepass(name, Phase.FORWARD, lit, vertex=lit.vertex,
                        constants=lit.constants, cull=lit.cull, lit=lit)


PIPELINES: dict[str, type[Pipeline]] = {names.Pipeline.DEFERRED.value: DeferredPipeline,
                                        names.Pipeline.FORWARD.value: ForwardPipeline}
