"""Cartoon hair dynamics (Costigan 4.2.2-4.2.4): stiff strands hold their style, loose ones
hang, roots follow the object, no particle ends inside a collision sphere, anchors pull onto the
keyframed pose, and the same inputs give the same bits."""

import numpy as np
import pytest

from deferred.materials.techniques.hair_dynamics import (
    HairPhysics,
    HairSimulation,
    transform_points,
)

LENGTH = 0.1


def horizontal_strands(count=3, points=8):
    """Strands sticking out sideways along +x from roots spread along z: cantilevers."""
    strands = np.zeros((count, points, 3))
    strands[:, :, 0] = np.linspace(0.0, LENGTH, points)
    strands[:, :, 2] = np.linspace(0.0, 0.05, count)[:, None]
    return strands


def run(sim, seconds):
    sim.advance(seconds, lambda t: np.eye(4))
    return sim.strands.astype(np.float64)


def test_a_stiff_strand_settles_near_its_rest_shape():
    rest = horizontal_strands()
    sim = HairSimulation(rest, HairPhysics(edge_stiffness=1.0, bend_stiffness=1.0,
                                           torsion_stiffness=1.0))
    strands = run(sim, 3.0)
    assert sim.kinetic_energy() < 1e-10
    assert np.abs(strands - rest).max() < 0.01 * LENGTH


def test_a_loose_strand_hangs():
    rest = horizontal_strands()
    sim = HairSimulation(rest, HairPhysics(bend_stiffness=0.0, torsion_stiffness=0.0))
    strands = run(sim, 6.0)  # a pendulum, damped by the air's drag
    assert sim.kinetic_energy() < 1e-6
    drop = strands[:, 0] - strands[:, -1]
    np.testing.assert_allclose(drop[:, 1], LENGTH, rtol=0.02)  # straight down, full length
    assert np.abs(drop[:, [0, 2]]).max() < 0.02 * LENGTH


@pytest.mark.slow
def test_stiffness_grades_the_sag():
    rest = horizontal_strands(1)
    sags = []
    for stiffness in (1.0, 0.9, 0.5, 0.0):
        sim = HairSimulation(rest, HairPhysics(bend_stiffness=stiffness,
                                               torsion_stiffness=stiffness))
        sags.append(-run(sim, 3.0)[0, -1, 1])
    assert sags == sorted(sags) and sags[0] < 1e-6 and sags[-1] > 0.09


def moving_model(t):
    angle = 1.3 * np.sin(3.0 * t)
    c, s = np.cos(angle), np.sin(angle)
    model = np.eye(4)
    model[:3, :3] = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) * 1.5
    model[:3, 3] = [0.2 * t, np.sin(5.0 * t) * 0.1, -0.3]
    return model


def test_roots_follow_the_object_transform_exactly():
    rest = horizontal_strands(4)
    sim = HairSimulation(rest, HairPhysics(bend_stiffness=0.3), model=moving_model(0.0))
    for frame in range(1, 40):
        sim.advance(frame / 30.0, moving_model)
        want = transform_points(moving_model(sim.time), rest[:, 0])
        np.testing.assert_allclose(sim.strands[:, 0], want, atol=2e-7)


def test_no_particle_ends_inside_a_collision_sphere():
    # loose strands rooted on top of a ball fall onto it while the ball swings
    count = 40
    rng = np.random.default_rng(3)
    direction = rng.normal(size=(count, 3)) * [1.0, 0.3, 1.0] + [0.0, 1.0, 0.0]
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    radius = 0.1
    t = np.linspace(0.0, 1.0, 8)[None, :, None]
    sideways = np.cross(direction, [0.0, 0.0, 1.0])
    rest = direction[:, None] * radius + t * 0.15 * (direction + sideways)[:, None]
    spheres = np.array([[0.0, 0.0, 0.0, radius], [0.0, -0.12, 0.05, 0.07]])
    sim = HairSimulation(rest, HairPhysics(bend_stiffness=0.05, torsion_stiffness=0.05,
                                           wind=(1.0, 0.0, 0.0)), spheres=spheres)

    def model_at(time):
        model = np.eye(4)
        model[0, 3] = 0.1 * np.sin(4.0 * time)
        return model

    touched = False
    for frame in range(1, 61):
        sim.advance(frame / 30.0, model_at)
        local = sim.strands[:, 1:].astype(np.float64) - model_at(sim.time)[:3, 3]
        gap = np.linalg.norm(local[:, :, None] - spheres[:, :3], axis=-1) - spheres[:, 3]
        assert gap.min() >= -1e-6 * radius, (frame, gap.min())
        touched |= gap.min() < 1e-3
    assert touched  # the strands did reach the ball


