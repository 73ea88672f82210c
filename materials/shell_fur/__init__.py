"""Curling and clumping shell fur (P. Silva, Y. Bando, B.-Y. Chen, T. Nishita, "Curling and
Clumping Fur Represented by Texture Layers").

The fur is N texture layers over the mesh (section 4; the shared fur technique's volume, level
of detail and fins, ``techniques/fur.py``), layer n at normalized length h = (1 + n)/N over an
opaque skin, each displaced in the vertex shader by the strand's bend and curl (Eq. 1, 4) and
clumped in the fragment shader (Eq. 5, Algorithm 2); lit with Kajiya-Kay and the shadow factor
gamma (Eq. 6). Per object and over time (:class:`ShellFurState`): the wetness mask (3.1,
Algorithm 1; ``techniques/wetness.py``), built from random droplets or an image and drying at
``dry_rate``, and one mass-spring strand per triangle (3.2.1, Eq. 2, 3;
``techniques/strands.py``) under gravity and gusting wind.

Pipelines:
- deferred: the base mesh goes to the G-buffer with the ``kajiya_kay`` shading model and the
  strand's chord as its ``strand_tangent``; the lights shade it; the layers are material-phase
  passes taking their light from the light accumulation at the root under them (as Revie's
  shells do), so their cost does not grow with the number of lights;
- forward: every layer fragment is lit by every light with its own strand tangent.
"""

from __future__ import annotations

import math
import weakref
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import moderngl
import numpy as np
from pydantic import Field, model_validator

from deferred.api import (
    COMPOSITE,
    Albedo,
    BlinnPhongParams,
    ForwardLitPass,
    GBufferPass,
    InputError,
    Phase,
    RenderPass,
    check_image,
    image_texture_bytes,
    materials,
    read_image,
)

from ..techniques.fins import FinPass
from ..techniques.fur import (
    FUR_DEBUG_VIEWS,
    FUR_UNIFORM_OVERRIDES,
    FurMaterial,
    FurParams,
    debug_defines,
    tiles_per_unit,
)
from ..techniques.fur_light import FurLightReader, fur_light_pass, fur_light_targets
from ..techniques.shells import ShellPass
from ..techniques.strands import (
    StrandForces,
    StrandSimulation,
    VertexAverage,
    curl_frames,
    curl_phases,
    gust_wind,
    triangle_strands,
)
from ..techniques.wetness import (
    UVSeams,
    dry_mask,
    dry_out,
    footprint_texels,
    load_wetness_mask,
    mean_uv_scale,
    random_droplets,
    read_mask_image,
    uv_wrap,
)

if TYPE_CHECKING:
    from deferred.api import Frame, SceneObject

Vec3 = tuple[float, float, float]
FUR_VERTEX = "materials/shell_fur/fur.vert"
SHELL_FRAGMENT = "materials/shell_fur/shell.frag"
FORWARD_SHELL_FRAGMENT = "materials/shell_fur/forward_shell.frag"
TIPS_WIDTH = 1024  # texels per row of the per-vertex strand texture
COLOR_MAP_SIZE = 256
GUST_WAVELENGTH = 1.0  # world units between gust fronts along the wind
# The state at time t is settle / time_step + t / time_step steps from scratch (a step's cost
# is in benchmarks/README.md): more is refused rather than left to run for hours.
MAX_SIMULATION_STEPS = 100_000
# Steps x strands a render may simulate: the work grows with both, so a fine mesh reaches the
# limit at an earlier time (benchmarks/README.md has what a strand step costs)
MAX_STRAND_STEPS = 200_000_000
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


def _params_at(obj: SceneObject, time: float) -> ShellFurParams:
    params_at = getattr(obj, "params_at", None)
    return params_at(time) if params_at is not None else obj.material.params


