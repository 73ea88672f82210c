"""Cartoon hair (Costigan, "Cartoon Hair Simulation", chapters 3-4): guide strands on the
object's scalp, simulated as mass-spring chains, swept into tapered tube meshes every frame and
shaded by the ``toon`` model through the material's X-toon ramp; the object's own mesh (the
head) is drawn too, in ``skin_color``.

- strands (4.1-4.2.1): from ``strands_file`` (JSON or OBJ polylines, object space) or grown on
  the scalp (the mesh's vertex-colour alpha: ``builtin:head`` paints one) in a ``style``;
- dynamics (4.2.2-4.2.4): :mod:`.techniques.hair_dynamics`, the roots pinned to the object,
  colliding with ``collision_spheres`` (``builtin:head``'s own by default), anchored to
  ``keyframes`` (strand files at ``key_times``, Catmull-Rom in time) by ``anchor_stiffness``;
  stepped from t = 0 at ``time_step`` (after ``settle`` seconds at rest before it), each step
  with the parameters of the scene's timeline at its time (gravity, wind, drag, stiffnesses,
  anchors, and every shading parameter may change between frames; what builds the strands and
  the simulation, ``timeline_fixed``, may not), so a frame's hair depends only on its time;
- tubes (4.3.1-4.3.2): :mod:`.techniques.hair_tubes`, ``hair_samples`` spline samples swept by a
  ``sides``-gon tapered by the quadratic ``taper``, built every frame by compute shaders where
  the context has them (:class:`.techniques.hair_tubes.GpuTubes`), else by numpy;
- shading (4.3.3-4.3.6): X-toon (:mod:`.techniques.xtoon`), the G-buffer datum ``strand_id``
  (0 on the head; on the hair 1 + the object's first id + the strand's index) lets the
  ``edges`` effect outline strands of one colour where they overlap (4.3.7);
- silhouette strokes (4.3.7, object space): :mod:`.techniques.hair_silhouettes` with
  ``silhouettes = true``, strokes ``stroke_width`` pixels wide in ``stroke_color`` along the
  tubes' silhouette edges, faded toward the roots by the quadratic ``stroke_fade``; drawn over
  the lit image (deferred: the material phase, visible by the G-buffer's strand ids; forward:
  after the lit hair, by the depth buffer).

The tubes carry each vertex's strand in the vertex format's comb slot (the hair has no comb):
``comb.x`` the strand's index, ``comb.y`` the parameter along it; ``uv`` is (along, around).
"""

from __future__ import annotations

import weakref
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import moderngl
import numpy as np
from pydantic import Field, model_validator

from deferred.api import (
    COMPOSITE,
    DEPTH,
    BlinnPhongParams,
    ForwardLitPass,
    GBufferData,
    GBufferPass,
    GpuMesh,
    InputError,
    Material,
    MeshData,
    MeshPrimitives,
    ObjectPass,
    Order,
    Phase,
    builtin_head_spheres,
    materials,
)

from ..shading_models import Toon
from ..techniques.hair_dynamics import HairPhysics, HairSimulation
from ..techniques.hair_silhouettes import SilhouettePass, silhouette_geometry, tube_adjacency
from ..techniques.hair_strands import grow_strands, load_strands, resample_strand, scalp_roots
from ..techniques.hair_tubes import GpuTubes, build_tubes, tube_radii
from ..techniques.hatching import TamSettings, tam_texture, tonal_art_map
from ..techniques.xtoon import XTOON_UNIFORM_OVERRIDES, XToonParams, XToonRamp

if TYPE_CHECKING:
    from deferred.api import Frame, SceneObject

Vec3 = tuple[float, float, float]
SURFACE = "materials/cartoon_hair/surface.glsl"
STRAND_ID = GBufferData("strand_id", "R32F", ("id",),
                        "cartoon_hair: 1 + the object's first id + the strand's index on "
                        "hair, 0 elsewhere")
MAX_STRANDS = 20000
STRAND_IDS = 32768  # ids a hair object's strands take (more than MAX_STRANDS)
MAX_HAIR_OBJECTS = (1 << 24) // STRAND_IDS  # ids stay whole numbers in the R32F datum
# The hair at time t is t / time_step steps from 0 (benchmarks/README.md has what a step
# costs): more is refused rather than left to run for hours
MAX_HAIR_STEPS = 20_000
MAX_HAIR_STRAND_STEPS = 50_000_000


