"""Screen-space ambient occlusion over the clean G-buffer (screen phase).

Revie 2.4.2: SSAO, edge detection and other techniques relying on G-buffer discontinuities must
run before the stippled geometry pass, or the stipple pattern turns into artefacts. The ambient
light multiplies its irradiance by the result (the ``ssao`` target).
"""

from __future__ import annotations

from pydantic import Field

from deferred.api import (
    AMBIENT_OCCLUSION,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    Effect,
    FullscreenPass,
    GBufferEffectParams,
    Phase,
    Pipeline,
    RenderPass,
    Scene,
    TargetSpec,
    effects,
)

SSAO_RAW = "ssao_raw"
SSAO_SPEC = TargetSpec(1, "f1", "ambient occlusion (1 = open)")


class SSAOParams(GBufferEffectParams):
    radius: float = Field(0.35, gt=0.0, description="view-space sampling radius")
    strength: float = Field(1.0, ge=0.0, le=4.0, description="how dark full occlusion gets")
    samples: int = Field(16, ge=1, le=128, description="samples per pixel")


@effects.register
class SSAO(Effect):
    name = "ssao"
    Params = SSAOParams
    pipelines = (Pipeline.DEFERRED,)  # and the forward pipeline with forward = true
    reads_gbuffer = True
    uniform_overrides = {"forward": None}  # where it runs, not a uniform

    def passes(self, scene: Scene, pipeline: str) -> list[RenderPass]:
        """Raw hemisphere SSAO, then a depth-aware blur into the ``ssao`` target."""
        return [
            FullscreenPass("screen.ssao", Phase.SCREEN, "effects/ssao/ssao.frag",
                           {"u_linear_depth": LINEAR_DEPTH,
                            "u_normal_exponent_id": NORMAL_EXPONENT_ID},
                           (SSAO_RAW,), creates={SSAO_RAW: SSAO_SPEC}, uniforms=self.uniforms),
            FullscreenPass("screen.ssao_blur", Phase.SCREEN, "effects/ssao/ssao_blur.frag",
                           {"u_ssao_raw": SSAO_RAW, "u_linear_depth": LINEAR_DEPTH},
                           (AMBIENT_OCCLUSION,), creates={AMBIENT_OCCLUSION: SSAO_SPEC}),
        ]
