"""Screen-space ambient occlusion over the clean G-buffer (screen phase).

Revie 2.4.2: SSAO, edge detection and other techniques relying on G-buffer discontinuities must
run before the stippled geometry pass, or the stipple pattern turns into artefacts. The ambient
light multiplies its irradiance by the result (the ``ssao`` target).

Occlusion varies slowly over a surface, so by default it is computed on a grid of half the
frame's resolution per axis (``resolution``): each grid texel samples the G-buffer at one pixel
(``grid.glsl``), the blur runs on the grid, and a depth-aware upsample fills the full-resolution
``ssao`` target without carrying one surface's occlusion across a silhouette onto another.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

from pydantic import Field

from deferred.api import (
    AMBIENT_OCCLUSION,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    Effect,
    Frame,
    FullscreenPass,
    GBufferEffectParams,
    Phase,
    Pipeline,
    RenderPass,
    RenderWork,
    Scene,
    TargetSpec,
    Work,
    effects,
)

SSAO_RAW = "ssao_raw"
SSAO_REDUCED = "ssao_reduced"
SSAO_SPEC = TargetSpec(1, "f1", "ambient occlusion (1 = open)")
# on a reduced grid: occlusion and the linear depth of the texel's sample point
SSAO_GRID_SPEC = TargetSpec(2, "f4", "ambient occlusion on the reduced grid, and the depth of "
                            "each texel's sample point")
REDUCED_GRID = {"REDUCED_GRID": "1"}
# the upsample's time a pixel, as a share of the full-resolution passes' (benchmarks/README.md,
# "SSAO on a reduced grid")
UPSAMPLE_SHARE = 0.1
# a grid texel spans two pixels at half resolution: a 3x3 blur there covers about what the 5x5
# covers at full resolution (a 5x5 on the grid smears contact shadows: 5 dB lower PSNR)
GRID_BLUR = {**REDUCED_GRID, "BLUR_RADIUS": "1"}


class SSAOParams(GBufferEffectParams):
    radius: float = Field(0.35, gt=0.0, description="view-space sampling radius")
    strength: float = Field(1.0, ge=0.0, le=4.0, description="how dark full occlusion gets")
    samples: int = Field(16, ge=1, le=128, description="samples per pixel")
    resolution: float = Field(0.5, ge=0.25, le=1.0,
                              description="the grid occlusion is computed on, as a fraction of "
                                          "the frame's width and height (1 = every pixel; "
                                          "below 1 a depth-aware upsample fills the frame)")


@effects.register
class SSAO(Effect):
    name = "ssao"
    Params = SSAOParams
    pipelines = (Pipeline.DEFERRED,)  # and the forward pipeline with forward = true
    reads_gbuffer = True
    # where it runs and on what grid, not uniforms
    uniform_overrides = {"forward": None, "resolution": None}

    def passes(self, scene: Scene, pipeline: str) -> list[RenderPass]:
        """Raw hemisphere SSAO, then a depth-aware blur into the ``ssao`` target; on a reduced
        grid both run there and a depth-aware upsample makes the ``ssao`` target."""
        if self.params.resolution == 1.0:
            return [
                FullscreenPass("screen.ssao", Phase.SCREEN, "effects/ssao/ssao.frag",
                               {"u_linear_depth": LINEAR_DEPTH,
                                "u_normal_exponent_id": NORMAL_EXPONENT_ID},
                               (SSAO_RAW,), creates={SSAO_RAW: SSAO_SPEC},
                               uniforms=self.uniforms),
                FullscreenPass("screen.ssao_blur", Phase.SCREEN, "effects/ssao/ssao_blur.frag",
                               {"u_ssao_raw": SSAO_RAW, "u_linear_depth": LINEAR_DEPTH},
                               (AMBIENT_OCCLUSION,), creates={AMBIENT_OCCLUSION: SSAO_SPEC}),
            ]
        grid = replace(SSAO_GRID_SPEC, scale=self.params.resolution)
        return [
            FullscreenPass("screen.ssao", Phase.SCREEN, "effects/ssao/ssao.frag",
                           {"u_linear_depth": LINEAR_DEPTH,
                            "u_normal_exponent_id": NORMAL_EXPONENT_ID},
                           (SSAO_RAW,), defines=REDUCED_GRID, creates={SSAO_RAW: grid},
                           uniforms=self.grid_uniforms(grid)),
            FullscreenPass("screen.ssao_blur", Phase.SCREEN, "effects/ssao/ssao_blur.frag",
                           {"u_ssao_raw": SSAO_RAW}, (SSAO_REDUCED,), defines=GRID_BLUR,
                           creates={SSAO_REDUCED: grid}),
            FullscreenPass("screen.ssao_upsample", Phase.SCREEN, "effects/ssao/ssao_upsample.frag",
                           {"u_ssao_reduced": SSAO_REDUCED, "u_linear_depth": LINEAR_DEPTH},
                           (AMBIENT_OCCLUSION,), creates={AMBIENT_OCCLUSION: SSAO_SPEC}),
        ]

    def work(self, job: RenderWork) -> list[Work]:
        """The full-resolution passes' work a pixel, over the grid's share of the pixels and
        the upsample's."""
        resolution = self.params.resolution
        share = 1.0 if resolution == 1.0 else resolution * resolution + UPSAMPLE_SHARE
        return [replace(work, units=work.units * share,
                        what=f"{work.what} (resolution {resolution:g})")
                for work in super().work(job)]

    def grid_uniforms(self, grid: TargetSpec) -> Callable[[Frame], dict[str, Any]]:
        """The parameters' uniforms and the size of the reduced grid at the frame's size."""
        def uniforms(frame: Frame) -> dict[str, Any]:
            width, height = grid.size(frame.width, frame.height)
            return self.offer({**self.uniforms(frame), "u_grid_size": (float(width),
                                                                       float(height))})
        return uniforms