class CartoonHairParams(BlinnPhongParams, XToonParams):
    color: Vec3 = Field((0.55, 0.35, 0.85), description="hair albedo, linear RGB")
    skin_color: Vec3 = Field((0.95, 0.78, 0.66), description="the head's albedo, linear RGB")
    specular_intensity: float = Field(0.0, ge=0.0, le=1.0,
                                      description="the toon model's hard specular band")
    # strands in (4.1-4.2.1)
    strands_file: str | None = Field(None, description="guide strands: JSON {\"strands\": "
                                                       "[[[x, y, z], ...], ...]} or OBJ l lines")
    strands: int = Field(200, ge=1, le=MAX_STRANDS, description="strands grown on the scalp")
    length: float = Field(0.18, gt=0.0, le=10.0, description="strand length, object units")
    segments: int = Field(7, ge=1, le=32, description="simulated segments a strand")
    style: Literal["combed", "spiky"] = Field("spiky", description="how grown strands lie")
    parting: float = Field(0.0, ge=-1.0, le=1.0, description="combed: the parting's x")
    seed: int = Field(1, ge=0, le=2**31 - 1, description="roots and styles")
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
        None, description="object-space (x, y, z, radius); default: builtin:head's own")
    # tubes (4.3.1-4.3.2)
    hair_samples: int = Field(8, ge=2, le=64, description="spline samples a strand")
    sides: int = Field(6, ge=3, le=16, description="sides of a tube")
    radius: float = Field(0.012, gt=0.0, le=1.0, description="tube radius at the root")
    taper: Vec3 = Field((0.0, -1.0, 1.0), description="radius along the strand: a x^2 + b x + c")
    # silhouette strokes (4.3.7, object space)
    silhouettes: bool = Field(False, description="strokes along the tubes' silhouette edges")
    stroke_width: float = Field(3.0, gt=0.0, le=64.0, description="silhouette strokes, pixels")
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
        material: CartoonHairMaterial = obj.material
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
        self.mesh = MeshData("cartoon_hair tubes", tubes[0], tubes[1],
                             *self._constant_attributes(tubes[2]), tubes[3])
        self.gpu = GpuMesh(ctx, self.mesh, moving=True)
        self.ctx = ctx
        self._gpu_tubes: GpuTubes | None = None
        self._silhouettes: MeshPrimitives | None = None
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
    def silhouettes(self) -> MeshPrimitives:
        """The tubes with each triangle's neighbours (made the first time it is asked for)."""
        if self._silhouettes is None:
            p = self.params
            topology = (self.simulation.strands.shape[0], p.hair_samples, p.sides)
            self._silhouettes = silhouette_geometry(self.ctx, self.gpu,
                                                    tube_adjacency(*topology))
        return self._silhouettes

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
    def _constant_attributes(tubes) -> tuple[np.ndarray, ...]:
        count = len(tubes.positions)
        uvs = np.stack([tubes.along, tubes.around], axis=1).astype(np.float32)
        zeros = np.zeros((count, 3), np.float32)
        comb = np.zeros((count, 4), np.float32)
        comb[:, 0] = tubes.strand_ids
        comb[:, 1] = tubes.along
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
        self.time = time

    def release(self) -> None:
        if self._silhouettes is not None:
            self._silhouettes.release()
        if self._gpu_tubes is not None:
            self._gpu_tubes.release()
        self.gpu.release()


def strand_base(scene, obj: SceneObject) -> float:
    """The first strand id of ``obj``'s hair: each cartoon_hair object of the scene has its own
    range of ``STRAND_IDS`` ids, so strands of two heads are told apart too."""
    hairs = [other for other in scene.objects if isinstance(other.material, CartoonHairMaterial)]
    index = next((k for k, other in enumerate(hairs) if other.node is obj.node), 0)
    if index >= MAX_HAIR_OBJECTS:
        raise InputError(f"a scene holds at most {MAX_HAIR_OBJECTS} cartoon_hair objects (their "
                         "strand ids share one float channel)", obj.label)
    return float(index * STRAND_IDS)


def hair_state(frame: Frame, obj: SceneObject) -> HairState:
    """``obj``'s hair in the frame's renderer, made the first time it is asked for."""
    state = frame.resources.cached(("cartoon_hair_state", obj.node),
                                   lambda ctx: HairState(ctx, obj))
    state.obj = obj  # the object as this frame has it (the tracks moving it now)
    return state


class PreparedHair:
    """A pass of an object's hair: ``prepare`` brings the hair to the frame's time (every pass
    is prepared before any draws, so all of them see the same hair) and :meth:`state` gives it
    to the pass's hooks."""

    name: str
    _prepared: tuple[weakref.ref, HairState] | None = None

    def prepare(self, frame: Frame) -> None:
        state = hair_state(frame, self.object(frame))
        state.advance(frame.time, frame)
        self._prepared = (weakref.ref(frame), state)

    def state(self, frame: Frame) -> HairState:
        if self._prepared is None or self._prepared[0]() is not frame:
            raise RuntimeError(f"{self.name}: drawn in a frame it was not prepared for")
        return self._prepared[1]


