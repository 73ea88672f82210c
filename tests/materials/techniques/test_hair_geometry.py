"""Cartoon hair geometry (Costigan 4.1-4.3.2): strand files, strands grown on builtin:head, the
Catmull-Rom smoothing and the tube meshes (counts, watertight, taper, outward normals, no twist)."""

import json

import numpy as np
import pytest
import trimesh

from deferred.errors import InputError
from deferred.materials.techniques.hair_clumps import strand_clumps
from deferred.materials.techniques.hair_poses import PolylineShapes, interpolate_shapes
from deferred.materials.techniques.hair_strands import (
    COMBED_TURN,
    catmull_rom_weights,
    grow_strands,
    interpolate_keyframes,
    load_strands,
    sample_spline,
    scalp_roots,
)
from deferred.materials.techniques.hair_tubes import (
    GpuTubes,
    build_tubes,
    tube_triangle_count,
    tube_vertex_count,
)
from deferred.scene.builtin_meshes import builtin_head, builtin_head_spheres

RNG = np.random.default_rng(7)


def wavy_strands(count=6, points=7):
    """Smooth curved strands (no kinks sharper than the tubes' radius can follow)."""
    t = np.linspace(0.0, 1.0, points)
    phase = RNG.uniform(0, 2 * np.pi, count)[:, None]
    x = 0.02 * np.sin(3.0 * t[None] + phase)
    y = 0.15 * t[None] + 0.0 * phase
    z = 0.02 * np.cos(2.0 * t[None] + phase)
    return np.stack([x, y, z], axis=-1) + RNG.normal(size=(count, 1, 3))


# --------------------------------------------------------------------------- tubes

@pytest.mark.parametrize("samples,sides", [(8, 8), (5, 3), (12, 6)])
def test_tube_counts_and_watertight(samples, sides):
    strands = wavy_strands(5)
    tubes = build_tubes(strands, samples, sides, radius=0.004, taper=(0.0, -0.5, 1.0))
    assert len(tubes.positions) == 5 * samples * sides + 5 * 2 == tube_vertex_count(5, samples,
                                                                                    sides)
    assert len(tubes.indices) == tube_triangle_count(5, samples, sides)
    mesh = trimesh.Trimesh(tubes.positions, tubes.indices, process=False)
    # every edge is shared by exactly two triangles, in opposite directions
    edges = np.sort(mesh.edges, axis=1)
    _, uses = np.unique(edges, axis=0, return_counts=True)
    assert (uses == 2).all()
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.volume > 0.0  # counter-clockwise seen from outside
    assert tubes.strand_ids.max() == 4 and len(tubes.strand_ids) == len(tubes.positions)
    assert tubes.along.min() == 0.0 and tubes.along.max() == 1.0


def test_tube_radii_follow_the_quadratic():
    # a straight strand along z: the spline is the axis, each ring's distance from it its radius
    strand = np.stack([np.zeros(5), np.zeros(5), np.linspace(0.0, 0.2, 5)], axis=1)[None]
    taper, radius, samples, sides = (-0.6, 0.2, 0.9), 0.01, 9, 7
    tubes = build_tubes(strand, samples, sides, radius=radius, taper=taper)
    rings = tubes.positions[:samples * sides].reshape(samples, sides, 3)
    distance = np.linalg.norm(rings[..., :2], axis=-1)
    x = np.linspace(0.0, 1.0, samples)
    want = radius * (taper[0] * x * x + taper[1] * x + taper[2])
    np.testing.assert_allclose(distance, np.repeat(want[:, None], sides, axis=1), rtol=1e-5)
    # the rings sit on the spline's samples (Ogre's one-sided end tangents slow its ends)
    np.testing.assert_allclose(rings[:, 0, 2], sample_spline(strand, samples)[0, :, 2],
                               atol=1e-6)
    # a taper below zero closes the tube to a point instead of turning it inside out
    pointed = build_tubes(strand, samples, sides, radius=radius, taper=(0.0, -2.0, 1.0))
    tip = pointed.positions[(samples - 1) * sides:samples * sides]
    np.testing.assert_allclose(np.linalg.norm(tip[:, :2], axis=1), 0.0, atol=1e-7)


