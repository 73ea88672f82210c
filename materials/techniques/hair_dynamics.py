"""Structured mass-spring strands of cartoon hair (Costigan 4.2.2-4.2.4 after Selle et al. 2008),
vectorised over all strands, at a fixed time step, deterministic.

**Structure (4.2.2).** Each segment ``p_i p_(i+1)`` of a strand gets one structural particle
``q_i`` beside its midpoint, perpendicular to it, each a quarter turn round the strand from the
last (a rotation-minimising frame carries the turn), so the chain
``p_-1 q_-1 p_0 q_0 p_1 ... p_(n-1)`` zigzags through space and every four consecutive
particles span a tetrahedron even where the strand is straight (Selle et al. add such particles
for straight hair). The springs are Selle et al.'s over that chain, attached to the styled strand
as it is (Fig. 4.4: the rest shape need not be straight):

- **edge** springs, particles 1 apart (``p q`` and ``q p``) and the strand's own segments
  ``p_i p_(i+1)``: they keep the length;
- **bend** springs, ``q_i q_(i+1)`` and ``p_i p_(i+2)``: they keep the angle at each joint;
- **torsion** springs, particles 3 apart (``p_i q_(i+1)``, ``q_i p_(i+2)``): with the others
  they make each tetrahedron rigid, so the strand cannot twist.

``p_-1`` and ``q_-1`` are a virtual first segment continuing the first segment backwards into
the scalp: with the root ``p_0`` they are pinned (4.2.1: the root takes no part in the
simulation and holds the strand up), so the root's position *and direction* follow the object's
model matrix every step exactly (4.2.4), and the strand keeps its angle to the scalp.

**Solver.** Bullet's soft bodies, which the thesis used (3.1), move each spring toward its rest
length by a fraction ``k`` in [0, 1] of the error per iteration (0 loose, 1 rigid, 4.2.2); this
is that position-based solver (Muller et al. 2007), swept from the root to the tip (follow the
leader, Muller et al. 2012): gravity and a drag toward the wind's velocity move the particles,
then each particle in turn, all strands at once, is moved (its root-side neighbours held) by
its springs to the three particles before it:

- its edge springs, each a distance projection with ``edge_stiffness``;
- its bend (a strand particle ``p``) or torsion (a structural particle ``q``) spring, with the
  edge springs it closes a tetrahedron; solved together they place the particle where the
  rest tetrahedron, laid on the current three, has it, approached by ``bend_stiffness`` or
  ``torsion_stiffness``.

Projecting Selle's springs one at a time, in classes that share no particle, converges too
slowly to hold a styled strand up against gravity (a 10 cm cantilever sagged to hanging at 100
iterations a step); solving each tetrahedron whole from the root does it in one sweep. ``k`` is
applied per sweep as ``1 - (1 - k)^(1 / iterations)`` so a stiffness means the same at any
iteration count. Velocities are what the step moved, divided by the step.

**Anchors (4.2.3).** Blending springs pull every particle toward its anchor, the same particle of
a keyframed strand set moved along a Catmull-Rom spline over the keyframe times (several poses
of the same strands; with none, the rest pose: anchors then keep the style, 3.1): the spline
runs over each strand's shape, its bends and segment lengths, not over the particles'
positions (:func:`.hair_strands.interpolate_shapes`: positions blended between a strand combed
left and combed right collapse it into the head halfway, which the collisions and springs fold
into kinks; bends blended stay within the poses' own), and the structural particles are laid on
the pose as on the rest strands, with stiffness
``anchor_stiffness`` scaled along the strand by the quadratic ``anchor_curve`` (uniform by
default). At 1 the strand is its keyframe pose.

**Collisions.** After the iterations every strand particle inside a collision sphere (object-space
centre and radius plus ``collision_margin``, moved by the model matrix; a scaled matrix scales
the radius by its largest axis scale) is pushed radially to its surface, for up to
``COLLISION_ROUNDS`` rounds where spheres overlap (a particle pushed out of one into another),
so particles end a step outside them (4.1: the head as a group of spheres; no hair-hair
collisions, as in 3.1).
Structural particles are not hair and do not collide: pushing one would twist the strand's
frame and bend the strand.

**Time.** Fixed steps from t = 0, after ``settle_steps`` steps of settling before it (the object
held at its placement at 0, the parameters at 0), so styled hair starts a render at rest. Each
step may take its own :class:`HairPhysics` (a scene timeline changing gravity, wind, drag,
stiffnesses or anchors between frames; the time step, iterations and structure stay the
simulation's, ``FIXED_PHYSICS``): replayed from the start, the state at a time depends on that
time alone.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .hair_poses import PolylineShapes, interpolate_shapes
from .hair_strands import quadratic, rotation_minimising_frames

PINNED = 3  # chain particles p_-1, q_-1, p_0
COLLISION_ROUNDS = 8
# what a simulation is built with and keeps: the others may change at every step
FIXED_PHYSICS = ("time_step", "iterations", "collision_margin", "structure_offset")


@dataclass(frozen=True)
class HairPhysics:
    """The simulation's parameters (world units: metres, seconds)."""

    edge_stiffness: float = 1.0  # [0, 1]: 0 loose, 1 rigid (4.2.2)
    bend_stiffness: float = 0.5
    torsion_stiffness: float = 0.5
    anchor_stiffness: float = 0.0  # [0, 1]: adherence to the keyframed pose (4.2.3)
    anchor_curve: tuple[float, float, float] = (0.0, 0.0, 1.0)  # a x^2 + b x + c along
    gravity: tuple[float, float, float] = (0.0, -9.81, 0.0)
    wind: tuple[float, float, float] = (0.0, 0.0, 0.0)  # the air's velocity
    drag: float = 2.0  # 1/s: how fast a particle takes the air's velocity
    time_step: float = 1.0 / 60.0
    iterations: int = 1  # sweeps a step: one holds k = 1 exactly; more only soften k < 1 less
    collision_margin: float = 0.0  # added to every collision sphere's radius
    structure_offset: float = 0.5  # structural particles' distance, in segment lengths

    def __post_init__(self) -> None:
        for name in ("edge_stiffness", "bend_stiffness", "torsion_stiffness",
                     "anchor_stiffness"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise ValueError(f"{name} must be in [0, 1], got {getattr(self, name)}")
        if not self.time_step > 0.0 or self.iterations < 1 or self.drag < 0.0:
            raise ValueError("time_step must be > 0, iterations >= 1 and drag >= 0")
        if not self.structure_offset > 0.0:
            raise ValueError("structure_offset must be > 0")


def structured_chain(strands: np.ndarray, offset: float = 0.5) -> np.ndarray:
    """The chain ``(S, 2P + 1, 3)`` of strands ``(S, P, 3)`` with their structural particles:
    ``p_-1 q_-1 p_0 q_0 ... p_(P-1)`` (see the module's docstring)."""
    strands = np.asarray(strands, dtype=np.float64)
    count, points = strands.shape[:2]
    first = strands[:, 1] - strands[:, 0]
    ends = np.concatenate([(strands[:, 0] - first)[:, None], strands], axis=1)  # p_-1 .. p_P-1
    segment = np.diff(ends, axis=1)  # (S, P, 3): segment i-1 for i = 0..P-1
    length = np.linalg.norm(segment, axis=-1, keepdims=True)
    tangent = segment / np.maximum(length, 1e-12)
    middle = 0.5 * (ends[:, 1:] + ends[:, :-1])
    normal = rotation_minimising_frames(middle, tangent)
    binormal = np.cross(tangent, normal)
    turn = np.arange(points) * (np.pi / 2.0)
    side = np.cos(turn)[None, :, None] * normal + np.sin(turn)[None, :, None] * binormal
    structural = middle + offset * length * side
    chain = np.empty((count, 2 * points + 1, 3))
    chain[:, 0::2] = ends
    chain[:, 1::2] = structural
    return chain


def solve_order(chain_length: int) -> list[tuple[int, tuple[int, int, int], tuple[int, ...]]]:
    """The free particles root to tip as ``(b, (back, middle, last), edge neighbours)``: each
    strand particle ``p_(i+1)`` and then its segment's structural particle ``q_i``.

    ``p_(i+1)`` (chain ``2i + 4``) follows ``p_i``: its edge spring to ``p_i`` and its bend
    springs place it in the frame of ``p_(i-1), q_(i-1), p_i``. ``q_i`` (chain ``2i + 3``) is
    placed after it, between the two: its edge springs to ``p_i`` and ``p_(i+1)`` and its
    torsion springs in the frame of ``p_i, p_(i+1), q_(i-1)``."""
    order = []
    for b in range(PINNED + 1, chain_length, 2):
        order.append((b, (b - 3, b - 4, b - 2), (b - 2,)))
        order.append((b - 1, (b - 3, b - 2, b), (b - 2, b)))
    return order


def tetrahedron_coordinates(chain: np.ndarray) -> np.ndarray:
    """``(C, S, 3)``: each free chain particle in its frame of :func:`solve_order` (origin
    ``last``, first axis from ``middle`` to ``last``, second toward ``back``): where its springs
    put it when they are all at rest (pinned rows unused)."""
    chain = np.moveaxis(np.asarray(chain, dtype=np.float64), 1, 0)  # (C, S, 3)
    coordinates = np.zeros_like(chain)
    for b, (back, middle, last), _ in solve_order(len(chain)):
        e1, e2, e3 = _frame(chain[back], chain[middle], chain[last])
        offset = chain[b] - chain[last]
        coordinates[b] = np.stack([(offset * e).sum(-1) for e in (e1, e2, e3)], axis=-1)
    return coordinates


def _frame(back: np.ndarray, middle: np.ndarray, last: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Orthonormal axes (..., 3) of the frame of three chain particles (see
    :func:`tetrahedron_coordinates`)."""
    e1 = last - middle
    e1 = e1 / np.maximum(np.linalg.norm(e1, axis=-1, keepdims=True), 1e-30)
    e2 = back - middle
    e2 = e2 - (e2 * e1).sum(-1, keepdims=True) * e1
    e2 = e2 / np.maximum(np.linalg.norm(e2, axis=-1, keepdims=True), 1e-30)
    return e1, e2, np.cross(e1, e2)


def _norm(v: np.ndarray, out: np.ndarray) -> np.ndarray:
    """Lengths of component-major vectors ``(3, S)`` into ``out`` ``(S,)``."""
    np.einsum("ij,ij->j", v, v, out=out)
    return np.sqrt(out, out=out)


def _normalise(v: np.ndarray, scratch: np.ndarray) -> None:
    """Component-major vectors ``(3, S)`` made unit length in place (zero ones left zero)."""
    _norm(v, scratch)
    np.maximum(scratch, 1e-30, out=scratch)
    v /= scratch


def _cross(a: np.ndarray, b: np.ndarray, out: np.ndarray) -> None:
    """Cross products of component-major vectors ``(3, S)`` into ``out``."""
    np.multiply(a[1], b[2], out=out[0])
    out[0] -= a[2] * b[1]
    np.multiply(a[2], b[0], out=out[1])
    out[1] -= a[0] * b[2]
    np.multiply(a[0], b[1], out=out[2])
    out[2] -= a[1] * b[0]


def transform_points(model: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``points`` ``(..., 3)`` through the 4x4 ``model`` matrix (column vectors)."""
    model = np.asarray(model, dtype=np.float64)
    return points @ model[:3, :3].T + model[:3, 3]


class HairSimulation:
    """Strands of one object simulated at a fixed time step (see the module's docstring).

    ``rest`` ``(S, P, 3)``: the strands in object space (the style; the first point of each is
    its root). ``spheres`` ``(K, 4)``: collision spheres in object space (centre, radius).
    ``keyframes`` ``(K, S, P, 3)`` at the increasing ``key_times`` (seconds): the anchors' poses;
    without them the anchors hold the rest pose. ``model``: the object's model matrix at time 0.

    The state is float32 in a component-major layout ``(3, chain, strands)``, so every spring
    family is a few whole-array operations over all strands.
    """

    def __init__(self, rest: np.ndarray, physics: HairPhysics | None = None,
                 spheres: np.ndarray | None = None, keyframes: np.ndarray | None = None,
                 key_times: Sequence[float] | None = None, model: np.ndarray | None = None,
                 settle_steps: int = 0):
        self.physics = physics or HairPhysics()
        if settle_steps < 0:
            raise ValueError("settle_steps must be >= 0")
        self.settle_steps = int(settle_steps)
        rest = np.asarray(rest, dtype=np.float64)
        if rest.ndim != 3 or rest.shape[1] < 2 or rest.shape[2] != 3:
            raise ValueError("rest strands must be (strands, points >= 2, 3)")
        self.strand_count, self.point_count = rest.shape[:2]
        offset = self.physics.structure_offset
        self._rest_chain = structured_chain(rest, offset)  # (S, C, 3) object space
        self.chain_length = self._rest_chain.shape[1]
        self._spheres = (np.zeros((0, 4)) if spheres is None
                         else np.asarray(spheres, dtype=np.float64).reshape(-1, 4))
        if keyframes is not None:
            keyframes = np.asarray(keyframes, dtype=np.float64)
            if keyframes.shape[1:] != rest.shape:
                raise ValueError(f"keyframes must be (keys, {self.strand_count}, "
                                 f"{self.point_count}, 3) like the rest strands, got "
                                 f"{keyframes.shape}")
            times = np.arange(len(keyframes), dtype=np.float64) if key_times is None \
                else np.asarray(key_times, dtype=np.float64)
            if len(times) != len(keyframes) or np.any(np.diff(times) <= 0.0):
                raise ValueError("key_times must be increasing, one per keyframe")
            self._key_chains = np.stack([structured_chain(k, offset) for k in keyframes])
            self._key_times = times
            self._key_shapes = PolylineShapes.of(keyframes)
        else:
            self._key_chains, self._key_times = self._rest_chain[None], np.zeros(1)
            self._key_shapes = PolylineShapes.of(rest[None])
        rest_chain = np.moveaxis(self._rest_chain, 1, 0).astype(np.float32)  # (C, S, 3)
        self._order = solve_order(self.chain_length)
        # each free particle's edge springs' rest lengths, in solve_order
        self._edges = {b: [(a, np.linalg.norm(rest_chain[b] - rest_chain[a], axis=-1)
                            .astype(np.float32)) for a in edges]
                       for b, _, edges in self._order}
        self._shape = np.ascontiguousarray(
            tetrahedron_coordinates(self._rest_chain).transpose(0, 2, 1), dtype=np.float32)
        along = np.zeros(self.chain_length)
        # p_i sits at chain 2 i + 2, q_i halfway to p_(i+1): the parameter along the strand
        along[2:] = np.arange(self.chain_length - 2) / (2.0 * (self.point_count - 1))
        self._along = along
        self._pinned_rest = np.ascontiguousarray(self._rest_chain[:, :PINNED].transpose(2, 1, 0))
        self.reset(model)

    def _per_round(self, stiffness: np.ndarray | float) -> np.ndarray:
        """A stiffness per iteration that compounds to ``stiffness`` over the iterations."""
        return 1.0 - (1.0 - np.asarray(stiffness, dtype=np.float64)) ** (
            1.0 / self.physics.iterations)

    def reset(self, model: np.ndarray | None = None) -> None:
        """Back to the start: the anchors' first pose (the rest pose without keyframes) moved
        by ``model`` (identity by default), at rest, ``settle_steps`` steps before t = 0
        (:meth:`advance` takes them first)."""
        self.steps = -self.settle_steps
        model = np.eye(4) if model is None else np.asarray(model, dtype=np.float64)
        start = transform_points(model, self._key_chains[0])
        self._x = np.ascontiguousarray(start.transpose(2, 1, 0), dtype=np.float32)  # (3, C, S)
        self._x[:, :PINNED] = self._pinned(model)
        self._v = np.zeros_like(self._x)
        self._before = np.empty_like(self._x)
        # the solver's scratch rows
        count = self.strand_count
        self._d, self._e1, self._e2, self._e3 = (np.empty((3, count), np.float32)
                                                 for _ in range(4))
        self._length, self._dot = np.empty(count, np.float32), np.empty(count, np.float32)

    @property
    def time(self) -> float:
        """Simulated time: steps times the fixed step."""
        return self.steps * self.physics.time_step

    def step(self, model: np.ndarray, physics: HairPhysics | None = None) -> None:
        """One fixed time step, ``model`` the object's model matrix at the step's end;
        ``physics`` the step's own parameters (default: the simulation's). Its time step,
        iterations, collision margin and structure must be the simulation's (they are the
        simulation's shape); the other parameters may change from step to step."""
        p = self.physics if physics is None else physics
        if physics is not None and physics is not self.physics:
            self._check_fixed(physics)
        dt = np.float32(p.time_step)
        model = np.asarray(model, dtype=np.float64)
        x, v = self._x, self._v
        # gravity and drag toward the wind, the drag implicit: stable at any drag and step
        pull = np.asarray(p.gravity) + p.drag * np.asarray(p.wind)
        v += (dt * pull).astype(np.float32)[:, None, None]
        v *= np.float32(1.0 / (1.0 + p.time_step * p.drag))
        before = self._before
        np.copyto(before, x)
        np.multiply(v, dt, out=v)  # v dt, for a moment
        x += v
        x[:, :PINNED] = self._pinned(model)
        anchors = None
        if p.anchor_stiffness > 0.0:
            pose = structured_chain(interpolate_shapes(self._key_shapes, self._key_times,
                                                       (self.steps + 1) * p.time_step),
                                    self.physics.structure_offset)
            anchors = transform_points(model, pose).transpose(2, 1, 0).astype(np.float32)
            anchor = self._per_round(p.anchor_stiffness * np.clip(
                quadratic(p.anchor_curve, self._along[PINNED:]), 0.0, 1.0))
            anchor = anchor.astype(np.float32)[:, None]
        edge = np.float32(self._per_round(p.edge_stiffness))
        shape = (np.float32(self._per_round(p.bend_stiffness)),  # strand particles (even b)
                 np.float32(self._per_round(p.torsion_stiffness)))  # structural ones (odd b)
        spheres = self._spheres_at(model)
        for _ in range(p.iterations):
            for b, frame, _ in self._order:
                self._solve_particle(b, frame, edge, shape[b % 2])
                strand_particle = b % 2 == 0
                if anchors is not None:
                    x[:, b] += anchor[b - PINNED] * (anchors[:, b] - x[:, b])
                    if strand_particle:  # toward the anchor, at the pose's length from its
                        # parent (no kink where the pull bends it) as far as it is not held
                        a = self._edges[b][0][0]
                        length = np.linalg.norm(anchors[:, b] - anchors[:, a], axis=0)
                        self._project_edge(b, a, length, edge * (1.0 - anchor[b - PINNED, 0]))
                if strand_particle and spheres is not None:
                    self._collide(x[:, b:b + 1], *spheres)
        np.subtract(x, before, out=v)
        v /= dt
        v[:, :PINNED] = 0.0
        self.steps += 1

    def _check_fixed(self, physics: HairPhysics) -> None:
        for name in FIXED_PHYSICS:
            if getattr(physics, name) != getattr(self.physics, name):
                raise ValueError(f"{name} is fixed for a simulation: "
                                 f"{getattr(self.physics, name)!r}, not "
                                 f"{getattr(physics, name)!r}")

    def _pinned(self, model: np.ndarray) -> np.ndarray:
        """The pinned particles ``(3, PINNED, S)`` moved by ``model``: one 3x3 product."""
        rest = self._pinned_rest
        moved = model[:3, :3] @ rest.reshape(3, -1) + model[:3, 3, None]
        return moved.reshape(rest.shape)

    def _project_edge(self, b: int, a: int, rest: np.ndarray, edge: np.float32) -> None:
        """Particle ``b`` moved toward its rest length ``rest`` from particle ``a`` by the
        fraction ``edge`` of the error (a distance projection), in place."""
        if edge <= 0.0:
            return
        x, d, length = self._x, self._d, self._length
        xb = x[:, b]
        np.subtract(xb, x[:, a], out=d)
        _norm(d, length)
        np.maximum(length, 1e-30, out=length)
        np.divide(rest, length, out=length)  # rest / length
        length *= -edge
        length += edge  # edge (1 - rest / length)
        d *= length
        xb -= d

    def _solve_particle(self, b: int, frame: tuple[int, int, int], edge: np.float32,
                        shape: np.float32) -> None:
        """Particle ``b`` of every strand moved by its springs (see :func:`solve_order`); the
        arithmetic in place on preallocated rows (a few dozen whole-array operations a
        particle are the simulation's cost)."""
        x = self._x
        xb = x[:, b]
        d = self._d
        springs = self._edges[b]
        # a structural particle has two edge springs: two rounds of projections nearly meet both
        for a, rest in springs * 2 if len(springs) > 1 else springs:
            self._project_edge(b, a, rest, edge)
        if shape > 0.0:
            back, middle, last = (x[:, i] for i in frame)
            e1, e2, e3, dot = self._e1, self._e2, self._e3, self._dot
            np.subtract(last, middle, out=e1)
            _normalise(e1, dot)
            np.subtract(back, middle, out=e2)
            np.einsum("ij,ij->j", e2, e1, out=dot)
            np.multiply(e1, dot, out=d)
            e2 -= d
            _normalise(e2, dot)
            _cross(e1, e2, e3)
            c = self._shape[b]
            # target - xb = (last - xb) + c0 e1 + c1 e2 + c2 e3
            e1 *= c[0]
            e2 *= c[1]
            e3 *= c[2]
            e1 += e2
            e1 += e3
            e1 += last
            e1 -= xb
            e1 *= shape
            xb += e1

    def _spheres_at(self, model: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """The collision spheres' centres (float32) and radii moved by ``model`` (None: no
        spheres)."""
        if not len(self._spheres):
            return None
        axis_scale = np.linalg.norm(model[:3, :3], axis=0).max()
        centres = transform_points(model, self._spheres[:, :3]).astype(np.float32)
        return centres, self._spheres[:, 3] * axis_scale + self.physics.collision_margin

    @staticmethod
    def _collide(free: np.ndarray, centres: np.ndarray, radii: np.ndarray) -> None:
        """The particles ``free`` ``(3, n, S)`` (a view of the state) pushed radially out of
        every sphere, in place."""
        # out of one sphere may be into an overlapping one: rounds until none is inside
        for _ in range(COLLISION_ROUNDS):
            moved = False
            for centre, radius in zip(centres, radii, strict=True):
                offset = free - centre[:, None, None]
                distance = np.sqrt(offset[0] ** 2 + offset[1] ** 2 + offset[2] ** 2)
                inside = distance < radius
                if inside.any():
                    # radially out to the surface (a particle at the very centre goes up), a
                    # millionth beyond it so float32 rounding cannot leave it inside
                    away = np.float32(radius * (1.0 + 1e-6)) / np.maximum(distance, 1e-30)
                    pushed = centre[:, None, None] + offset * away
                    pushed[1] += np.where(distance > 0.0, 0.0, np.float32(radius * (1 + 1e-6)))
                    np.copyto(free, pushed, where=inside[None])
                    moved = True
            if not moved:
                break

    def advance(self, until: float, model_at: Callable[[float], np.ndarray],
                physics_at: Callable[[float], HairPhysics] | None = None) -> None:
        """Step until the simulated time is ``until`` (rounded to a whole step), ``model_at(t)``
        giving the object's model matrix at time ``t`` and ``physics_at(t)`` (optional) the
        parameters in effect then (each step takes both at its end; the settling steps before
        t = 0 those at 0). Going back in time restarts from the settling, so the state at a
        time never depends on which frames were asked for before."""
        target = round(until / self.physics.time_step)
        if target < self.steps:
            self.reset(model_at(0.0))
        while self.steps < target:
            t = max((self.steps + 1) * self.physics.time_step, 0.0)
            self.step(model_at(t), None if physics_at is None else physics_at(t))

    @property
    def strands(self) -> np.ndarray:
        """The strands' particles in world space, ``(S, P, 3)`` float32, root first."""
        return np.ascontiguousarray(self._x[:, 2::2].transpose(2, 1, 0))

    @property
    def particles(self) -> np.ndarray:
        """Every chain particle, structural ones included, ``(S, 2P + 1, 3)`` world space."""
        return np.ascontiguousarray(self._x.transpose(2, 1, 0))

    @property
    def component_points(self) -> np.ndarray:
        """The strands' particles component-major, ``(3, P, S)`` float32, root first (the
        layout :class:`.hair_tubes.GpuTubes` uploads)."""
        return np.ascontiguousarray(self._x[:, 2::2])

    def component_references(self) -> np.ndarray:
        """:meth:`root_references` component-major, ``(3, S)`` float32."""
        x = self._x
        return x[:, 1] - 0.5 * (x[:, 0] + x[:, 2])

    def root_references(self) -> np.ndarray:
        """``(S, 3)``: a direction across each strand's root that turns with the object (from
        the pinned virtual segment to its structural particle): the first ring's orientation
        for the tube builder, so rings do not jump round as the strands swing."""
        return np.ascontiguousarray(self.component_references().T)

    def kinetic_energy(self) -> float:
        """Half the sum of the free particles' squared speeds (unit masses)."""
        v = self._v[:, PINNED:].astype(np.float64)
        return 0.5 * float((v * v).sum())