class HairInputs(PreparedHair):
    """The hair's surface passes: they draw the tubes instead of the object's mesh."""

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        obj = self.object(frame)
        return {**super().uniforms(frame), "u_hair": True, "u_color": obj.params.color,
                "u_strand_base": strand_base(frame.scene, obj)}

    def draw(self, frame: Frame, program: moderngl.Program) -> None:
        self.state(frame).gpu.render(program)


class HairHatchingPass(HairInputs, ObjectPass):
    """The tubes again, their lit tone's hatching multiplied over the lit hair (4.3.8): the
    lighting evaluated here (every light of the frame, as the forward pipeline does), the ink
    from the tonal art map (:mod:`.techniques.hatching`, made once and cached on disk)."""

    fragment = "materials/cartoon_hair/hatching.frag"
    colors = (COMPOSITE,)
    depth = DEPTH
    depth_func = "lequal"
    depth_write = False
    blend = "multiply"
    order = Order.OPAQUE  # the material's own pixels, before its strokes

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        params = self.object(frame).params
        tam = hatching_map()
        return {**super().uniforms(frame), "u_tam_tones": tam.tones,
                "u_tam_gutter": tam.gutter, "u_hatching_strength": params.hatching_strength,
                # screen hatching keeps the map's strokes at their width in pixels
                "u_hatching_scale": 1.0 if params.hatching == "screen" else params.hatching_scale,
                "u_hatching_screen": params.hatching == "screen"}

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        texture = frame.resources.cached("cartoon_hair_tam",
                                         lambda ctx: tam_texture(ctx, hatching_map()))
        return {**super().textures(frame), "u_tam": texture}


def hatching_map():
    """The hatching's tonal art map: the thesis' 6 tones x 3 mips of 78 strokes at 256^2
    (cached on disk by :func:`.techniques.hatching.tonal_art_map`)."""
    return tonal_art_map(TamSettings(size=256, tones=6, mips=3, strokes=78, candidates=10))


class HairGBufferPass(HairInputs, GBufferPass):
    """The tubes into the G-buffer."""


class HairForwardPass(HairInputs, ForwardLitPass):
    """The tubes lit in the forward pipeline."""


class HairSilhouettePass(PreparedHair, SilhouettePass):
    """The tubes' silhouette strokes over the lit image."""

    def silhouette_geometry(self, frame: Frame) -> MeshPrimitives:
        return self.state(frame).silhouettes

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        uniforms = super().uniforms(frame)
        if self.id_buffer:  # the stroke's own strand's id in the G-buffer
            uniforms["u_strand_base"] = strand_base(frame.scene, self.object(frame))
        return uniforms

    def stroke_settings(self, frame: Frame) -> dict[str, Any]:
        p = self.object(frame).params
        # a tube's own front surface lies up to its radius nearer than its silhouette
        return {"width": p.stroke_width, "color": p.stroke_color, "fade": p.stroke_fade,
                "tolerance": float(tube_radii(p.hair_samples, p.radius, p.taper).max())}