@pytest.mark.parametrize("normals", ["averaged", "swept"])
def test_tube_normals_point_outward(normals):
    strands = wavy_strands(8)
    samples, sides = 10, 6
    tubes = build_tubes(strands, samples, sides, radius=0.006, taper=(0.3, -1.0, 1.0),
                        normals=normals)
    per = samples * sides + 2
    positions = tubes.positions.reshape(8, per, 3).astype(np.float64)
    vertex_normals = tubes.normals.reshape(8, per, 3).astype(np.float64)
    np.testing.assert_allclose(np.linalg.norm(vertex_normals, axis=-1), 1.0, atol=1e-5)
    rings = positions[:, :-2].reshape(8, samples, sides, 3)
    centre = rings.mean(axis=2, keepdims=True)  # a ring's centroid is its spline point
    outward = ((rings - centre) * vertex_normals[:, :-2].reshape(rings.shape)).sum(-1)
    assert (outward > 0.0).all()  # taper 0.3 - 1 + 1 > 0: no ring is a point
    along = positions[:, per - 1] - positions[:, per - 2]  # cap centres: root and tip
    assert ((vertex_normals[:, -2] * along).sum(-1) < 0.0).all()
    assert ((vertex_normals[:, -1] * along).sum(-1) > 0.0).all()


def test_averaged_normals_are_the_triangles_area_weighted_mean():
    tubes = build_tubes(wavy_strands(3), 7, 5, radius=0.01, taper=(0.0, -0.5, 1.0))
    p, f = tubes.positions.astype(np.float64), tubes.indices
    face = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    reference = np.zeros_like(p)
    for corner in range(3):
        np.add.at(reference, f[:, corner], face)
    reference /= np.linalg.norm(reference, axis=1, keepdims=True)
    np.testing.assert_allclose(tubes.normals, reference, atol=2e-5)


def test_tubes_do_not_twist_along_a_planar_strand():
    # a strand bending in the xy plane: the rotation-minimising frame that starts along z
    # stays along z, so every ring's first vertex is displaced along z only
    angle = np.linspace(0.0, 2.0, 9)
    strand = np.stack([np.sin(angle), 1.0 - np.cos(angle), np.zeros(9)], axis=1)[None] * 0.1
    samples, sides = 16, 8
    tubes = build_tubes(strand, samples, sides, radius=0.005, taper=(0.0, 0.0, 1.0),
                        reference=np.array([[0.0, 0.0, 1.0]]))
    rings = tubes.positions[:samples * sides].reshape(samples, sides, 3)
    first = rings[:, 0] - rings.mean(axis=1)
    np.testing.assert_allclose(first[:, :2], 0.0, atol=1e-6)
    np.testing.assert_allclose(first[:, 2], 0.005, rtol=1e-4)


def test_catmull_rom_passes_through_the_points_with_catmull_rom_tangents():
    points = RNG.normal(size=(1, 5, 3))
    sampled = sample_spline(points, 9)  # every other sample is a control point
    np.testing.assert_allclose(sampled[0, ::2], points[0], atol=1e-12)
    # midpoint of an inner segment: Hermite at u = 1/2 with tangents (P[k+1] - P[k-1]) / 2
    p = points[0]
    m1, m2 = (p[2] - p[0]) / 2, (p[3] - p[1]) / 2
    want = 0.5 * p[1] + 0.125 * m1 + 0.5 * p[2] - 0.125 * m2
    np.testing.assert_allclose(sampled[0, 3], want, atol=1e-12)
    slope = catmull_rom_weights(5, 9, derivative=True) @ p
    np.testing.assert_allclose(slope[2], m1 * 4, atol=1e-12)  # d/dt with t over [0, 1]


def test_keyframes_interpolate_through_each_key():
    keys = RNG.normal(size=(4, 2, 3, 3))
    times = np.array([0.0, 0.5, 1.5, 2.0])
    for key, time in zip(keys, times, strict=True):
        np.testing.assert_allclose(interpolate_keyframes(keys, times, time), key, atol=1e-12)
    between = interpolate_keyframes(keys, times, 1.0)
    assert not np.allclose(between, keys[1]) and not np.allclose(between, keys[2])
    np.testing.assert_allclose(interpolate_keyframes(keys, times, 9.0), keys[-1])