def test_anchors_pull_a_loose_strand_onto_the_keyframe_pose():
    rest = horizontal_strands(3)
    pose = rest.copy()
    pose[:, :, 1] = np.linspace(0.0, 0.06, 8)  # the keyframe: raised toward the tip
    distances = []
    for stiffness in (0.0, 0.1, 0.5, 0.9, 1.0):
        sim = HairSimulation(rest, HairPhysics(bend_stiffness=0.0, torsion_stiffness=0.0,
                                               anchor_stiffness=stiffness),
                             keyframes=pose[None])
        distances.append(np.abs(run(sim, 3.0) - pose).max())
    assert distances == sorted(distances, reverse=True)
    assert distances[0] > 0.05 and distances[-1] < 1e-6


def test_anchor_stiffness_follows_the_quadratic_along_the_strand():
    rest = horizontal_strands(1)
    pose = rest.copy()
    pose[:, :, 1] = 0.03
    pose[:, 0, 1] = 0.0
    physics = HairPhysics(bend_stiffness=0.0, torsion_stiffness=0.0, anchor_stiffness=1.0,
                          anchor_curve=(1.0, 0.0, 0.0))  # 0 at the root, 1 at the tip
    strands = run(HairSimulation(rest, physics, keyframes=pose[None]), 2.0)
    np.testing.assert_allclose(strands[0, -1], pose[0, -1], atol=1e-6)  # held at the tip
    assert np.abs(strands[0, 1] - pose[0, 1]).max() > 1e-3  # free near the root


def test_anchors_move_along_the_keyframes_over_time():
    rest = horizontal_strands(2)
    keys = np.stack([rest + [0.0, dy, 0.0] for dy in (0.0, 0.05, -0.02)])
    keys[:, :, 0] = rest[:, 0]  # the roots stay
    times = [0.0, 0.5, 1.0]
    sim = HairSimulation(rest, HairPhysics(anchor_stiffness=1.0, bend_stiffness=0.0,
                                           torsion_stiffness=0.0), keyframes=keys,
                         key_times=times)
    for key, time in zip(keys, times, strict=True):
        np.testing.assert_allclose(run(sim, time), key, atol=1e-6)


@pytest.mark.slow
def test_the_same_inputs_give_the_same_bits():
    rest = horizontal_strands(5)
    pose = rest + [0.0, 0.02, 0.0]
    physics = HairPhysics(bend_stiffness=0.4, torsion_stiffness=0.7, anchor_stiffness=0.2,
                          wind=(0.5, 0.0, -1.0), iterations=3)
    spheres = np.array([[0.05, -0.05, 0.0, 0.04]])

    def simulate():
        sim = HairSimulation(rest, physics, spheres=spheres, keyframes=np.stack([rest, pose]),
                             model=moving_model(0.0))
        sim.advance(1.0, moving_model)
        return sim

    first, second = simulate(), simulate()
    assert first.strands.tobytes() == second.strands.tobytes()
    # going back in time restarts: the state at a time does not depend on the frames before
    first.advance(1.5, moving_model)
    first.advance(1.0, moving_model)
    assert first.strands.tobytes() == second.strands.tobytes()


@pytest.mark.parametrize("field", ["edge_stiffness", "bend_stiffness", "torsion_stiffness",
                                   "anchor_stiffness"])
def test_stiffness_outside_0_1_is_refused(field):
    with pytest.raises(ValueError, match=field):
        HairPhysics(**{field: 1.5})


def combed_head(count=40):
    """Combed strands on builtin:head and its collision spheres: a style that is not at rest
    (gravity pulls it down onto the head at once)."""
    from deferred.materials.techniques.hair_strands import grow_strands, scalp_roots
    from deferred.scene.builtin_meshes import builtin_head, builtin_head_spheres

    spheres = builtin_head_spheres()
    return grow_strands(scalp_roots(builtin_head(), count, 3), 0.15, 7, "combed", 3, spheres), \
        spheres