@materials.register
class CartoonHairMaterial(Material):
    name = "cartoon_hair"
    Params = CartoonHairParams
    surface_shader = SURFACE
    shading_model = "toon"
    gbuffer_data = (STRAND_ID,)
    uniform_overrides = {
        **XTOON_UNIFORM_OVERRIDES,
        **{name: None for name in (
            "skin_color", "strands_file", "strands", "length", "segments", "style", "parting",
            "seed", "edge_stiffness", "bend_stiffness", "torsion_stiffness",
            "anchor_stiffness", "anchor_curve", "keyframes", "key_times", "gravity", "wind",
            "drag", "time_step", "settle", "collision_spheres", "hair_samples", "sides",
            "radius", "taper",
            "silhouettes", "stroke_width", "stroke_color", "stroke_fade", "hatching",
            "hatching_strength", "hatching_scale")},
        "color": lambda value: {},  # the head's pass takes skin_color, the hair's color
    }
    # read once, at t = 0: the strands, the simulation's structure and the tubes' topology
    # (the dynamics' parameters follow the timeline step by step: HairState.physics_at)
    timeline_fixed = ("strands_file", "strands", "length", "segments", "style", "parting",
                      "seed", "keyframes", "key_times", "hair_samples", "sides",
                      "collision_spheres", "time_step", "settle")

    def motion_extent(self, obj: SceneObject) -> float:
        """The strands reach up to their length beyond the head."""
        return float(self.params.length)

    def check_time_for(self, obj: SceneObject, time: float, where: str) -> None:
        """The hair is stepped from t = 0 at ``time_step``, after ``settle``: the steps, and the
        steps times the strands, are bounded (``MAX_HAIR_STEPS``, ``MAX_HAIR_STRAND_STEPS``), so
        a late frame is refused before any frame instead of running for hours."""
        steps = round(time / self.params.time_step) + settle_steps(self.params)
        strands = self.params.strands if self.params.strands_file is None else \
            len(load_strands(self.resolve_path(self.params.strands_file), "strands_file"))
        if steps > MAX_HAIR_STEPS or steps * strands > MAX_HAIR_STRAND_STEPS:
            settling = " (with settle)" if self.params.settle > 0.0 else ""
            raise InputError(f"t = {time:g} s needs {steps:,} simulation steps of "
                             f"{self.params.time_step:g} s{settling} for {strands:,} strands "
                             f"({obj.label}); the most is {MAX_HAIR_STEPS:,} steps and "
                             f"{MAX_HAIR_STRAND_STEPS:,} strand steps: render an earlier time, "
                             "raise time_step or grow fewer strands", where)

    def check_files(self, where: str | None) -> None:
        super().check_files(where)
        for key, names in (("strands_file", [self.params.strands_file]),
                           ("keyframes", list(self.params.keyframes))):
            for index, name in enumerate(names):
                if name is None:
                    continue
                at = f"{where}.{key}" if where else key
                at = at if key == "strands_file" else f"{at}[{index}]"
                load_strands(self.file_parameter(name, "strand file", at), at)

    def xtoon_ramp(self) -> XToonRamp:
        image = None if self.params.ramp_image is None else \
            self.resolve_path(self.params.ramp_image)
        return XToonRamp.from_params(self.params, image)

    def uniforms(self, frame: Frame) -> dict[str, Any]:  # the ramp's layer: the scene's
        return {**super().uniforms(frame), "u_hair": False, "u_strand_base": 0.0,
                "u_color": self.params.skin_color,
                "u_ramp_row": Toon.xtoon_row(frame.scene, self.xtoon_ramp())}

    # -- the strands ----------------------------------------------------------------------
    def spheres(self, obj: SceneObject) -> np.ndarray:
        """Object-space collision spheres: the params', or builtin:head's, or none."""
        if self.params.collision_spheres is not None:
            return np.asarray(self.params.collision_spheres, np.float64).reshape(-1, 4)
        if obj.mesh.name == "builtin:head":
            return builtin_head_spheres()
        return np.zeros((0, 4))

    def rest_strands(self, obj: SceneObject) -> np.ndarray:
        """The style: ``(S, P, 3)`` object-space strands, root first."""
        p = self.params
        if p.strands_file is not None:
            strands = load_strands(self.resolve_path(p.strands_file), "strands_file")
            if len(strands) >= STRAND_IDS:
                raise InputError(f"{len(strands):,} strands; a hair object holds fewer than "
                                 f"{STRAND_IDS:,}", "strands_file")
            return strands
        roots = scalp_roots(obj.mesh, p.strands, p.seed)
        return grow_strands(roots, p.length, p.segments, p.style, p.seed, self.spheres(obj),
                            p.parting)

    def keyframe_strands(self, shape: tuple[int, ...]) -> np.ndarray:
        """The keyframes' strands, each resampled to the rest strands' points."""
        poses = []
        for index, name in enumerate(self.params.keyframes):
            strands = load_strands(self.resolve_path(name), f"keyframes[{index}]")
            if len(strands) != shape[0]:
                raise InputError(f"{Path(name).name} has {len(strands)} strands; the hair "
                                 f"has {shape[0]}", f"keyframes[{index}]")
            poses.append(np.stack([resample_strand(s, shape[1]) for s in strands]))
        return np.stack(poses)

    # -- passes ---------------------------------------------------------------------------
    def geometry_passes(self, obj: SceneObject) -> list:
        return [*super().geometry_passes(obj),
                HairGBufferPass(f"{obj.label}.hair", Phase.GEOMETRY, obj)]

    def material_passes(self, obj: SceneObject) -> list:
        passes = [*super().material_passes(obj)]
        if self.params.hatching != "none":
            passes.append(HairHatchingPass(f"{obj.label}.hatching", Phase.MATERIAL, obj))
        if self.params.silhouettes:
            passes.append(HairSilhouettePass(f"{obj.label}.silhouettes", Phase.MATERIAL, obj,
                                             id_buffer=True))
        return passes

    def forward_passes(self, obj: SceneObject) -> list:
        passes = [*super().forward_passes(obj),
                  HairForwardPass(f"{obj.label}.hair", Phase.FORWARD, obj)]
        if self.params.hatching != "none":  # blended after the opaque lit passes
            passes.append(HairHatchingPass(f"{obj.label}.forward_hatching", Phase.FORWARD, obj,
                                           order=Order.VOLUME))
        if self.params.silhouettes:
            passes.append(HairSilhouettePass(f"{obj.label}.forward_silhouettes", Phase.FORWARD,
                                             obj))
        return passes