def test_shapes_interpolate_through_each_key_keeping_lengths_and_bends():
    """interpolate_shapes (the anchors' poses, 4.2.3) passes through every key, keeps each
    segment's length where the keys agree, and bends no more than the keys do where they
    mirror each other (a strand bent left, then right: halfway, straight)."""
    keys = np.cumsum(RNG.normal(size=(3, 4, 6, 3)), axis=2)
    times = np.array([0.0, 1.0, 2.5])
    shapes = PolylineShapes.of(keys)
    for key, time in zip(keys, times, strict=True):
        np.testing.assert_allclose(interpolate_shapes(shapes, times, time), key, atol=1e-9)
    angle = np.linspace(0.0, 1.2, 6)[None, :]
    bent = np.stack([np.sin(angle), np.cos(angle), 0.0 * angle], axis=-1)  # unit segments
    left = np.concatenate([np.zeros((1, 1, 3)), np.cumsum(bent, axis=1)], axis=1)
    right = left * [-1.0, 1.0, 1.0]
    mirrored = PolylineShapes.of(np.stack([left, right]))
    halfway = interpolate_shapes(mirrored, np.array([0.0, 1.0]), 0.5)
    np.testing.assert_allclose(np.linalg.norm(np.diff(halfway, axis=1), axis=-1), 1.0)
    np.testing.assert_allclose(halfway[0, :, 0], 0.0, atol=1e-12)  # straight up
    points = interpolate_keyframes(np.stack([left, right]), np.array([0.0, 1.0]), 0.5)
    assert np.linalg.norm(np.diff(points, axis=1), axis=-1).min() < 0.4  # positions: shrunk


def test_clumps_gather_strands_that_run_together():
    """strand_clumps: about clump_size strands a clump, the strands of a grown spiky clump
    (one shared tip) mostly in one clump, deterministic, 1: every strand its own."""
    head = builtin_head(32, 24)
    roots = scalp_roots(head, 120, seed=4)
    spiky = grow_strands(roots, 0.15, 6, "spiky", seed=4, clump_size=6)
    clumps = strand_clumps(spiky, 6)
    np.testing.assert_array_equal(clumps, strand_clumps(spiky, 6))
    assert clumps.min() == 0 and 12 <= clumps.max() + 1 <= 28
    _, tip_groups = np.unique(spiky[:, -1].round(9), axis=0, return_inverse=True)
    together = [len(np.unique(clumps[tip_groups.ravel() == g])) == 1
                for g in range(tip_groups.max() + 1)]
    assert np.mean(together) > 0.6  # most spikes are one clump (a big one may split)
    np.testing.assert_array_equal(strand_clumps(spiky, 1), np.arange(120))


# --------------------------------------------------------------------------- head and growing

def test_head_scalp_lies_on_its_collision_spheres():
    head = builtin_head(32, 24)
    spheres = builtin_head_spheres()
    p = head.positions.astype(np.float64)
    distance = np.linalg.norm(p[:, None] - spheres[None, :, :3], axis=2) - spheres[None, :, 3]
    assert distance.min(axis=1).min() > -1e-6  # no vertex inside the union of the spheres
    scalp = head.comb[:, 3] > 0.5
    assert 0.2 < scalp.mean() < 0.7
    # the scalp is on the cranium sphere, above the face
    np.testing.assert_allclose(np.linalg.norm(p[scalp], axis=1), 0.1, rtol=1e-4)
    assert p[scalp, 1].mean() > 0.02 and p[~scalp, 1].mean() < 0.0


@pytest.mark.parametrize("style", ["combed", "spiky"])
def test_grown_strands_are_deterministic_and_outside_the_head(style):
    head, spheres = builtin_head(32, 24), builtin_head_spheres()
    roots = scalp_roots(head, 120, seed=5)
    again = scalp_roots(head, 120, seed=5)
    np.testing.assert_array_equal(roots.positions, again.positions)
    # roots on the painted scalp: the cranium (a 32 x 24 sphere's chords lie within 1% of it)
    np.testing.assert_allclose(np.linalg.norm(roots.positions, axis=1), 0.1, rtol=1e-2)
    strands = grow_strands(roots, 0.12, 6, style, seed=5, spheres=spheres)
    assert strands.shape == (120, 7, 3)
    np.testing.assert_array_equal(strands, grow_strands(roots, 0.12, 6, style, seed=5,
                                                        spheres=spheres))
    assert not np.array_equal(strands, grow_strands(roots, 0.12, 6, style, seed=6,
                                                    spheres=spheres))
    inner = strands[:, 1:].reshape(-1, 3)
    distance = np.linalg.norm(inner[:, None] - spheres[None, :, :3], axis=2) - spheres[:, 3]
    assert distance.min() > 0.0


