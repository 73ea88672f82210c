"""FXAA: anti-aliasing in post, over the tone-mapped frame (Lottes' FXAA 3.11 quality
algorithm, ``effects/fxaa/fxaa.frag``). It copies ``final`` and resamples the copy into ``final``,
after every other post pass."""

from __future__ import annotations

from pydantic import Field

from deferred.api import (
    FINAL,
    FINAL_SPEC,
    Effect,
    EffectParams,
    FullscreenPass,
    Order,
    Phase,
    RenderPass,
    Scene,
    copy_pass,
    effects,
)

FXAA_SOURCE = "fxaa_source"


class FXAAParams(EffectParams):
    edge_threshold: float = Field(0.125, gt=0.0, le=1.0,
                                  description="contrast needed, relative to the local luma")
    edge_threshold_min: float = Field(0.0312, ge=0.0, le=1.0,
                                      description="contrast needed in dark areas")
    subpixel: float = Field(0.75, ge=0.0, le=1.0, description="sub-pixel blend (0 = off)")


@effects.register
class FXAA(Effect):
    name = "fxaa"
    Params = FXAAParams

    def passes(self, scene: Scene, pipeline: str) -> list[RenderPass]:
        return [
            copy_pass("post.fxaa_source", Phase.POST, FINAL, FXAA_SOURCE, FINAL_SPEC,
                      order=Order.LAST),
            FullscreenPass("post.fxaa", Phase.POST, "effects/fxaa/fxaa.frag",
                           {"u_source": FXAA_SOURCE}, (FINAL,), uniforms=self.uniforms,
                           order=Order.LAST),
        ]
