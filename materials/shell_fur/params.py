"""shell_fur's parameters (Silva et al.: colour, curl, clump, wetness, strand dynamics) and the
limits on the simulation they set up (``state.py``)."""

from __future__ import annotations

import math
from typing import Any, Literal

from pydantic import Field, model_validator

from deferred.api import Albedo, BlinnPhongParams

from ..techniques.fur import FurParams

Vec3 = tuple[float, float, float]

# The state at time t is settle / time_step + t / time_step steps from scratch (a step's cost
# is in benchmarks/README.md): more is refused rather than left to run for hours.
MAX_SIMULATION_STEPS = 100_000
# Steps x strands a render may simulate: the work grows with both, so a fine mesh reaches the
# limit at an earlier time (benchmarks/README.md has what a strand step costs)
MAX_STRAND_STEPS = 200_000_000
STRAND_STEP_SECONDS = 100e-9  # a strand step, for the cost model (63-96 ns measured)
# Wetness-mask texels the droplets of a render may blend (each droplet blends the texels under
# it: radius^2 x droplets); benchmarks/README.md has what a texel costs
MAX_DROPLET_TEXELS = 400_000_000


class ShellFurParams(FurParams, BlinnPhongParams):
    # Eq. 6
    specular_intensity: float = Field(0.3, ge=0.0, le=1.0, description="K_s, Kajiya-Kay")
    specular_exponent: float = Field(40.0, ge=1.0, le=2048.0, description="p_phong")
    # colour (section 4, Fig. 3)
    color: Albedo = Field((0.55, 0.36, 0.20), description="fur colour (tints the texture), "
                                                           "each in [0, 1]")
    color_texture: str | None = Field(None, description="colour image over the mesh's UVs "
                                                        "(sRGB) instead of the pattern")
    color_pattern: Literal["none", "stripes", "spots"] = Field(
        "none", description="generated colour texture (Fig. 3a)")
    pattern_color: Albedo = Field((0.12, 0.07, 0.04), description="the pattern's second colour")
    color_scale: float = Field(1.0, gt=0.0, le=256.0,
                               description="repeats of the colour texture across the UVs")
    # curl (3.2.2, Eq. 4)
    curl_radius: float = Field(0.0, ge=0.0, le=4.0, description="K_alpha, object units")
    curl_frequency: float = Field(0.0, ge=0.0, le=1000.0,
                                  description="w, radians along the strand")
    curl_variation: float = Field(1.0, ge=0.0, le=1.0,
                                  description="curls start at phases spread over this much of "
                                              "a turn (seeded, a smooth field: slower for a "
                                              "larger curl_radius at t = 0; 0: all in one "
                                              "phase, the paper)")
    # clump (3.3, Eq. 5)
    clump_shape: float = Field(0.5, ge=0.0, le=1.0,
                               description="w: 0 leans straight to the centre, 1 bends in")
    clump_strength: float = Field(1.0, ge=0.0, le=8.0,
                                  description="1 gathers wet tips into half the radius")
    # wetness (3.1, Algorithm 1)
    droplets: int = Field(0, ge=0, le=10000,
                          description="random droplets fallen so far (seeded by `seed`)")
    droplet_radius: float = Field(0.08, gt=0.0, le=100.0, description="world units")
    droplet_wetness: float = Field(0.8, ge=0.0, le=1.0, description="rho of a droplet")
    wetness_mask: str | None = Field(None, description="wetness mask image (R, G centre, "
                                                       "B radius, A wetness) under the droplets")
    mask_size: int = Field(256, ge=16, le=4096, description="wetness mask texels per side")
    dry_rate: float = Field(0.0, ge=0.0, le=100.0, description="wetness lost per second")
    soak_time: float = Field(0.5, ge=0.0, le=60.0,
                             description="seconds the droplets of an event after t = 0 take to "
                                         "soak in: their wetness ramps up (0: at once)")
    # strand dynamics (3.2.1, Eq. 2, 3)
    stiffness: float = Field(2.0, gt=0.0, le=1e6, description="k, spring constant")
    mass: float = Field(0.01, gt=0.0, le=1e3, description="m, mass at the strand tip")
    damping: float = Field(0.05, ge=0.0, le=1e6, description="c, force per unit velocity")
    gravity: Vec3 = Field((0.0, -9.81, 0.0), description="world acceleration")
    wind: Vec3 = Field((0.0, 0.0, 0.0), description="world force on each strand tip")
    gust: float = Field(0.0, ge=0.0, le=8.0,
                        description="wind varies by +- this fraction in travelling gusts")
    gust_frequency: float = Field(0.5, ge=0.0, le=100.0,
                                  description="gusts per second (the slowest of the gust "
                                              "waves: they never repeat)")
    strand_variation: float = Field(0.35, ge=0.0, le=0.9,
                                    description="each strand's stiffness, mass and wind "
                                                "response vary by +- this fraction (seeded)")
    time_step: float = Field(1.0 / 240.0, gt=0.0, le=0.1, description="simulation step, s")
    settle: float = Field(2.0, ge=0.0, le=60.0,
                          description="seconds simulated before t = 0 (strands at rest)")
    fur_mapping: Literal["triplanar", "uv"] = Field(
        "triplanar", description="strands triplanar in world units (the fur technique: no "
                                 "seams, no poles) or over the mesh's UVs (the paper: a third "
                                 "of the lookups, the density following the unwrap)")
    fins: bool = Field(False, description="fins at silhouette edges (Lengyel 2001; not in the "
                                          "paper): straight, along the strand's chord, they "
                                          "suit uncurled fur")
    shading: Literal["kajiya_kay", "marschner"] = Field(
        "kajiya_kay", description="kajiya_kay: the paper's Eq. 6; marschner: the hair shading "
                                  "model (R, TT, TRT about the strand)")
    roughness: float = Field(0.2, gt=0.0, le=1.0,
                             description="marschner: longitudinal roughness beta, radians")
    debug: Literal["none", "samples", "shell_count", "single_shell", "wetness",
                   "opacity_shadow"] = Field(
        "none", description="debug view instead of the fur (shell_fur's debug_views)")

    @model_validator(mode="after")
    def _bounded_settle(self) -> ShellFurParams:
        if simulation_steps(self, 0.0) > MAX_SIMULATION_STEPS:
            raise ValueError(f"settle / time_step is {simulation_steps(self, 0.0):,} steps; "
                             f"the most is {MAX_SIMULATION_STEPS:,}")
        return self


def simulation_steps(params: ShellFurParams, time: float) -> int:
    """Steps simulated from scratch to reach ``time``: the settling, then t / time_step."""
    return int(round(params.settle / params.time_step)) + \
        int(math.floor(max(time, 0.0) / params.time_step + 1e-9))


def layers_uniform(shells: int) -> dict[str, Any]:
    """``u_layers``: the layer count N the shells' spacing (1 + n) / N is of."""
    return {"u_layers": float(max(shells, 1))}


# Parameters that are no uniforms: files, patterns, the simulation's (read in Python)
NOT_UNIFORMS = ("fur_mapping", "color_texture", "color_pattern", "pattern_color", "droplets",
                "droplet_radius", "droplet_wetness", "wetness_mask", "mask_size", "dry_rate",
                "soak_time", "stiffness", "mass", "damping", "gravity", "wind", "gust",
                "gust_frequency", "time_step", "settle", "heightfield", "shading",
                "strand_variation", "curl_variation")
