"""The deferred and forward pipelines: each builds the ordered pass list for a scene.

Deferred (Revie 2.1): geometry -> screen -> stipple -> lighting -> material -> post -> output.
Forward: one lit pass per object (every light looped per fragment), then the materials' forward
passes, then the same post. Both see the scene only through the material and light interfaces.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .gbuffer import DEPTH, GBUFFER_TARGETS, NORMAL_EXPONENT_ID
from .graph import compile_graph
from .light import LightTypePass
from .passes import ClearPass, FullscreenPass, Order, Phase, RenderPass
from .scene import Scene
from .screen import SSAO, ssao_passes
from .targets import (
    COMPOSITE,
    COMPOSITE_SPEC,
    FINAL,
    FINAL_SPEC,
    LIGHT_ACCUMULATION,
    LIGHT_ACCUMULATION_SPEC,
)

TONEMAPS = {"none": 0, "reinhard": 1, "aces": 2}


def tonemap_pass() -> RenderPass:
    return FullscreenPass(
        "post.tonemap", Phase.POST, "post/tonemap.frag", {"u_source": COMPOSITE}, (FINAL,),
        creates={FINAL: FINAL_SPEC}, uniforms=lambda frame: {"u_exposure": frame.scene.exposure,
                                "u_tonemap": TONEMAPS[frame.scene.tonemap]})


def object_passes(scene: Scene, phase: Phase) -> list[RenderPass]:
    """The objects' passes of ``phase``, by ``Order``: opaque ones in scene order, blended
    ones (volumes, transparent surfaces) far to near, so object order never changes the image."""
    view = scene.camera.view()
    keyed = []
    for index, obj in enumerate(scene.objects):
        low, high = obj.mesh.bounds()
        centre = obj.model @ np.append((low + high) / 2.0, 1.0)
        distance = -(view @ centre)[2]
        for render_pass in obj.material.passes(phase, obj):
            blended = render_pass.order >= Order.VOLUME
            keyed.append(((render_pass.order, -distance if blended else 0.0, index), render_pass))
    return [render_pass for _, render_pass in sorted(keyed, key=lambda item: item[0])]


class Pipeline:
    name = ""

    def build(self, scene: Scene) -> list[RenderPass]:
        raise NotImplementedError

    def passes(self, scene: Scene) -> list[RenderPass]:
        """The pass list for ``scene``, checked (:func:`deferred.graph.compile_graph`)."""
        return compile_graph(self.build(scene)).passes


class DeferredPipeline(Pipeline):
    name = "deferred"

    def build(self, scene: Scene) -> list[RenderPass]:
        layout = scene.gbuffer_layout()
        passes: list[RenderPass] = [ClearPass("gbuffer.clear", Phase.GEOMETRY, layout.targets)]
        passes += object_passes(scene, Phase.GEOMETRY)
        passes += screen_passes(scene)
        passes += object_passes(scene, Phase.SCREEN)
        passes += object_passes(scene, Phase.STIPPLE)
        passes.append(FullscreenPass(
            "lighting.background", Phase.LIGHTING, "lights/background.frag",
            {"u_normal_exponent_id": NORMAL_EXPONENT_ID}, (LIGHT_ACCUMULATION,),
            creates={LIGHT_ACCUMULATION: LIGHT_ACCUMULATION_SPEC},
            uniforms=lambda frame: {"u_background": frame.scene.background}))
        occlusion = SSAO if scene.ssao else None
        passes += [LightTypePass(cls, occlusion, layout.color_targets)
                   for cls in scene.light_types()]
        passes.append(FullscreenPass("material.composite_copy", Phase.MATERIAL, "post/copy.frag",
                                     {"u_source": LIGHT_ACCUMULATION}, (COMPOSITE,),
                                     creates={COMPOSITE: COMPOSITE_SPEC}))
        passes += object_passes(scene, Phase.MATERIAL)
        passes.append(tonemap_pass())
        return passes


def screen_passes(scene: Scene) -> list[RenderPass]:
    """Scene-wide screen-space passes over the clean G-buffer (before any stipple)."""
    return ssao_passes(scene.ssao) if scene.ssao else []


class ForwardPipeline(Pipeline):
    name = "forward"

    def build(self, scene: Scene) -> list[RenderPass]:
        passes: list[RenderPass] = [ClearPass("forward.clear", Phase.FORWARD, {
            COMPOSITE: replace(COMPOSITE_SPEC, clear=(*scene.background, 0.0)),
            DEPTH: GBUFFER_TARGETS[DEPTH]})]
        passes += object_passes(scene, Phase.FORWARD)
        passes.append(tonemap_pass())
        return passes


PIPELINES: dict[str, type[Pipeline]] = {"deferred": DeferredPipeline,
                                        "forward": ForwardPipeline}