def droplet_texels(obj: SceneObject, time: float) -> tuple[int, str]:
    """The wetness-mask texels blended by the droplets fallen on ``obj`` by ``time`` (each count
    of droplets on its timeline falls with the radius of its own time, as
    :class:`ShellFurState` rains them), and where the droplets that pass
    :data:`MAX_DROPLET_TEXELS` were asked for (the object's params or an event's)."""
    first = _params_at(obj, 0.0)
    wrap, seams, fallen, texels = None, None, 0, 0
    named = getattr(obj, "where", None)
    where = f"{named}.params" if named else f"{obj.label}: params"
    blame = where
    events = [e for e in getattr(obj, "events", ()) if e.time <= time]
    for at in [0.0, *(e.time for e in events if e.time > 0.0)]:
        params = _params_at(obj, at)
        if params.droplets > fallen:
            wrap = uv_wrap(obj.mesh) if wrap is None else wrap
            seams = UVSeams(obj.mesh) if seams is None else seams
            texels += footprint_texels(
                random_droplets(obj.mesh, obj.model, params.droplets - fallen,
                                params.droplet_radius, params.droplet_wetness, params.seed,
                                start=fallen), first.mask_size, wrap, seams)
            fallen = params.droplets
            if texels > MAX_DROPLET_TEXELS and blame is where:
                latest = [e for e in events if e.time <= at and "droplets" in e.params]
                blame = f"{latest[-1].where}.params" if latest and latest[-1].where else where
    return texels, f"{blame}.droplets"


def _layers_uniform(shells: int) -> dict[str, Any]:
    return {"u_layers": float(max(shells, 1))}


NOT_UNIFORMS = ("fur_mapping", "color_texture", "color_pattern", "pattern_color", "droplets",
                "droplet_radius", "droplet_wetness", "wetness_mask", "mask_size", "dry_rate",
                "soak_time", "stiffness", "mass", "damping", "gravity", "wind", "gust",
                "gust_frequency", "time_step", "settle", "heightfield", "shading",
                "strand_variation", "curl_variation")


# -- colour texture --------------------------------------------------------------------------

def color_pattern(name: str, size: int = COLOR_MAP_SIZE, seed: int = 1) -> np.ndarray:
    """(size, size) weight of the pattern colour over the UV square, tileable: ``stripes``
    (wavy bands across u, a tabby's), ``spots`` (round blotches), ``none`` (zeros)."""
    t = (np.arange(size) + 0.5) / size
    v, u = np.meshgrid(t, t, indexing="ij")
    if name == "none":
        return np.zeros((size, size))
    if name == "stripes":
        wave = u * 6.0 + 0.35 * np.sin(2.0 * np.pi * v * 2.0) + 0.1 * np.sin(2.0 * np.pi * v * 7.0)
        s = 0.5 + 0.5 * np.cos(2.0 * np.pi * wave)
        return np.clip((s - 0.55) / 0.15, 0.0, 1.0)
    if name == "spots":
        rng = np.random.default_rng(seed)
        centres = rng.uniform(0.0, 1.0, (40, 2))
        radii = rng.uniform(0.03, 0.06, 40)
        weight = np.zeros((size, size))
        for (cu, cv), r in zip(centres, radii, strict=True):
            du = (u - cu + 0.5) % 1.0 - 0.5  # tileable distance
            dv = (v - cv + 0.5) % 1.0 - 0.5
            weight = np.maximum(weight, np.clip((r - np.sqrt(du * du + dv * dv)) / 0.008,
                                                0.0, 1.0))
        return weight
    raise ValueError(f"unknown colour pattern '{name}'")


def pattern_texture(ctx: moderngl.Context, params: ShellFurParams) -> moderngl.Texture:
    """The generated colour texture: white, blended to pattern_color / color where the pattern
    is (the tint ``color`` multiplies the whole)."""
    weight = color_pattern(params.color_pattern, seed=params.seed)[..., None]
    ratio = np.asarray(params.pattern_color) / np.maximum(np.asarray(params.color), 1e-3)
    rgb = (1.0 - weight) + weight * ratio[None, None, :]
    rgba = np.concatenate([rgb, np.ones(rgb.shape[:2] + (1,))], -1).astype(np.float16)
    texture = ctx.texture((rgb.shape[1], rgb.shape[0]), 4, rgba.tobytes(), dtype="f2")
    texture.build_mipmaps()
    texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    return texture


# -- per-object state over time ----------------------------------------------------------------

def _float_texture(ctx: moderngl.Context, width: int, height: int) -> moderngl.Texture:
    texture = ctx.texture((width, height), 4, dtype="f4")
    texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
    return texture


