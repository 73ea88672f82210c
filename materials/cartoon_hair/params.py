"""cartoon_hair's parameters (Costigan chapters 3-4: the strands, their dynamics, the tubes,
the strokes) and the limits on what they set up."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, field_validator, model_validator

from deferred.api import BlinnPhongParams

from ..techniques.xtoon import XToonParams

Vec3 = tuple[float, float, float]
MAX_STRANDS = 20000
STRAND_IDS = 32768  # ids a hair object's strands take (more than MAX_STRANDS)
MAX_HAIR_OBJECTS = (1 << 24) // STRAND_IDS  # ids stay whole numbers in the R32F datum
# The hair at time t is t / time_step steps from 0 (benchmarks/README.md has what a step
# costs): more is refused rather than left to run for hours
MAX_HAIR_STEPS = 20_000
MAX_HAIR_STRAND_STEPS = 50_000_000
MAX_COLLISION_SPHERES = 256  # each is tested against every particle at every step

# The cost model's seconds (benchmarks/cost_model.py calibrate; benchmarks/README.md): a
# particle of the simulated chains a step, and a collision sphere tested against one; a tube
# vertex made once (numpy's tubes, the vertex format, the buffers) and built again each frame
# (compute shaders); a tube triangle drawn (each pass over the tubes: G-buffer or lit pass,
# hatching) and its silhouette strokes (a geometry shader over triangles with adjacency)
PARTICLE_STEP_SECONDS = 33e-9
SPHERE_TEST_SECONDS = 3e-9
TUBE_VERTEX_MADE_SECONDS = 1.5e-6
TUBE_VERTEX_FRAME_SECONDS = 40e-9
TUBE_TRIANGLE_SECONDS = 200e-9
SILHOUETTE_TRIANGLE_SECONDS = 390e-9
# Bytes a tube vertex takes, held and at the peak of making the tubes (numpy's float64 arrays,
# the vertex format, its GPU buffers), and a tube triangle's adjacency for the strokes
TUBE_BYTES_PER_VERTEX = 240
SILHOUETTE_BYTES_PER_TRIANGLE = 50


class CartoonHairParams(BlinnPhongParams, XToonParams):
    color: Vec3 = Field((0.55, 0.35, 0.85), description="hair albedo, linear RGB")
    skin_color: Vec3 = Field((0.95, 0.78, 0.66), description="the head's albedo, linear RGB")
    specular_intensity: float = Field(0.0, ge=0.0, le=1.0,
                                      description="the hair's hard specular band, across the "
                                                  "strands where they run perpendicular to the "
                                                  "half vector (Kajiya-Kay's sin(T, H))")
    skin_specular_intensity: float = Field(0.0, ge=0.0, le=1.0,
                                           description="the head's hard specular band (N.H)")
    skin_specular_exponent: float = Field(40.0, ge=1.0, le=2048.0,
                                          description="the head's band: (N.H)^exponent")
    # strands in (4.1-4.2.1)
    strands_file: str | None = Field(None, description="guide strands: JSON {\"strands\": "
                                                       "[[[x, y, z], ...], ...]} or OBJ l lines")
    strands: int = Field(200, ge=1, le=MAX_STRANDS, description="strands grown on the scalp")
    length: float = Field(0.18, gt=0.0, le=10.0, description="strand length, object units")
    segments: int = Field(7, ge=1, le=32, description="simulated segments a strand")
    style: Literal["combed", "spiky"] = Field("spiky", description="how grown strands lie")
    parting: float = Field(0.0, ge=-1.0, le=1.0, description="combed: the parting's x")
    seed: int = Field(1, ge=0, le=2**31 - 1, description="roots and styles")
    clump_size: int = Field(6, ge=1, le=1000,
                            description="strands a clump (k-means over the strands' shapes); "
                                        "the edges effect outlines clumps, 1: every strand")
    # dynamics (4.2.2-4.2.4)
    edge_stiffness: float = Field(1.0, ge=0.0, le=1.0, description="edge springs")
    bend_stiffness: float = Field(0.8, ge=0.0, le=1.0, description="bend springs")
    torsion_stiffness: float = Field(0.8, ge=0.0, le=1.0, description="torsion springs")
    anchor_stiffness: float = Field(0.0, ge=0.0, le=1.0,
                                    description="pull toward the keyframed pose")
    anchor_curve: Vec3 = Field((0.0, 0.0, 1.0),
                               description="anchor stiffness along the strand: a x^2 + b x + c")
    keyframes: tuple[str, ...] = Field((), description="strand files of the anchors' poses")
    key_times: tuple[float, ...] = Field((), description="seconds of each keyframe")
    gravity: Vec3 = Field((0.0, -9.81, 0.0), description="world acceleration")
    wind: Vec3 = Field((0.0, 0.0, 0.0), description="the air's velocity, world units/s")
    drag: float = Field(2.0, ge=0.0, le=1000.0,
                        description="1/s: how fast the hair takes the air's velocity (damping)")
    time_step: float = Field(1.0 / 60.0, gt=0.0, le=0.1, description="simulation step, s")
    settle: float = Field(0.0, ge=0.0, le=60.0,
                          description="seconds simulated before t = 0 (the hair at rest)")
    collision_spheres: tuple[tuple[float, float, float, float], ...] | None = Field(
        None, max_length=MAX_COLLISION_SPHERES,
        description="object-space (x, y, z, radius); default: builtin:head's own")
    # tubes (4.3.1-4.3.2)
    hair_samples: int = Field(15, ge=2, le=64,
                              description="spline samples a strand (4.3.1: more than the "
                                          "segments + 1 simulated points, so the spline "
                                          "rounds the bends between them)")
    sides: int = Field(6, ge=3, le=16, description="sides of a tube")
    radius: float = Field(0.012, gt=0.0, le=1.0, description="tube radius at the root")
    taper: Vec3 = Field((0.0, -1.0, 1.0), description="radius along the strand: a x^2 + b x + c")
    # silhouette strokes (4.3.7, object space)
    silhouettes: bool = Field(False, description="strokes along the tubes' silhouette edges")
    stroke_width: float = Field(3.0, gt=0.0, le=64.0,
                                description="silhouette strokes, pixels (at most the tube's "
                                            "radius on screen)")
    stroke_world_width: float | None = Field(
        None, gt=0.0, le=10.0, description="silhouette strokes in object units at their depth "
                                           "(thinning with distance) instead of stroke_width")
    stroke_color: Vec3 = Field((0.08, 0.05, 0.12), description="silhouette strokes, linear RGB")
    stroke_fade: Vec3 = Field((-1.0, 2.0, 0.0),
                              description="stroke alpha along the strand (0 root, 1 tip): "
                                          "a x^2 + b x + c, clamped to [0, 1]")

    # hatching (4.3.8)
    hatching: Literal["none", "surface", "screen"] = Field(
        "none", description="tonal-art-map strokes darkening the hair by its lit tone: along "
                            "the tubes (Praun, Fig. 4.20b) or over the screen (Lake, 4.20a)")
    hatching_strength: float = Field(0.8, ge=0.0, le=1.0, description="ink at full tone")
    hatching_scale: float = Field(3.0, gt=0.0, le=64.0,
                                  description="surface hatching: the map's repeats along a "
                                              "strand (screen hatching: a map texel a pixel)")
    hatching_width: float = Field(1.5, ge=0.75, le=6.0,
                                  description="hatching strokes' width in pixels (the tonal "
                                              "art map's, read at about a texel a pixel)")

    @field_validator("collision_spheres")
    @classmethod
    def _sphere_radii(cls, spheres: tuple[tuple[float, float, float, float], ...] | None
                      ) -> tuple[tuple[float, float, float, float], ...] | None:
        for index, sphere in enumerate(spheres or ()):
            if sphere[3] < 0.0:
                raise ValueError(f"sphere {index} has radius {sphere[3]:g}; a radius is >= 0")
        return spheres

    @field_validator("taper")
    @classmethod
    def _some_radius(cls, taper: Vec3) -> Vec3:
        if quadratic_peak(taper) <= 0.0:
            raise ValueError("gives the tube no radius anywhere along the strand (a x^2 + b x + "
                             "c is <= 0 for every x in [0, 1], root to tip; the default, "
                             "(0, -1, 1), tapers from the root's radius to 0)")
        return taper

    @model_validator(mode="after")
    def _keys(self) -> CartoonHairParams:
        if len(self.key_times) != len(self.keyframes):
            raise ValueError("key_times needs a time for each keyframe")
        if any(b <= a for a, b in zip(self.key_times, self.key_times[1:], strict=False)):
            raise ValueError("key_times must increase")
        if settle_steps(self) > MAX_HAIR_STEPS:
            raise ValueError(f"settle / time_step is {settle_steps(self):,} steps; the most is "
                             f"{MAX_HAIR_STEPS:,}")
        return self


def settle_steps(params: CartoonHairParams) -> int:
    """Steps simulated before t = 0."""
    return int(round(params.settle / params.time_step))


def tube_counts(strands: int, params: CartoonHairParams) -> tuple[int, int]:
    """The tubes' vertices and triangles for ``strands`` strands: ``hair_samples`` rings of
    ``sides`` and two cap centres a strand; the rings' quads and the caps' fans."""
    rings = params.hair_samples * params.sides
    return strands * (rings + 2), strands * 2 * rings


def quadratic_peak(coefficients: Vec3) -> float:
    """The largest value of ``a x^2 + b x + c`` for ``x`` in [0, 1]."""
    a, b, c = coefficients
    candidates = [0.0, 1.0]
    if a < 0.0 and 0.0 < -b / (2.0 * a) < 1.0:  # a maximum inside
        candidates.append(-b / (2.0 * a))
    return max(a * x * x + b * x + c for x in candidates)
