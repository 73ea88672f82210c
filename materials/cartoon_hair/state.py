"""cartoon_hair's state over time, one per object and renderer: the guide strands simulated as
mass-spring chains (``techniques/hair_dynamics.py``) and swept into the tube mesh every frame
(``techniques/hair_tubes.py``), and the simulation (:class:`HairSimulation`) that brings it to
each frame's time and refuses a time it cannot reach in bounded work."""

from __future__ import annotations

from typing import TYPE_CHECKING

import moderngl
import numpy as np

from deferred.api import (
    GpuMesh,
    InputError,
    MeshData,
    MeshPrimitives,
    Per,
    ReachMotion,
    RenderWork,
    Simulation,
    Work,
    WorkObject,
    counted,
)

from ..techniques.hair_dynamics import HairPhysics, HairSimulation
from ..techniques.hair_silhouettes import SilhouetteEdges, silhouette_geometry, tube_adjacency
from ..techniques.hair_strands import load_strands
from ..techniques.hair_tubes import GpuTubes, build_tubes
from .params import (
    MAX_HAIR_STEPS,
    MAX_HAIR_STRAND_STEPS,
    PARTICLE_STEP_SECONDS,
    SILHOUETTE_BYTES_PER_TRIANGLE,
    SPHERE_TEST_SECONDS,
    TUBE_BYTES_PER_VERTEX,
    TUBE_VERTEX_FRAME_SECONDS,
    TUBE_VERTEX_MADE_SECONDS,
    CartoonHairParams,
    settle_steps,
    tube_counts,
)

if TYPE_CHECKING:
    from deferred.api import Frame, SceneObject


def hair_physics(params: CartoonHairParams) -> HairPhysics:
    """The simulation's parameters of a material state."""
    return HairPhysics(
        edge_stiffness=params.edge_stiffness, bend_stiffness=params.bend_stiffness,
        torsion_stiffness=params.torsion_stiffness, anchor_stiffness=params.anchor_stiffness,
        anchor_curve=params.anchor_curve, gravity=params.gravity, wind=params.wind,
        drag=params.drag, time_step=params.time_step)


def params_at(obj: SceneObject, time: float) -> CartoonHairParams:
    """``obj``'s parameters at ``time`` on its timeline (its material's, without one)."""
    at = getattr(obj, "params_at", None)
    return at(time) if at is not None else obj.material.params


