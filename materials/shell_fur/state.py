"""shell_fur's state over time, one per object and renderer: the wetness mask (Silva et al. 3.1,
Algorithm 1; ``techniques/wetness.py``), built from random droplets or an image and drying at
``dry_rate``, and one mass-spring strand per triangle (3.2.1, Eq. 2, 3;
``techniques/strands.py``) under gravity and gusting wind; the simulation
(:class:`ShellFurSimulation`) that brings it to each frame's time and refuses a time it cannot
reach in bounded work.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import moderngl
import numpy as np

from deferred.api import (
    InputError,
    MotionOffsets,
    Per,
    ReachMotion,
    RenderWork,
    Simulation,
    Work,
    WorkObject,
    counted,
)

from ..techniques.strands import (
    StrandForces,
    StrandSimulation,
    VertexAverage,
    curl_frames,
    curl_phases,
    gust_wind,
    triangle_strands,
)
from ..techniques.uv_seams import UVSeams
from ..techniques.wetness import (
    dry_mask,
    dry_out,
    footprint_texels,
    load_wetness_mask,
    mean_uv_scale,
    random_droplets,
    uv_wrap,
)
from .params import (
    MAX_DROPLET_TEXELS,
    MAX_SIMULATION_STEPS,
    MAX_STRAND_STEPS,
    STRAND_STEP_SECONDS,
    ShellFurParams,
    simulation_steps,
)

if TYPE_CHECKING:
    from deferred.api import Frame, SceneObject

TIPS_WIDTH = 1024  # texels per row of the per-vertex strand texture
GUST_WAVELENGTH = 1.0  # world units between gust fronts along the wind


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


def _float_texture(ctx: moderngl.Context, width: int, height: int) -> moderngl.Texture:
    texture = ctx.texture((width, height), 4, dtype="f4")
    texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
    return texture


class ShellFurState:
    """An object's wetness mask and strands over time, with their textures (``u_wetness_mask``,
    ``u_strand_tips``): one per object and renderer (:class:`ShellFurSimulation`), brought to
    each frame's time before the frame's passes run.

    Time is a count of fixed steps from t = 0: the state at time t is that after step
    ``floor(t / time_step)`` whatever frames came before, so the same time gives the same frame
    (asked for an earlier time, the state starts over). Step n runs with the parameters at
    ``n * time_step`` (``ObjectState.params_at``); droplets fall at the first step at or after
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
        # the tip deflections the frame before showed, in the same layout (motion vectors:
        # StrandMotion); this frame's on a first frame
        self.previous_data = np.zeros_like(self.strand_data)
        self.previous_texture = _float_texture(ctx, TIPS_WIDTH,
                                               len(self.strand_data) // TIPS_WIDTH)
        self.step: int | None = None  # steps taken since t = 0
        self.mask = dry_mask(self.size)  # Algorithm 1's, drying included
        self.shown = self.mask.copy()  # what the shaders see: the mask as it soaks in (_soak)
        self.fallen = 0
        self._uploaded: int | None = None
        self._first_previous = True

    def params_at(self, time: float) -> ShellFurParams:
        return _params_at(self.obj, time)

    def advance(self, time: float) -> None:
        """Bring the state to ``time`` (seconds) and upload it if it changed; what the frame
        before showed becomes the previous tips (once a frame: the simulation's advance)."""
        rows = slice(0, 3 * self.obj.mesh.vertex_count, 3)
        shown = self.strand_data[rows].copy() if self._uploaded is not None else None
        self._advance(time)
        previous = self.strand_data[rows] if shown is None else shown
        if not np.array_equal(previous, self.previous_data[rows]) or self._first_previous:
            self.previous_data[rows] = previous
            self.previous_texture.write(self.previous_data.tobytes())
            self._first_previous = False

    def _advance(self, time: float) -> None:
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
        self.previous_texture.release()


class ShellFurSimulation(Simulation):
    """shell_fur's :class:`ShellFurState` of each object, and the work a frame time asks of
    it: the steps (with the settling), the steps times the object's strands (one a triangle:
    the work grows with both, so a fine mesh reaches its limit sooner), and the wetness-mask
    texels its droplets blend; it holds the wetness mask (an array and a float RGBA texture,
    ``mask_size`` squared each)."""

    key = "shell_fur_state"

    def start(self, ctx: moderngl.Context, obj: SceneObject) -> ShellFurState:
        return ShellFurState(ctx, obj)

    def advance(self, state: ShellFurState, frame: Frame, obj: SceneObject) -> None:
        state.obj = obj  # the object as this frame has it (the tracks moving it now)
        state.advance(frame.time)

    def check_time(self, obj: SceneObject, time: float, where: str) -> None:
        check_steps(obj.material.params, time, len(obj.mesh.indices), obj.label, where)
        texels, blame = droplet_texels(obj, time)
        if texels > MAX_DROPLET_TEXELS:
            droplets = _params_at(obj, time).droplets
            raise InputError(f"{droplets:,} droplets by t = {time:g} s blend "
                             f"{texels:,} wetness-mask texels (each the texels under it: "
                             f"droplet_radius and mask_size set how many); the most is "
                             f"{MAX_DROPLET_TEXELS:,}: fewer or smaller droplets, or a smaller "
                             "mask_size", blame)

    def held_memory(self, obj: SceneObject) -> dict[str, int]:
        return {f"wetness mask of {obj.label}": 2 * obj.material.params.mask_size ** 2 * 16}

    def work(self, obj: WorkObject, job: RenderWork) -> list[Work]:
        """The strand steps to the latest frame (one strand a triangle), refused past the
        limits before the mesh is made (:func:`check_steps`)."""
        params = obj.material.params
        strands = obj.triangles
        check_steps(params, job.latest_time, strands, obj.label, job.time_key)
        steps = simulation_steps(params, job.latest_time)
        return [Work(f"{obj.label}: {steps:,} simulation steps x {counted(strands)} strands",
                     steps * strands, STRAND_STEP_SECONDS, obj.key("time_step"), Per.RENDER)]


def check_steps(params: ShellFurParams, time: float, strands: int, label: str,
                where: str) -> None:
    """Refuse (naming ``where``) a frame ``time`` whose steps, or steps times ``strands``, pass
    the limits."""
    steps = simulation_steps(params, time)
    if steps > MAX_SIMULATION_STEPS:
        raise InputError(f"t = {time:g} s needs {steps:,} simulation steps of "
                         f"{params.time_step:g} s (with settle); the most is "
                         f"{MAX_SIMULATION_STEPS:,}: render an earlier time or raise "
                         "time_step", where)
    if steps * strands > MAX_STRAND_STEPS:
        raise InputError(f"t = {time:g} s needs {steps:,} simulation steps of "
                         f"{strands:,} strands ({label}: one a triangle), "
                         f"{steps * strands:,} strand steps; the most is "
                         f"{MAX_STRAND_STEPS:,}: render an earlier time, raise time_step "
                         "or give the object a coarser mesh", where)


SIMULATION = ShellFurSimulation()


def fur_state(frame: Frame, obj: SceneObject) -> ShellFurState:
    """``obj``'s state in the frame's renderer at the frame's time (``obj``: a scene object
    or its state in the frame)."""
    return SIMULATION.state(frame, frame.scene.object_state(obj.node))


class StrandMotion(ReachMotion):
    """shell_fur's reach in the motion vectors: ``fur_length`` along the normals, moved by each
    vertex's simulated tip deflection (gravity, gusting wind) of this frame and of the frame
    before, so the tips' own motion is in the vectors (a still camera in the wind)."""

    def offsets(self, frame: Frame, obj: SceneObject) -> MotionOffsets:
        state = fur_state(frame, obj)
        return MotionOffsets(state.tips_texture, state.previous_texture, stride=3)
