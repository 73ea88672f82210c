"""The ``glass`` material: thin transparent surfaces composed order-independently, in both
pipelines, over the lit opaque scene (the deferred pipeline's material phase, the forward
pipeline's lit passes) and depth-tested against it.

A layer of glass (``layer.glsl``) sends the viewer what it scatters itself (``opacity``, lit
with ``color`` as albedo) and its highlight, lit by every light of the frame and their
shadows, and keeps from the viewer, per channel, ``1 - (1 - opacity) (1 - F) color`` of what
lies behind it (``color`` is its transmittance; F is glass's Fresnel reflectance at the view
angle). What is seen through it is read at a screen-space offset against the slant of its
normal (``refraction``). Two ways of composing the layers of a pixel (``mode``):

- ``wboit`` (default): weighted blended order-independent transparency (McGuire and Bavoil
  2013), per channel: each fragment adds its weighted light and coverage into two targets and
  multiplies its transparency into a third (one pass, four outputs, each with its own blend
  state); a full-screen pass divides and composes. One layer is exact; more are approximated
  by weighting nearer layers more (``docs``: the error measured against ``exact``).
- ``exact``: per-pixel linked lists in storage buffers (GL 4.3): each fragment pushes its layer
  onto its pixel's list, and a full-screen pass sorts the ``layers`` nearest and composes them
  front to back. The reference to judge ``wboit`` by.

The layers of the scene's glass objects are one composition (``deferred.api.compose_runs``):
the blended passes of other objects (fur shells, hair) that lie between glass objects in the
far-to-near order split it, so glass in front of fur covers it and glass behind it is seen
through it. Glass casts coloured shadows: its shadow caster multiplies its transmittance into
the shadow atlas's transmittance map (``lighting/shadows.glsl``), so what lies behind it along
a light is lit through its colour.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

import moderngl
from pydantic import Field

from deferred.api import (
    BEGIN,
    COMPOSITE,
    COMPOSITE_SPEC,
    DEPTH,
    END,
    Albedo,
    Blend,
    BlinnPhongParams,
    ClearPass,
    FullscreenPass,
    InputError,
    Material,
    ObjectPass,
    Order,
    Phase,
    RenderError,
    RenderPass,
    ShadowCaster,
    TargetSpec,
    Technique,
    copy_pass,
    materials,
)

if TYPE_CHECKING:
    from deferred.api import Frame, SceneObject, ShadowView

COMPOSITION = "glass"
ACCUM = "glass_accum"
COVERAGE = "glass_coverage"
REVEALAGE = "glass_revealage"
REFRACTION = "glass_refraction"
BACKGROUND = "glass_background"
WBOIT_TARGETS = {
    ACCUM: TargetSpec(4, "f2", "glass: sum of emitted light x weight", clear=(0.0,) * 4),
    COVERAGE: TargetSpec(4, "f2", "glass: sum of coverage x weight", clear=(0.0,) * 4),
    REVEALAGE: TargetSpec(4, "f2", "glass: product of 1 - coverage", clear=(1.0,) * 4),
    REFRACTION: TargetSpec(2, "f2", "glass: sum of refraction offsets", clear=(0.0, 0.0)),
}
# the accumulation's outputs: add, add, multiply by one minus the source, add
WBOIT_BLEND = ("add", "add", Blend("zero", "one_minus_src_color"), "add")
# storage buffer bindings of the exact mode's lists (the light lists take 1)
LIST_BINDINGS = {"GLASS_HEADS_BINDING": "4", "GLASS_LAYERS_BINDING": "5",
                 "GLASS_LINKS_BINDING": "6"}
NODE_BYTES = 24  # a node's layer (uvec4) and link (uvec2)


class GlassParams(BlinnPhongParams):
    color: Albedo = Field((0.9, 0.95, 1.0), description="transmittance: what passes through "
                                                         "is multiplied by it, each in [0, 1]")
    opacity: float = Field(0.05, ge=0.0, le=1.0, description="the fraction the surface "
                                                              "scatters itself (lit, with color "
                                                              "as albedo) instead of passing on")
    mode: Literal["wboit", "exact"] = Field("wboit", description="wboit: weighted blended OIT; "
                                            "exact: per-pixel sorted lists (GL 4.3)")
    refraction: float = Field(0.03, ge=0.0, le=0.5, description="screen offset of what is seen "
                              "through, per unit of the normal's slant (a fraction of the "
                              "frame's height)")
    layers: int = Field(8, ge=1, le=32, description="exact mode: the nearest layers a pixel "
                        "composes; its fragment pool holds this many a pixel")
    specular_intensity: float = Field(0.8, ge=0.0, le=1.0, description="Blinn-Phong intensity")
    specular_exponent: float = Field(128.0, ge=1.0, le=2048.0,
                                     description="Blinn-Phong exponent")


class GlassLists:
    """The exact mode's storage: the heads (a count, then a node a pixel) and the pool of
    nodes for a frame of ``width`` x ``height`` pixels, ``layers`` nodes a pixel."""

    def __init__(self, ctx: moderngl.Context, width: int, height: int, layers: int):
        self.width = width
        self.capacity = width * height * layers
        self.heads = ctx.buffer(reserve=4 * (1 + width * height))
        self.layers = ctx.buffer(reserve=16 * self.capacity)
        self.links = ctx.buffer(reserve=8 * self.capacity)

    def clear(self) -> None:
        """No node taken, every pixel's list empty (``lists.glsl``: none is 0)."""
        self.heads.clear()

    def bind(self) -> None:
        for buffer, binding in ((self.heads, LIST_BINDINGS["GLASS_HEADS_BINDING"]),
                                (self.layers, LIST_BINDINGS["GLASS_LAYERS_BINDING"]),
                                (self.links, LIST_BINDINGS["GLASS_LINKS_BINDING"])):
            buffer.bind_to_storage_buffer(int(binding))

    @property
    def uniforms(self) -> dict[str, int]:
        return {"u_glass_width": self.width, "u_glass_capacity": self.capacity}

    def release(self) -> None:
        for buffer in (self.heads, self.layers, self.links):
            buffer.release()