class HairState:
    """One object's hair in one renderer: the simulation and the tube mesh's GPU buffers,
    brought to a frame's time by :meth:`advance`.

    The tubes' positions and normals live in a buffer of their own (a moving
    :class:`GpuMesh`); with compute shaders they are built there (:class:`GpuTubes`) and
    ``mesh.positions`` keep the tubes of t = 0, else numpy builds them and they are uploaded.
    """

    def __init__(self, ctx: moderngl.Context, obj: SceneObject):
        self.obj = obj
        material = obj.material  # a CartoonHairMaterial
        params = params_at(obj, 0.0)  # what builds the hair: timeline_fixed
        self.params = params
        rest = material.rest_strands(obj)
        keyframes = material.keyframe_strands(rest.shape) if params.keyframes else None
        self._physics: dict[int, tuple[CartoonHairParams, HairPhysics]] = {}
        self.simulation = HairSimulation(rest, self.physics_at(0.0), material.spheres(obj),
                                         keyframes, params.key_times or None,
                                         self.model_at(0.0), settle_steps(params))
        self.inverse_model = np.linalg.inv(self.model_at(0.0))
        tubes = self._tubes(params)
        self.clumps = material.clumps(rest)
        self.mesh = MeshData("cartoon_hair tubes", tubes[0], tubes[1],
                             *self._constant_attributes(tubes[2], self.clumps), tubes[3])
        # the tubes of the frame before kept beside them: the motion vectors (HairMotion)
        self.gpu = GpuMesh(ctx, self.mesh, moving=True, keeps_previous=True)
        self.ctx = ctx
        self._gpu_tubes: GpuTubes | None = None
        self._silhouettes: MeshPrimitives | None = None
        self._silhouette_edges: SilhouetteEdges | None = None
        self.time: float | None = None
        self._placed = self._placement()

    def physics_at(self, time: float) -> HairPhysics:
        """The simulation's parameters at ``time`` (made once for each state of the
        timeline)."""
        params = params_at(self.obj, time)
        known = self._physics.get(id(params))
        if known is None or known[0] is not params:
            known = self._physics[id(params)] = (params, hair_physics(params))
        return known[1]

    def _placement(self) -> tuple:
        """What the hair's history is made of: the object's tracks, its placement at t = 0
        and its timeline (the base parameters and events)."""
        material = self.obj.material
        return (tuple(map(id, getattr(self.obj, "tracks", ()))),
                self.model_at(0.0).tobytes(),
                getattr(self.obj, "base_params", material.params),
                getattr(self.obj, "events", ()))

    def model_at(self, time: float) -> np.ndarray:
        """The object's world matrix at ``time``: its tracks' and its parents'
        (ObjectState.model_at), else its model."""
        model_at = getattr(self.obj, "model_at", None)
        return model_at(time) if model_at is not None else self.obj.model

    @property
    def topology(self) -> tuple[int, int, int]:
        """The tubes' strands, samples and sides."""
        return self.simulation.strand_count, self.params.hair_samples, self.params.sides

    @property
    def silhouettes(self) -> MeshPrimitives:
        """The tubes with each triangle's neighbours (made the first time it is asked for: the
        geometry shader's silhouettes, GL 3.3)."""
        if self._silhouettes is None:
            self._silhouettes = silhouette_geometry(self.ctx, self.gpu,
                                                    tube_adjacency(*self.topology))
        return self._silhouettes

    @property
    def silhouette_edges(self) -> SilhouetteEdges:
        """The tubes' silhouette edges on the GPU (made the first time it is asked for)."""
        if self._silhouette_edges is None:
            self._silhouette_edges = SilhouetteEdges(self.ctx, *self.topology)
        return self._silhouette_edges

    def _tubes(self, params: CartoonHairParams):
        """The tubes by numpy (:func:`build_tubes`), in object space."""
        p = self.params
        tubes = build_tubes(self.simulation.strands, p.hair_samples, p.sides, params.radius,
                            params.taper, reference=self.simulation.root_references())
        # the simulation is in world space; the object's passes draw in object space
        linear, offset = self.inverse_model[:3, :3], self.inverse_model[:3, 3]
        positions = tubes.positions @ linear.T + offset
        normals = tubes.normals @ np.linalg.inv(linear)  # the inverse transpose, applied
        normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
        return positions.astype(np.float32), normals.astype(np.float32), tubes, tubes.indices

    @staticmethod
    def _constant_attributes(tubes, clumps: np.ndarray) -> tuple[np.ndarray, ...]:
        """uv (along, around), no tangent frame, and the comb slot: (strand, along, clump,
        around + 1/2 wrapped: the hatching's seamless lookup round the tube)."""
        count = len(tubes.positions)
        uvs = np.stack([tubes.along, tubes.around], axis=1).astype(np.float32)
        zeros = np.zeros((count, 3), np.float32)
        comb = np.zeros((count, 4), np.float32)
        comb[:, 0] = tubes.strand_ids
        comb[:, 1] = tubes.along
        comb[:, 2] = clumps[tubes.strand_ids]
        comb[:, 3] = np.mod(tubes.around + 0.5, 1.0)
        return uvs, zeros, zeros.copy(), comb

    def advance(self, time: float, frame: Frame | None = None) -> None:
        """The hair at ``time`` (seconds): stepped from where it is (or from the start, for an
        earlier time), the tubes rebuilt: by compute shaders where ``frame``'s context has
        them, else by numpy and uploaded."""
        placement = self._placement()
        if placement != self._placed:  # new tracks, model or timeline: the history starts over
            self.simulation.reset(self.model_at(0.0))
            self._physics.clear()
            self._placed, self.time = placement, None
        # what the frame before showed (a first frame's or a still one's: this frame's)
        self.gpu.keep_previous()
        if self.time == time:
            return
        # the roots follow the object's transform at each step (its tracks move it); the
        # tubes go back to object space through the transform at the simulated step
        self.simulation.advance(time, self.model_at, self.physics_at)
        simulated = max(self.simulation.time, 0.0)
        self.inverse_model = np.linalg.inv(self.model_at(simulated))
        params = params_at(self.obj, simulated)  # the tube's radius and taper
        if frame is not None and frame.gl.features.compute_shaders:
            if self._gpu_tubes is None:
                p = self.params
                self._gpu_tubes = GpuTubes(self.ctx, self.simulation.strand_count,
                                           self.simulation.point_count, p.hair_samples,
                                           p.sides)
            self._gpu_tubes.upload(self.simulation.component_points,
                                   self.simulation.component_references())
            self._gpu_tubes.build(frame.shaders, self.gpu.surface_vbo, params.radius,
                                  params.taper, self.inverse_model)
        else:
            positions, normals, _, _ = self._tubes(params)
            self.mesh.positions, self.mesh.normals = positions, normals
            self.gpu.write_surface()
        if self.time is None:  # a first frame (or the history started over): no motion
            self.gpu.keep_previous()
        self.time = time

    def release(self) -> None:
        if self._silhouettes is not None:
            self._silhouettes.release()
        if self._silhouette_edges is not None:
            self._silhouette_edges.release()
        if self._gpu_tubes is not None:
            self._gpu_tubes.release()
        self.gpu.release()