def test_settling_starts_the_hair_at_rest():
    """``settle_steps`` run before t = 0 with the object still: combed hair, which falls
    onto the head when it starts from its style, moves hardly at all after t = 0 then."""
    rest, spheres = combed_head()
    physics = HairPhysics(bend_stiffness=0.5, torsion_stiffness=0.5)
    energies, moved = {}, {}
    for settle in (0, 180):
        sim = HairSimulation(rest, physics, spheres=spheres, settle_steps=settle)
        sim.advance(0.0, lambda t: np.eye(4))
        assert sim.steps == 0 and sim.time == 0.0
        start = sim.strands.copy()
        energy = []
        for step in range(1, 13):  # the first 0.2 s
            sim.advance(step * physics.time_step, lambda t: np.eye(4))
            energy.append(sim.kinetic_energy())
        energies[settle], moved[settle] = max(energy), np.abs(sim.strands - start).max()
    assert energies[180] < 0.01 * energies[0]
    assert moved[180] < 0.1 * moved[0]


def test_settling_holds_the_object_at_its_placement_at_0():
    rest, spheres = combed_head(10)
    sim = HairSimulation(rest, HairPhysics(), spheres=spheres, settle_steps=30,
                         model=moving_model(0.0))
    asked = []

    def model_at(t):
        asked.append(t)
        return moving_model(t)

    sim.advance(0.0, model_at)
    assert len(asked) == 30 and set(asked) == {0.0}
    roots = transform_points(moving_model(0.0), rest[:, 0])
    np.testing.assert_allclose(sim.strands[:, 0], roots, atol=1e-6)


def test_parameters_may_change_from_step_to_step():
    """``physics_at(t)`` gives each step its parameters (a scene timeline): wind from 0.5 s
    on leaves the strands as they were before it and blows them after; the structure a
    simulation is built with cannot change."""
    rest = horizontal_strands(4)
    still = HairPhysics(bend_stiffness=0.3, torsion_stiffness=0.3)
    windy = HairPhysics(bend_stiffness=0.3, torsion_stiffness=0.3, wind=(0.0, 0.0, 6.0))

    def physics_at(t):
        return still if t < 0.5 - 1e-9 else windy

    plain, blown = HairSimulation(rest, still), HairSimulation(rest, still)
    for sim, at in ((plain, None), (blown, physics_at)):
        sim.advance(0.45, lambda t: np.eye(4), at)
    assert plain.strands.tobytes() == blown.strands.tobytes()
    for sim, at in ((plain, None), (blown, physics_at)):
        sim.advance(1.0, lambda t: np.eye(4), at)
    assert blown.strands[:, -1, 2].mean() > plain.strands[:, -1, 2].mean() + 0.01
    with pytest.raises(ValueError, match="time_step is fixed"):
        plain.step(np.eye(4), HairPhysics(time_step=0.01))


def bend_angles(strands: np.ndarray) -> np.ndarray:
    """Degrees between consecutive segments, ``(S, P - 2)``."""
    segments = np.diff(np.asarray(strands, np.float64), axis=1)
    segments /= np.linalg.norm(segments, axis=-1, keepdims=True)
    cosine = (segments[:, 1:] * segments[:, :-1]).sum(-1)
    return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


ANCHORED_BEND_BOUND = 15.0  # degrees past the style's own sharpest bend


def test_anchored_strands_sweep_between_partings_without_kinks():
    """examples/cartoon_hair/anchored_head.toml: anchors pull the hair from a left parting to a
    right one and back over 2 s. The anchors blend the poses' bends, not their points' positions
    (which, halfway between combed left and combed right, fold strands through the head into
    knees of up to 176 degrees), and pull each particle at its pose's length from its parent:
    at 24 frames a second the sharpest bend of any strand stays within ANCHORED_BEND_BOUND of
    the sharpest in the keyframed styles."""
    from locations import ROOT

    from deferred.materials.cartoon_hair.state import hair_physics
    from deferred.scene.loader import load_scene

    scene = load_scene(ROOT / "examples" / "cartoon_hair" / "anchored_head.toml")
    obj = scene.objects[0]
    material, params = obj.material, obj.material.params
    rest = material.rest_strands(obj)
    keys = material.keyframe_strands(rest.shape)
    sim = HairSimulation(rest, hair_physics(params), material.spheres(obj), keys,
                         params.key_times, obj.model)
    styled = max(bend_angles(key).max() for key in keys)
    sharpest = 0.0
    for frame in range(49):
        sim.advance(frame / 24.0, lambda t: obj.model)
        sharpest = max(sharpest, bend_angles(sim.strands).max())
    assert styled < 40.0  # the poses themselves are smooth (grown combed hair slides over the head)
    assert sharpest <= styled + ANCHORED_BEND_BOUND, (sharpest, styled)
    assert sharpest > styled  # the sweep does bend them