def glass_lists(frame: Frame, layers: int) -> GlassLists:
    """The frame's lists (kept for the renderer's life, one set a frame size and bound)."""
    return frame.resources.cached(("glass.lists", frame.width, frame.height, layers),
                                  lambda ctx: GlassLists(ctx, frame.width, frame.height, layers))


def scene_layers(objects) -> int:
    """The layer bound of the scene's exact-mode composition: its objects' largest."""
    return max(obj.material.params.layers for obj in objects)


class ClearListsPass(RenderPass):
    """Exact mode, opening a run of glass: the lists emptied."""

    def __init__(self, phase: Phase, layers: int):
        self.name = f"{phase.value}.glass_clear_lists"
        self.phase = phase
        self.layers = layers
        self.brackets = (COMPOSITION, BEGIN)

    def execute(self, frame: Frame) -> None:
        if not frame.gl.features.storage_buffers:
            raise RenderError("glass mode 'exact' needs storage buffers (GL 4.3); this context "
                              "has none (DEFERRED_GL33?): use mode 'wboit'")
        frame.gl_call(glass_lists(frame, self.layers).clear)


class AppendPass(ObjectPass):
    """Exact mode: an object's glass fragments pushed onto their pixels' lists."""

    fragment = "materials/glass/append.frag"
    colors = ()
    depth = DEPTH
    depth_func = "lequal"
    depth_write = False
    cull = None
    order = Order.VOLUME
    transparent = True
    composition = COMPOSITION
    layers = 8

    def defines(self, frame: Frame) -> dict[str, str]:
        return {**super().defines(frame), **LIST_BINDINGS}

    def uniforms(self, frame: Frame) -> dict:
        return glass_lists(frame, self.layers).uniforms

    def draw(self, frame: Frame, program: moderngl.Program) -> None:
        glass_lists(frame, self.layers).bind()
        super().draw(frame, program)


class ResolvePass(FullscreenPass):
    """Exact mode, closing a run of glass: each pixel's list sorted and composed over the
    snapshot of what lies behind."""

    def __init__(self, phase: Phase, layers: int):
        super().__init__(f"{phase.value}.glass_resolve", phase, "materials/glass/resolve.frag",
                         {"u_glass_background": BACKGROUND}, (COMPOSITE,),
                         defines={**LIST_BINDINGS, "GLASS_LAYERS": str(layers)},
                         brackets=(COMPOSITION, END))
        self.layers = layers
        self.uniforms = lambda frame: {"u_glass_width": frame.width}

    def execute(self, frame: Frame) -> None:
        frame.barrier()  # the appends' storage writes, visible to this pass's reads
        glass_lists(frame, self.layers).bind()
        super().execute(frame)