class ShellFurState:
    """An object's wetness mask and strands over time, with their textures (``u_wetness_mask``,
    ``u_strand_tips``): one per object and renderer (:func:`object_state`), brought to each
    frame's time by the object's passes' ``prepare``.

    Time is a count of fixed steps from t = 0: the state at time t is that after step
    ``floor(t / time_step)`` whatever frames came before, so the same time gives the same frame
    (asked for an earlier time, the state starts over). Step n runs with the parameters at
    ``n * time_step`` (``SceneObject.params_at``); droplets fall at the first step at or after
    their event; drying removes ``dry_rate * time_step`` per step. Before t = 0 the strands
    settle for ``settle`` seconds with the parameters at 0. Parameters the material reads once
    (``timeline_fixed``) are the ones at t = 0: a timeline may not change them."""

    def __init__(self, ctx: moderngl.Context, obj: SceneObject):
        self.obj = obj  # its material is read from it each time (a timeline may give it a copy)
        params = self.params_at(0.0)
        self.dt = params.time_step
        self.fur_length = params.fur_length
        # the strands live in the world, so they are placed by the object's transform at each
        # step (model_at: an object on a track carries them along, and they trail it)
        self.model = np.array(obj.model_at(0.0))
        self.linear_inverse = np.linalg.inv(self.model[:3, :3])
        self.strands = StrandSimulation(*triangle_strands(obj.mesh, self.model, self.fur_length))
        self.strands.vary(params.strand_variation, params.seed)
        self.average = VertexAverage(obj.mesh)
        self.size = params.mask_size
        self.wrap = uv_wrap(obj.mesh)
        self.seams = UVSeams(obj.mesh)  # droplets near a chart's seam wet the chart across it
        self.world_per_uv = mean_uv_scale(obj.mesh, self.model)
        self.mask_texture = _float_texture(ctx, self.size, self.size)
        self.mask_texture.repeat_x = self.mask_texture.repeat_y = True
        # three texels per vertex: tip deflection, curl u, curl v (fur.vert)
        vertices = obj.mesh.vertex_count
        self.strand_data = np.zeros((max(1, math.ceil(3 * vertices / TIPS_WIDTH)) * TIPS_WIDTH,
                                     4), np.float32)
        curl_u, curl_v = curl_frames(obj.mesh, self.average.welded)
        phase = curl_phases(obj.mesh, params.curl_variation, params.seed,
                            params.curl_radius)[:, None]
        curl_u, curl_v = (np.cos(phase) * curl_u + np.sin(phase) * curl_v,
                          np.cos(phase) * curl_v - np.sin(phase) * curl_u)
        self.strand_data[1:3 * vertices:3, :3] = curl_u
        self.strand_data[2:3 * vertices:3, :3] = curl_v
        self.tips_texture = _float_texture(ctx, TIPS_WIDTH, len(self.strand_data) // TIPS_WIDTH)
        self.step: int | None = None  # steps taken since t = 0
        self.mask = dry_mask(self.size)  # Algorithm 1's, drying included
        self.shown = self.mask.copy()  # what the shaders see: the mask as it soaks in (_soak)
        self.fallen = 0
        self._uploaded: int | None = None

    def params_at(self, time: float) -> ShellFurParams:
        return _params_at(self.obj, time)

    def advance(self, time: float) -> None:
        """Bring the state to ``time`` (seconds) and upload it if it changed."""
        target = int(math.floor(time / self.dt + 1e-9))
        if self.step is None or target < self.step:
            self._start()
        events = [t for t in getattr(self.obj, "event_times", ()) if t > 0.0]
        while self.step < target:
            now = self.step * self.dt
            params = self.params_at(now)
            self._rain(params)
            # run to the first step at or after the next event (its parameters differ)
            later = [math.ceil(t / self.dt - 1e-9) for t in events if t > now + 1e-12]
            end = min([target, *[n for n in later if n > self.step]])
            for n in range(self.step, end):
                if self.obj.tracks:
                    self._place(self.obj.model_at(n * self.dt))
                self.strands.step(self.dt, self._forces(params, n * self.dt))
            dry_out(self.mask, params.dry_rate * self.dt * (end - self.step))
            self._soak(params, end - self.step)
            self.step = end
        if self.obj.tracks:
            self._place(self.obj.model_at(self.step * self.dt))
        self._rain(self.params_at(self.step * self.dt))
        if self._uploaded != self.step:
            self._upload()

    def _place(self, model: np.ndarray) -> None:
        """Move the strands' roots to where ``model`` puts the mesh (nothing if it is where
        they are)."""
        if np.array_equal(model, self.model):
            return
        self.model = np.array(model)
        self.linear_inverse = np.linalg.inv(self.model[:3, :3])
        self.world_per_uv = mean_uv_scale(self.obj.mesh, self.model)
        self.strands.move(*triangle_strands(self.obj.mesh, self.model, self.fur_length))
        self._uploaded = None

    def _start(self) -> None:
        params = self.params_at(0.0)
        path = self.obj.material.wetness_mask_path(params)
        self.mask = load_wetness_mask(path, self.size) if path is not None \
            else dry_mask(self.size)
        self.fallen = 0
        self._place(np.asarray(self.obj.model_at(0.0)))
        self._rain(params)  # the droplets fallen by t = 0 have soaked in
        self.shown = self.mask.copy()
        self.strands.reset()
        steps = int(round(params.settle / self.dt))
        for k in range(steps):
            self.strands.step(self.dt, self._forces(params, (k - steps) * self.dt))
        self.step = 0
        self._uploaded = None

    def _soak(self, params: ShellFurParams, steps: int) -> None:
        """The shown mask after ``steps`` steps: its wetness rises toward the mask's (Algorithm
        1's, drying included) by ``dt / soak_time`` a step, never above it, so an event's
        droplets soak in over ``soak_time`` instead of in one frame; drying shows at once. The
        ramp is linear, so steps taken at once or one by one give the same mask."""
        rise = math.inf if params.soak_time <= 0.0 else steps * self.dt / params.soak_time
        self.shown[..., :3] = self.mask[..., :3]
        self.shown[..., 3] = np.minimum(self.mask[..., 3], self.shown[..., 3] + rise)

    def _rain(self, params: ShellFurParams) -> None:
        """Blend the droplets that fell since last time (the ``droplets`` count grew)."""
        if params.droplets > self.fallen:
            for droplet in random_droplets(self.obj.mesh, self.model,
                                           params.droplets - self.fallen, params.droplet_radius,
                                           params.droplet_wetness, params.seed,
                                           start=self.fallen):
                self.seams.blend(self.mask, droplet, self.wrap)
            self.fallen = params.droplets
            self._uploaded = None

    def _forces(self, params: ShellFurParams, time: float) -> StrandForces:
        wind = gust_wind(np.asarray(params.wind, np.float64), self.strands.roots,
                         self.strands.normals, params.gust, params.gust_frequency, time,
                         GUST_WAVELENGTH)
        return StrandForces(params.stiffness, params.mass, params.damping,
                            np.asarray(params.gravity, np.float64), wind)

    def vertex_deflections(self) -> np.ndarray:
        """(V, 3) each vertex's tip deflection ``p - p_0`` in object space."""
        return self.average(self.strands.deflections()) @ self.linear_inverse.T

    def _upload(self) -> None:
        self.mask_texture.write(np.ascontiguousarray(self.shown, np.float32).tobytes())
        vertices = self.obj.mesh.vertex_count
        self.strand_data[0:3 * vertices:3, :3] = self.vertex_deflections()
        self.tips_texture.write(self.strand_data.tobytes())
        self._uploaded = self.step

    def release(self) -> None:
        self.mask_texture.release()
        self.tips_texture.release()


# -- passes -------------------------------------------------------------------------------------

def object_state(frame: Frame, obj: SceneObject) -> ShellFurState:
    """``obj``'s state in the frame's renderer, made the first time it is asked for; keyed by
    the object itself, so objects sharing a material instance each have their own, and
    released with the renderer's resources."""
    state = frame.resources.cached(("shell_fur_state", obj.node),
                                   lambda ctx: ShellFurState(ctx, obj))
    state.obj = obj  # the object as this frame has it (the tracks moving it now)
    return state


class ObjectStateInputs:
    """Passes of a shell_fur object: ``prepare`` brings the object's state to the frame's time
    (the renderer prepares every pass before any draws, so all of the object's passes see the
    same state); the pass binds the state's textures, and those that clump (``clumps``) learn
    whether the mesh's UVs wrap."""

    name: str
    clumps = False
    # the frame prepared for (weakly: a pass keeps no frame alive) and the state
    _prepared: tuple[weakref.ref, ShellFurState] | None = None

    def prepare(self, frame: Frame) -> None:
        state = object_state(frame, self.object(frame))
        state.advance(frame.time)  # a no-op for the object's other passes: already there
        self._prepared = (weakref.ref(frame), state)

    def state(self, frame: Frame) -> ShellFurState:
        """The object's state as ``prepare`` left it for ``frame``."""
        if self._prepared is None or self._prepared[0]() is not frame:
            raise RuntimeError(f"{self.name}: drawn in a frame it was not prepared for (the "
                               "shell_fur state steps in prepare)")
        return self._prepared[1]

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        state = self.state(frame)
        return {**super().textures(frame), "u_wetness_mask": state.mask_texture,
                "u_strand_tips": state.tips_texture}

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        uniforms = super().uniforms(frame)
        if self.clumps:
            state = self.state(frame)
            uniforms["u_mask_wrap"] = tuple(float(w) for w in state.wrap)
            # the world density over the UVs: tiles per world unit x world units per UV unit
            uniforms["u_fur_uv_tiles"] = tiles_per_unit(self.object(frame).params) * \
                state.world_per_uv
        return uniforms


def layer_layout(count: float, shell_range: tuple[float, float] = (0.0, 1.0),
                 debug: str = "none") -> list[tuple[float, float] | None]:
    """(h, fade) of each layer drawn for a continuous layer count N: the skin (h = 0, index 0),
    then Silva's layers h = (1 + n)/N, n = 0 .. ceil(N) - 1, the last kept at h <= 1 and faded
    by N's fraction, so the level of detail never pops. None: not drawn (outside shell_range, or
    hidden by a debug view)."""
    drawn = math.ceil(count - 1e-9)
    layers = [(0.0, 1.0)] + [(min((1 + n) / count, 1.0),
                              1.0 if n < drawn - 1 else count - (drawn - 1))
                             for n in range(drawn)]
    low, high = shell_range
    if debug in ("shell_count", "wetness"):
        return [layers[0]] + [None] * drawn
    in_range = [k for k, (h, _) in enumerate(layers) if low <= h <= high]
    if debug == "single_shell":
        shown = {in_range[len(in_range) // 2]} if in_range else set()
    else:
        shown = set(in_range)
    return [layer if k in shown else None for k, layer in enumerate(layers)]


class ShellFurLayerPass(FurLightReader, ObjectStateInputs, ShellPass):
    """The skin and the N layers (Silva's spacing, :func:`layer_layout`)."""

    vertex = FUR_VERTEX
    clumps = True

    def layout(self, count: float, params: ShellFurParams) -> list[tuple[float, float] | None]:
        # no layers, not even the skin, without shells
        return layer_layout(count, params.shell_range, params.debug) if count > 0 else []

    def slabs(self, count: float) -> float:
        return count  # N layers over the skin: each stands for 1/N of the fur


class ShellFurFinPass(FurLightReader, ObjectStateInputs, FinPass):
    vertex = FUR_VERTEX
    clumps = True

    def draws(self, frame: Frame) -> int:
        return 0 if self.object(frame).params.debug == "wetness" else super().draws(frame)

    def defines(self, frame: Frame) -> dict[str, str]:
        return {**super().defines(frame), "FIN_STRAND_TANGENT": "1", "STRAND_CHORD": "1"}


class ShellFurBasePass(ObjectStateInputs, GBufferPass):
    vertex = FUR_VERTEX


class ShellFurForwardBasePass(ObjectStateInputs, ForwardLitPass):
    vertex = FUR_VERTEX


CHORD = {"STRAND_CHORD": "1"}


@materials.register
class ShellFurMaterial(FurMaterial):
    name = "shell_fur"
    Params = ShellFurParams
    surface_shader = "materials/shell_fur/surface.glsl"
    inputs_from_params = True  # uniforms from the params, textures from frame.resources
    shading_model = "kajiya_kay"
    uniform_overrides = {**FUR_UNIFORM_OVERRIDES, **{key: None for key in NOT_UNIFORMS},
                         "shells": _layers_uniform}
    # the simulation's set-up (ShellFurState), and the passes built once
    timeline_growing = ("droplets",)  # fallen droplets stay (Algorithm 1 blends, never removes)
    timeline_fixed = ("fur_length", "mask_size", "wetness_mask", "time_step", "settle", "seed",
                      "fins", "shading", "strand_variation", "curl_variation")
    debug_views = {
        **{name: view for name, view in FUR_DEBUG_VIEWS.items() if name not in ("comb",
                                                                                 "samples")},
        "samples": ("the light sample each layer and fin fragment used: green its root's "
                    "pixel (or a neighbour), yellow its own pixel, red none; white in the "
                    "forward pipeline, which lights every fragment", {"debug": "samples"}),
        "wetness": ("the wetness mask on the skin: a colour per clump, as bright as it is "
                    "wet; black dry (Silva et al. Fig. 11's inset)", {"debug": "wetness"}),
    }

    fur_vertex = FUR_VERTEX
    deferred_opacity = True  # its layers correct their root's light light by light (shell.frag)

    def shadow_textures(self, frame: Frame, obj: SceneObject) -> dict[str, moderngl.Texture]:
        # the state the object's passes brought to the frame's time in their prepare
        state = object_state(frame, obj)
        return {"u_wetness_mask": state.mask_texture, "u_strand_tips": state.tips_texture}

    def __init__(self, params: ShellFurParams | None = None, base_dir: Path | None = None):
        super().__init__(params, base_dir)
        self.shading_model = self.params.shading

    def check_time(self, time: float, where: str) -> None:
        steps = simulation_steps(self.params, time)
        if steps > MAX_SIMULATION_STEPS:
            raise InputError(f"t = {time:g} s needs {steps:,} simulation steps of "
                             f"{self.params.time_step:g} s (with settle); the most is "
                             f"{MAX_SIMULATION_STEPS:,}: render an earlier time or raise "
                             "time_step", where)

    def check_time_for(self, obj: SceneObject, time: float, where: str) -> None:
        """The steps, and the steps times the object's strands (one a triangle): the work
        grows with both, so a fine mesh reaches its limit sooner."""
        self.check_time(time, where)
        steps, strands = simulation_steps(self.params, time), len(obj.mesh.indices)
        if steps * strands > MAX_STRAND_STEPS:
            raise InputError(f"t = {time:g} s needs {steps:,} simulation steps of "
                             f"{strands:,} strands ({obj.label}: one a triangle), "
                             f"{steps * strands:,} strand steps; the most is "
                             f"{MAX_STRAND_STEPS:,}: render an earlier time, raise time_step "
                             "or give the object a coarser mesh", where)
        texels, blame = droplet_texels(obj, time)
        if texels > MAX_DROPLET_TEXELS:
            params = _params_at(obj, time)
            raise InputError(f"{params.droplets:,} droplets by t = {time:g} s blend "
                             f"{texels:,} wetness-mask texels (each the texels under it: "
                             f"droplet_radius and mask_size set how many); the most is "
                             f"{MAX_DROPLET_TEXELS:,}: fewer or smaller droplets, or a smaller "
                             "mask_size", blame)

    def check_files(self, where: str | None) -> None:
        super().check_files(where)
        for key in ("color_texture", "wetness_mask"):
            value = getattr(self.params, key)
            if value is None:
                continue
            name = f"{where}.{key}" if where else key
            path = self.file_parameter(value, key.replace("_", " ") + " image", name)
            try:
                read_mask_image(path) if key == "wetness_mask" else read_image(path)
            except InputError as exc:
                raise InputError(exc.message, name) from None

    def held_memory(self, obj: SceneObject) -> dict[str, int]:
        """The fur volume, the colour texture, and the wetness mask: its array and its float
        RGBA texture, ``mask_size`` squared each."""
        held = super().held_memory(obj)
        if self.params.color_texture is not None:
            path = self.resolve_path(self.params.color_texture)
            width, height, _ = check_image(path)
            held[f"texture {path}"] = image_texture_bytes(width, height)
        held[f"wetness mask of {obj.label}"] = 2 * self.params.mask_size ** 2 * 16
        return held

    def wetness_mask_path(self, params: ShellFurParams | None = None) -> Path | None:
        params = params or self.params
        return None if params.wetness_mask is None else self.resolve_path(params.wetness_mask)

    def defines(self, obj: SceneObject) -> dict[str, str]:
        # The layers reject light samples the G-buffer shows occluded (Revie's Figure 2.8 fix)
        # by the depths of the fur_light gather (materials/techniques/fur_light.glsl), always.
        defines = {**super().defines(obj), **debug_defines(self.params)}
        if self.params.fur_mapping == "uv":
            defines["FUR_UV_MAPPING"] = "1"
        if self.has_color_map():
            defines["FUR_COLOR_MAP"] = "1"
        if self.params.shading == "marschner":
            defines["FUR_MARSCHNER"] = "1"
        return defines

    def has_color_map(self) -> bool:
        """Whether the colour varies over the UVs (a texture or a pattern), else the tint."""
        return self.params.color_texture is not None or self.params.color_pattern != "none"

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        params = self.params
        textures = super().textures(frame)
        if params.color_texture is not None:
            textures["u_color_map"] = frame.resources.image_texture(
                self.resolve_path(params.color_texture))
        elif self.has_color_map():
            textures["u_color_map"] = frame.resources.texture(
                ("shell_fur_pattern", params.color_pattern, params.seed, params.color,
                 params.pattern_color), lambda ctx: pattern_texture(ctx, params))
        return textures

    # -- passes ------------------------------------------------------------------------------
    @classmethod
    def fur_light(cls) -> str:
        """The fur light gather of this material's objects (``techniques/fur_light.py``): one
        per material class, as its G-buffer id is."""
        return f"{cls.name}_light"

    @classmethod
    def scene_passes(cls, objects: list[SceneObject], phase: Phase) -> list[RenderPass]:
        """The fur's light per pixel, gathered once for every shell_fur object's layers and
        fins (deferred only: forward layers light themselves)."""
        if phase != Phase.MATERIAL or not any(obj.material.params.shells > 0 for obj in objects):
            return []
        return [fur_light_pass(f"material.{cls.fur_light()}", cls.fur_light(),
                               objects[0].material.surface_id(), cls.name)]

    def geometry_passes(self, obj: SceneObject) -> list[RenderPass]:
        return [ShellFurBasePass(f"{obj.label}.gbuffer", Phase.GEOMETRY, obj,
                                 constants=self.vertex_constants(obj, 0.0), extra_defines=CHORD)]

    def material_passes(self, obj: SceneObject) -> list[RenderPass]:
        if self.params.shells == 0:
            return []
        passes: list[RenderPass] = []
        if self.params.fins:
            passes.append(ShellFurFinPass(f"{obj.label}.fins", Phase.MATERIAL, obj,
                                          fragment=SHELL_FRAGMENT, colors=(COMPOSITE,),
                                          extra_reads=fur_light_targets(self.fur_light()),
                                          fur_light=self.fur_light(),
                                          constants=self.vertex_constants(obj)))
        passes.append(ShellFurLayerPass(f"{obj.label}.layers", Phase.MATERIAL, obj,
                                        fragment=SHELL_FRAGMENT, colors=(COMPOSITE,),
                                        extra_reads=fur_light_targets(self.fur_light()),
                                        fur_light=self.fur_light(),
                                        constants=self.vertex_constants(obj)))
        return passes

    def forward_passes(self, obj: SceneObject) -> list[RenderPass]:
        passes: list[RenderPass] = [
            ShellFurForwardBasePass(f"{obj.label}.forward", Phase.FORWARD, obj,
                                    constants=self.vertex_constants(obj, 0.0),
                                    extra_defines=CHORD)]
        if self.params.shells == 0:
            return passes
        if self.params.fins:
            passes.append(ShellFurFinPass(f"{obj.label}.forward_fins", Phase.FORWARD, obj,
                                          fragment=FORWARD_SHELL_FRAGMENT, colors=(COMPOSITE,),
                                          constants=self.vertex_constants(obj)))
        passes.append(ShellFurLayerPass(f"{obj.label}.forward_layers", Phase.FORWARD, obj,
                                        fragment=FORWARD_SHELL_FRAGMENT, colors=(COMPOSITE,),
                                        constants=self.vertex_constants(obj)))
        return passes