def test_combed_strands_fall_away_from_the_parting_and_spiky_ones_clump():
    head = builtin_head(32, 24)
    roots = scalp_roots(head, 200, seed=2)
    combed = grow_strands(roots, 0.15, 8, "combed", seed=2, spheres=builtin_head_spheres(),
                          parting=0.3)
    assert (combed[:, -1, 1] < combed[:, 0, 1]).mean() > 0.95  # gravity
    # over the head without knees: each segment turns at most COMBED_TURN from the last
    segments = np.diff(combed, axis=1)
    segments /= np.linalg.norm(segments, axis=-1, keepdims=True)
    turns = np.degrees(np.arccos(np.clip((segments[:, 1:] * segments[:, :-1]).sum(-1), -1, 1)))
    assert turns.max() <= COMBED_TURN + 1e-6
    half_width = np.abs(roots.positions[:, 0]).max()
    side = np.sign(roots.positions[:, 0] - 0.3 * half_width)
    far = np.abs(roots.positions[:, 0] - 0.3 * half_width) > 0.01
    assert (np.sign(combed[far, 3, 0] - combed[far, 0, 0]) == side[far]).mean() > 0.9
    spiky = grow_strands(roots, 0.15, 8, "spiky", seed=2, clump_size=8)
    tips = np.unique(spiky[:, -1].round(9), axis=0)
    assert len(tips) == 25  # strands of a clump share one tip: a spike


# --------------------------------------------------------------------------- strand files

def test_json_and_obj_strand_files_load(tmp_path):
    strands = [[[0, 0, 0], [0, 1, 0], [0, 2, 0]], [[1, 0, 0], [1, 1, 0], [1, 2, 0.5]]]
    path = tmp_path / "hair.json"
    path.write_text(json.dumps({"strands": strands}))
    np.testing.assert_array_equal(load_strands(path), np.array(strands, dtype=np.float64))
    obj = tmp_path / "hair.obj"
    # one polyline as an 'l' per edge (as Blender writes it), one as a single 'l'
    obj.write_text("# hair\nv 0 0 0\nv 0 1 0\nv 0 2 0\nv 1 0 0\nv 1 1 0\nv 1 2 0.5\n"
                   "l 1 2\nl 2 3\nl 4 5 6\n")
    np.testing.assert_array_equal(load_strands(obj), np.array(strands, dtype=np.float64))
    # strands of different point counts are resampled by arc length to the largest count
    path.write_text(json.dumps({"strands": [[[0, 0, 0], [0, 2, 0]], strands[0]]}))
    loaded = load_strands(path)
    assert loaded.shape == (2, 3, 3)
    np.testing.assert_allclose(loaded[0], strands[0])


@pytest.mark.parametrize("name,text,says", [
    ("a.json", '{"strands": [[[0, 0, 0], [1, 2]]]}', "strand 0 point 1 must be 3 numbers"),
    ("b.json", '{"strands": []}', "non-empty list"),
    ("c.json", '{"strands": [[]]}', "strand 0 has 0 points"),
    ("d.json", '{"strands": [[[0, 0, 0], [0, 1, 0]], [[0, 0, 0]]]}', "strand 1 has 1 point;"),
    ("e.json", '{"strands": [[[0, 0, 0], [0, NaN, 0]]]}', "not a finite number"),
    ("f.json", '{"strands": [[[0, 0, 0], [0, 1, 0]', "not valid JSON"),
    ("g.json", '{"hair": []}', 'expected an object {"strands"'),
    ("h.json", '{"strands": [[[0, 0, 0], [0, 0, 0]]]}', "repeats a point"),
    ("i.obj", "v 0 0 0\nv 0 1 0\nl 1 3\n", "line 3: vertex 3 does not exist"),
    ("j.obj", "v 0 0 0\nv 0 1 0\n", "no 'l' polylines"),
    ("k.obj", "v 0 0 x\nl 1 2\n", "line 1: a vertex needs 3 numbers"),
    ("l.obj", "v 0 0 0\nl 1\n", "line 2: a polyline needs at least 2 points"),
    ("m.txt", "0 0 0", "unsupported strand file format"),
])
def test_bad_strand_files_are_one_line_errors_naming_the_file(tmp_path, name, text, says):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(InputError) as caught:
        load_strands(path)
    message = str(caught.value)
    assert "\n" not in message and name in message and says in message, message


def test_a_missing_strand_file_is_named(tmp_path):
    with pytest.raises(InputError, match="nowhere.json: strand file not found"):
        load_strands(tmp_path / "nowhere.json")


