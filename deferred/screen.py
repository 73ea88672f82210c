"""Screen-phase passes: effects over the clean G-buffer, run before any stipple pass.

Revie 2.4.2: SSAO, edge detection and other techniques relying on G-buffer discontinuities must
run before the stippled geometry pass, or the stipple pattern turns into artefacts.
"""

from __future__ import annotations

from dataclasses import dataclass

from .gbuffer import LINEAR_DEPTH, NORMAL_EXPONENT_ID
from .passes import FullscreenPass, Phase, RenderPass
from .targets_spec import TargetSpec

SSAO = "ssao"
SSAO_RAW = "ssao_raw"
SSAO_SPEC = TargetSpec(1, "f1", "ambient occlusion (1 = open)")


@dataclass(frozen=True)
class SSAOSettings:
    radius: float = 0.35
    strength: float = 1.0
    samples: int = 16


def ssao_passes(settings: SSAOSettings) -> list[RenderPass]:
    """Raw hemisphere SSAO, then a depth-aware blur into the ``ssao`` target."""
    uniforms = {"u_radius": settings.radius, "u_strength": settings.strength,
                "u_samples": settings.samples}
    return [
        FullscreenPass("screen.ssao", Phase.SCREEN, "screen/ssao.frag",
                       {"u_linear_depth": LINEAR_DEPTH, "u_normal_exponent_id": NORMAL_EXPONENT_ID},
                       (SSAO_RAW,), creates={SSAO_RAW: SSAO_SPEC}, uniforms=lambda frame: uniforms),
        FullscreenPass("screen.ssao_blur", Phase.SCREEN, "screen/ssao_blur.frag",
                       {"u_ssao_raw": SSAO_RAW, "u_linear_depth": LINEAR_DEPTH}, (SSAO,),
                       creates={SSAO: SSAO_SPEC}),
    ]