def accumulate_pass(phase: Phase, obj: SceneObject) -> RenderPass:
    """WBOIT: an object's glass fragments added into the accumulation targets."""
    return ObjectPass(f"{obj.label}.glass", phase, obj,
                      fragment="materials/glass/accumulate.frag", colors=tuple(WBOIT_TARGETS),
                      blend=WBOIT_BLEND, depth=DEPTH, depth_func="lequal", depth_write=False,
                      cull=None, order=Order.VOLUME, transparent=True, composition=COMPOSITION)


def scene_mode(objects) -> str:
    """The mode of the scene's glass composition: the one its objects share."""
    modes = {obj.material.params.mode for obj in objects}
    if len(modes) > 1:
        raise InputError(f"glass objects of one scene compose together and must share a mode "
                         f"(found {', '.join(sorted(modes))})",
                         f"object {objects[0].label}.params.mode")
    return modes.pop()


class GlassPasses(Technique):
    """The members (one pass an object) and the composition's begin and end passes, in the
    phase where glass is composed: the material phase (deferred) or the forward phase."""

    phases = (Phase.MATERIAL, Phase.FORWARD)

    def passes(self, material: Material, phase: Phase, obj: SceneObject) -> list[RenderPass]:
        if phase not in self.phases:
            return []
        if material.params.mode == "exact":
            return [AppendPass(f"{obj.label}.glass", phase, obj,
                               layers=material.params.layers)]
        return [accumulate_pass(phase, obj)]

    def scene_passes(self, objects, phase: Phase) -> list[RenderPass]:
        if phase not in self.phases or not objects:
            return []
        background = copy_pass(f"{phase.value}.glass_background", phase, COMPOSITE, BACKGROUND,
                               COMPOSITE_SPEC, brackets=(COMPOSITION, END))
        if scene_mode(objects) == "exact":
            layers = scene_layers(objects)
            return [ClearListsPass(phase, layers), background, ResolvePass(phase, layers)]
        inputs = {f"u_{name}": name for name in (*WBOIT_TARGETS, BACKGROUND)}
        return [ClearPass(f"{phase.value}.glass_clear", phase, WBOIT_TARGETS,
                          brackets=(COMPOSITION, BEGIN)),
                background,
                FullscreenPass(f"{phase.value}.glass_composite", phase,
                               "materials/glass/composite.frag", inputs, (COMPOSITE,),
                               brackets=(COMPOSITION, END))]


class GlassShadow(ShadowCaster):
    """Glass hides nothing from a light: it draws no depth, only its transmittance
    (``transmittance.frag``), so what lies behind it is lit through its colour."""

    def draw(self, frame: Frame, obj: SceneObject, view: ShadowView) -> None:
        pass

    def transmits(self, obj: SceneObject) -> bool:
        return True

    def draw_transmittance(self, frame: Frame, obj: SceneObject, view: ShadowView) -> None:
        self.draw_with(frame, obj, view, "materials/glass/transmittance.frag")


@materials.register
class GlassMaterial(Material):
    name = "glass"
    Params = GlassParams
    surface_shader = "materials/glass/surface.glsl"
    techniques = (GlassPasses(),)
    shadow = GlassShadow()
    inputs_from_params = True
    # u_opacity is the deep opacity maps' sampler (lighting/shadows.glsl) where fur casts them
    uniform_overrides = {"mode": None, "layers": None,
                         "opacity": lambda value: {"u_glass_opacity": value}}

    @classmethod
    def frame_memory(cls, objects, size: tuple[int, int]) -> dict[str, int]:
        """The exact mode's lists: a head a pixel and ``layers`` nodes a pixel."""
        if scene_mode(objects) != "exact":
            return {}
        layers, pixels = scene_layers(objects), size[0] * size[1]
        return {f"glass lists ({layers} layers a pixel)":
                4 * (1 + pixels) + NODE_BYTES * layers * pixels}