class HairDynamics(Simulation):
    """The hair of each cartoon_hair object (:class:`HairState`), stepped from t = 0 at
    ``time_step`` after ``settle``: the steps, and the steps times the strands, are bounded
    (``MAX_HAIR_STEPS``, ``MAX_HAIR_STRAND_STEPS``), so a late frame is refused before any
    frame instead of running for hours."""

    key = "cartoon_hair_state"

    def start(self, ctx: moderngl.Context, obj: SceneObject) -> HairState:
        return HairState(ctx, obj)

    def advance(self, state: HairState, frame: Frame, obj: SceneObject) -> None:
        state.obj = obj  # the object as this frame has it (the tracks moving it now)
        state.advance(frame.time, frame)

    def check_time(self, obj: SceneObject, time: float, where: str) -> None:
        params = obj.material.params
        check_steps(params, time, hair_shape(obj.material)[0], obj.label, where)

    def work(self, obj: WorkObject, job: RenderWork) -> list[Work]:
        """The chains stepped to the latest frame (their particles, and each against the
        collision spheres), the tubes made once and built again each frame; refused past the
        step limits (:func:`check_steps`)."""
        material = obj.material
        params = material.params
        strands, points = hair_shape(material)
        check_steps(params, job.latest_time, strands, obj.label, job.time_key)
        steps = hair_steps(params, job.latest_time)
        particles = strands * (2 * points + 1)  # the chains: points and their middles
        spheres = len(material.spheres_of(obj.mesh))
        vertices, _ = tube_counts(strands, params)
        shape = f"{strands:,} strands x {params.hair_samples} samples x {params.sides} sides"
        works = [Work(f"{obj.label}: {steps:,} steps x {counted(particles)} particles",
                      steps * particles, PARTICLE_STEP_SECONDS, obj.key("strands"), Per.RENDER),
                 Work(f"{obj.label}: making the tubes, {shape}", vertices,
                      TUBE_VERTEX_MADE_SECONDS, obj.key("strands"), Per.RENDER),
                 Work(f"{obj.label}: the tubes built, {shape}", vertices,
                      TUBE_VERTEX_FRAME_SECONDS, obj.key("strands"), Per.FRAME)]
        if spheres:
            works.append(Work(f"{obj.label}: {steps:,} steps x {counted(particles)} particles x "
                              f"{spheres} collision spheres", steps * particles * spheres,
                              SPHERE_TEST_SECONDS, obj.key("collision_spheres"), Per.RENDER))
        return works

    def held_memory(self, obj: SceneObject) -> dict[str, int]:
        """The tubes (made by numpy, in the vertex format and its buffers), their triangles'
        adjacency for the silhouette strokes, and the simulated chains."""
        params = obj.material.params
        strands, points = hair_shape(obj.material)
        vertices, triangles = tube_counts(strands, params)
        held = {f"hair tubes of {obj.label}": vertices * TUBE_BYTES_PER_VERTEX,
                f"hair chains of {obj.label}": strands * (2 * points + 1) * CHAIN_BYTES}
        if params.silhouettes:
            held[f"hair silhouettes of {obj.label}"] = triangles * SILHOUETTE_BYTES_PER_TRIANGLE
        return held


# bytes a particle of the chains takes (positions, velocities, the step's scratch: float32)
CHAIN_BYTES = 12 * 3 * 4


def hair_shape(material) -> tuple[int, int]:
    """The strands and the points a strand of a cartoon_hair material: its file's (read once
    and kept), or ``strands`` of ``segments + 1`` points."""
    params = material.params
    if params.strands_file is None:
        return params.strands, params.segments + 1
    strands = load_strands(material.resolve_path(params.strands_file),
                           material.key_where("strands_file"))
    return strands.shape[0], strands.shape[1]


def hair_steps(params: CartoonHairParams, time: float) -> int:
    """Steps simulated to reach ``time``, the settling with them."""
    return round(time / params.time_step) + settle_steps(params)


def check_steps(params: CartoonHairParams, time: float, strands: int, label: str,
                where: str) -> None:
    """Refuse (naming ``where``) a frame ``time`` whose steps, or steps times ``strands``, pass
    the limits."""
    steps = hair_steps(params, time)
    if steps > MAX_HAIR_STEPS or steps * strands > MAX_HAIR_STRAND_STEPS:
        settling = " (with settle)" if params.settle > 0.0 else ""
        raise InputError(f"t = {time:g} s needs {steps:,} simulation steps of "
                         f"{params.time_step:g} s{settling} for {strands:,} strands "
                         f"({label}); the most is {MAX_HAIR_STEPS:,} steps and "
                         f"{MAX_HAIR_STRAND_STEPS:,} strand steps: render an earlier time, "
                         "raise time_step or grow fewer strands", where)


DYNAMICS = HairDynamics()


class HairMotion(ReachMotion):
    """cartoon_hair in the motion vectors: the head pushed out by the strands' ``length`` (what
    the hair reaches), and the tubes drawn over it from the frame before's to this frame's
    (dynamics, wind, anchors: the hair's own motion with a still camera)."""

    def surfaces(self, frame: Frame, obj: SceneObject) -> tuple[GpuMesh, ...]:
        return (DYNAMICS.state(frame, obj).gpu,)
