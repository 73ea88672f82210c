"""The deferred and forward pipelines: each builds the ordered pass list for a scene.

Deferred (Revie 2.1): geometry -> screen -> stipple -> lighting -> material -> post -> output.
Forward: one lit pass per object (every light looped per fragment), then the materials' forward
passes, then the same post. Both see the scene only through the material and light interfaces.
"""

from __future__ import annotations

import numpy as np

from .errors import RenderError
from .gbuffer import ALBEDO_SPECULAR, DEPTH, LINEAR_DEPTH, NORMAL_EXPONENT_ID
from .light import LightTypePass
from .passes import ClearPass, FullscreenPass, Order, Phase, RenderPass
from .scene import Scene
from .screen import SSAO, ssao_passes
from .targets import COMPOSITE, FINAL, LIGHT_ACCUMULATION

TONEMAPS = {"none": 0, "reinhard": 1, "aces": 2}


def tonemap_pass() -> RenderPass:
    return FullscreenPass(
        "post.tonemap", Phase.POST, "post/tonemap.frag", {"u_source": COMPOSITE}, (FINAL,),
        uniforms=lambda frame: {"u_exposure": frame.scene.exposure,
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
        passes = self.build(scene)
        seen: set[str] = set()
        for render_pass in passes:
            if render_pass.name in seen:
                raise RenderError(f"two passes are named '{render_pass.name}'")
            seen.add(render_pass.name)
        return passes


class DeferredPipeline(Pipeline):
    name = "deferred"

    def build(self, scene: Scene) -> list[RenderPass]:
        from . import registry

        passes: list[RenderPass] = [ClearPass(
            "gbuffer.clear", Phase.GEOMETRY,
            {ALBEDO_SPECULAR: (0.0,) * 4, NORMAL_EXPONENT_ID: (0.0,) * 4, LINEAR_DEPTH: (0.0,)},
            depth=DEPTH)]
        passes += object_passes(scene, Phase.GEOMETRY)
        passes += screen_passes(scene)
        passes += object_passes(scene, Phase.SCREEN)
        passes += object_passes(scene, Phase.STIPPLE)
        passes.append(FullscreenPass(
            "lighting.background", Phase.LIGHTING, "lights/background.frag",
            {"u_normal_exponent_id": NORMAL_EXPONENT_ID}, (LIGHT_ACCUMULATION,),
            uniforms=lambda frame: {"u_background": frame.scene.background}))
        present = {type(light) for light in scene.lights}
        occlusion = SSAO if scene.ssao else None
        passes += [LightTypePass(cls, occlusion) for _, cls in registry.lights.items()
                   if cls in present]
        passes.append(FullscreenPass("material.composite_copy", Phase.MATERIAL, "post/copy.frag",
                                     {"u_source": LIGHT_ACCUMULATION}, (COMPOSITE,)))
        passes += object_passes(scene, Phase.MATERIAL)
        passes.append(tonemap_pass())
        return passes


def screen_passes(scene: Scene) -> list[RenderPass]:
    """Scene-wide screen-space passes over the clean G-buffer (before any stipple)."""
    return ssao_passes(scene.ssao) if scene.ssao else []


class ForwardPipeline(Pipeline):
    name = "forward"

    def build(self, scene: Scene) -> list[RenderPass]:
        passes: list[RenderPass] = [ClearPass("forward.clear", Phase.FORWARD,
                                              {COMPOSITE: (*scene.background, 0.0)},
                                              depth=DEPTH)]
        passes += object_passes(scene, Phase.FORWARD)
        passes.append(tonemap_pass())
        return passes


PIPELINES: dict[str, type[Pipeline]] = {"deferred": DeferredPipeline,
                                        "forward": ForwardPipeline}