def test_strand_files_asking_for_too_much_are_refused(tmp_path, monkeypatch):
    """Strands are resampled to the longest one's points: a file whose strands times that count
    pass MAX_STRAND_POINTS is refused before the array is made; an integer too large for a
    float is a bad point, not an OverflowError."""
    import json

    from deferred.errors import InputError
    from deferred.materials.techniques import hair_strands

    monkeypatch.setattr(hair_strands, "MAX_STRAND_POINTS", 100)
    many = [[[0, 0, 0], [0, 1, 0]]] * 10 + [[[0, 0, k] for k in range(20)]]
    (tmp_path / "many.json").write_text(json.dumps({"strands": many}))
    with pytest.raises(InputError, match=r"11 strands resampled to the longest one's 20 points "
                                         r"are 220 points, more than the 100 held"):
        hair_strands.load_strands(tmp_path / "many.json")
    (tmp_path / "huge.json").write_text('{"strands": [[[0, 0, 0], [' + "9" * 400 + ', 0, 0]]]}')
    with pytest.raises(InputError, match="point 1 must be 3 numbers"):
        hair_strands.load_strands(tmp_path / "huge.json")


# --------------------------------------------------------------------------- tubes on the GPU

def gpu_tubes(gl, strands, samples, sides, radius, taper, reference, to_object=None):
    """:class:`GpuTubes`' positions and normals ``(V, 3)`` each, read back."""
    from deferred.gl.shaderlib import ShaderLibrary

    strands = np.asarray(strands, np.float32)
    builder = GpuTubes(gl.ctx, len(strands), strands.shape[1], samples, sides)
    vertices = gl.ctx.buffer(reserve=builder.vertex_count * 24)
    try:
        builder.upload(strands.transpose(2, 1, 0), np.asarray(reference).T)
        builder.build(ShaderLibrary(gl.ctx, 430), vertices, radius, taper, to_object)
        out = np.frombuffer(vertices.read(), np.float32).reshape(-1, 6)
    finally:
        builder.release()
        vertices.release()
    return out[:, :3], out[:, 3:]


@pytest.mark.parametrize("samples,sides,taper", [(8, 8, (0.0, -1.0, 1.0)), (2, 3, (0.0, 0.0, 1.0)),
                                                 (13, 16, (0.3, -1.0, 1.0)),
                                                 (9, 5, (0.0, -2.0, 1.0))])
def test_gpu_tubes_are_the_numpy_tubes(gl, samples, sides, taper):
    """The compute shaders build what build_tubes builds (same vertex order, so the same
    indices make the same watertight tubes with the same radii and caps), to float32
    rounding. The strands lie within a head's size of the origin: the triangles' edges are
    differences of positions, so both builds' rounding grows with the distance over the
    radius (a metre away, unit normals differ by up to 2e-4)."""
    if not gl.features.compute_shaders:
        pytest.skip("no compute shaders")
    strands = wavy_strands(9)
    strands = strands - strands[:, :1] + 0.08 * RNG.normal(size=(9, 1, 3))
    reference = RNG.normal(size=(9, 3))
    want = build_tubes(strands, samples, sides, 0.006, taper, reference)
    positions, normals = gpu_tubes(gl, strands, samples, sides, 0.006, taper, reference)
    assert len(positions) == tube_vertex_count(9, samples, sides)
    np.testing.assert_allclose(positions, want.positions, atol=1e-7)
    np.testing.assert_allclose(normals, want.normals, atol=5e-5)
    # a placement with a mirror and a non-uniform scale: positions through the matrix,
    # normals through its inverse transpose (still outward: the mirror turns them back)
    model = np.diag([1.5, -0.7, 1.2, 1.0])
    model[:3, 3] = (0.03, 0.01, -0.02)
    positions, normals = gpu_tubes(gl, strands, samples, sides, 0.006, taper, reference, model)
    moved = want.positions @ model[:3, :3].T + model[:3, 3]
    turned = want.normals @ np.linalg.inv(model[:3, :3])
    turned /= np.maximum(np.linalg.norm(turned, axis=1, keepdims=True), 1e-12)
    np.testing.assert_allclose(positions, moved, atol=2e-6)
    np.testing.assert_allclose(normals, turned, atol=5e-5)


def test_gpu_tubes_refuse_points_of_another_shape(gl):
    if not gl.features.compute_shaders:
        pytest.skip("no compute shaders")
    builder = GpuTubes(gl.ctx, 4, 6, 8, 6)
    try:
        with pytest.raises(ValueError, match=r"points must be \(3, 6, 4\)"):
            builder.upload(np.zeros((3, 5, 4)), np.zeros((3, 4)))
    finally:
        builder.release()
