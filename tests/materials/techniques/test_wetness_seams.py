"""The wetness mask across UV-chart seams (techniques/uv_seams.py, UVSeams): the seam map checked
against the charts' own UVs of the same surface points, a droplet on a seam wetting both
charts alike (where a plain blend is cut at the chart's edge), and droplets kept to their own
chart."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from locations import ROOT

from deferred.materials.techniques.topology import weld
from deferred.materials.techniques.uv_seams import UVSeams
from deferred.materials.techniques.wetness import (
    Droplet,
    blend_droplet,
    dry_mask,
    footprint_texels,
    random_droplets,
)
from deferred.scene.builtin_meshes import builtin_cube, builtin_plane, builtin_sphere
from deferred.scene.geometry import build_mesh
from deferred.scene.meshes import load_mesh

BUNNY = ROOT / "examples" / "meshes" / "bunny.ply"
CELLS = 8  # grid cells a side of the two-chart square


def left_uv(x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The left half's chart (x <= 0.5): u from 0.05 to 0.45, v from 0.1 to 0.9."""
    return np.stack([0.05 + 0.8 * x, 0.1 + 0.8 * z], -1)


def right_uv(x: np.ndarray, z: np.ndarray, mirrored: bool) -> np.ndarray:
    """The right half's chart (x >= 0.5) in u 0.55 .. 0.95: turned half a turn (its seam edge
    at u = 0.95), or mirrored in u (its seam edge at u = 0.95, v as the left's)."""
    if mirrored:
        return np.stack([0.95 - 0.8 * (x - 0.5), 0.1 + 0.8 * z], -1)
    return np.stack([0.95 - 0.8 * (x - 0.5), 0.9 - 0.8 * z], -1)


def two_chart_square(mirrored: bool):
    """The unit square (y = 0) in two charts cut at x = 0.5; the seam's vertices are stored once
    per chart, as an unwrap stores them."""
    positions, uvs, indices = [], [], []
    half = CELLS // 2
    for side in (0, 1):
        base = len(positions)
        for j in range(CELLS + 1):
            for i in range(half + 1):
                x, z = (side * half + i) / CELLS, j / CELLS
                positions.append((x, 0.0, z))
                uvs.append(left_uv(np.array(x), np.array(z)) if side == 0
                           else right_uv(np.array(x), np.array(z), mirrored))
        for j in range(CELLS):
            for i in range(half):
                a = base + j * (half + 1) + i
                b, c, d = a + 1, a + half + 1, a + half + 2
                indices += [(a, c, b), (b, c, d)]
    return build_mesh("two-chart square", np.array(positions), np.array(indices),
                      uvs=np.array(uvs, np.float64))


def face_at(mesh, x: float, z: float) -> int:
    """A triangle with (x, 0, z) in it."""
    faces = np.asarray(mesh.indices).reshape(-1, 3)
    p = np.asarray(mesh.positions, np.float64)[faces][:, :, [0, 2]]
    for k, (a, b, c) in enumerate(p):
        m = np.array([b - a, c - a]).T
        s, t = np.linalg.solve(m, np.array([x, z]) - a)
        if s >= -1e-9 and t >= -1e-9 and s + t <= 1 + 1e-9:
            return k
    raise AssertionError("no triangle there")


def lookup(mask: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """The texels (nearest) at ``uv`` (..., 2)."""
    size = mask.shape[0]
    j = np.clip(np.floor(uv[..., 0] * size).astype(int), 0, size - 1)
    i = np.clip(np.floor(uv[..., 1] * size).astype(int), 0, size - 1)
    return mask[i, j]


@pytest.mark.parametrize("mirrored", [False, True])
def test_seam_map_takes_a_chart_to_its_neighbour(mirrored):
    """The map over a seam takes a point's UVs in one chart to that surface point's UVs in the
    other, both ways, whether the charts are turned or mirrored."""
    mesh = two_chart_square(mirrored)
    seams = UVSeams(mesh)
    assert seams.chart_count == 2 and seams.laid_out
    assert len(seams.source) == 2 * CELLS  # each seam edge, both ways
    rng = np.random.default_rng(1)
    x, z = rng.uniform(0.3, 0.7, 20), rng.uniform(0.0, 1.0, 20)
    for record in range(len(seams.source)):
        source_is_left = seams.source[record] == seams.face_chart[face_at(mesh, 0.1, 0.5)]
        there = left_uv(x, z) if source_is_left else right_uv(x, z, mirrored)
        expected = right_uv(x, z, mirrored) if source_is_left else left_uv(x, z)
        carried = np.array([seams.carry(record, tuple(p)) for p in there])
        np.testing.assert_allclose(carried, expected, atol=2e-6)  # float32 UVs
        assert bool(seams.mirror[record]) == mirrored


@pytest.mark.slow
def test_seam_map_on_an_unwrapped_mesh():
    """On the bunny's unwrap: each seam record takes its edge's ends to the same ends in the
    chart across, and puts the source's triangle on the far side of the edge there (the
    unfolding), not on top of the target's triangle."""
    mesh = load_mesh(str(BUNNY))
    seams = UVSeams(mesh)
    assert seams.laid_out and len(seams.source) > 0
    assert np.all(seams.source != seams.target)
    faces = np.asarray(mesh.indices).reshape(-1, 3)
    uvs = np.asarray(mesh.uvs, np.float64)
    welded = weld(mesh.positions)
    chart_uv: dict[tuple[int, int], np.ndarray] = {}
    for face, chart in enumerate(seams.face_chart):
        for corner in faces[face]:
            chart_uv[(int(chart), int(welded[corner]))] = uvs[corner]
    checked = 0
    for record in range(len(seams.source)):
        a, b = seams.a[record], seams.b[record]
        for end in (a, b):
            # the welded vertex at this end of the edge, in the source chart
            source_faces = np.flatnonzero(seams.face_chart == seams.source[record])
            corners = faces[source_faces].reshape(-1)
            at = corners[np.abs(uvs[corners, 0] + 1j * uvs[corners, 1] - end) < 1e-9]
            vertex = int(welded[at[0]])
            target_uv = chart_uv[(int(seams.target[record]), vertex)]
            np.testing.assert_allclose(seams.carry(record, (end.real, end.imag)), target_uv,
                                       atol=1e-6)
            checked += 1
    assert checked == 2 * len(seams.source)


@pytest.mark.parametrize("mirrored", [False, True])
def test_droplet_on_a_seam_wets_both_charts_alike(mirrored):
    """A droplet centred on the seam wets the surface about it on both sides alike, in one
    clump whose centre each chart holds in its own UVs; blended plainly (in its own chart's
    UVs alone) it is cut at the seam and the other side stays dry."""
    mesh = two_chart_square(mirrored)
    seams = UVSeams(mesh)
    size = 256
    centre_3d = (0.5, 0.5)
    face = face_at(mesh, 0.49, 0.5)
    radius_world = 0.12
    droplet = Droplet(tuple(left_uv(np.array(0.5), np.array(0.5))), radius_world * 0.8, 0.7,
                      face)
    mask = dry_mask(size)
    seams.blend(mask, droplet)
    plain = dry_mask(size)
    blend_droplet(plain, droplet)
    # surface points within 0.9 of the droplet's radius, on each side of the seam
    rng = np.random.default_rng(2)
    angle = rng.uniform(0, 2 * np.pi, 4000)
    reach = radius_world * 0.9 * np.sqrt(rng.uniform(0, 1, 4000))
    x, z = centre_3d[0] + reach * np.cos(angle), centre_3d[1] + reach * np.sin(angle)
    left, right = x < 0.5 - 1.5 / size / 0.8, x > 0.5 + 1.5 / size / 0.8
    wet_left = lookup(mask, left_uv(x[left], z[left]))
    wet_right = lookup(mask, right_uv(x[right], z[right], mirrored))
    coverage_left = (wet_left[:, 3] > 0).mean()
    coverage_right = (wet_right[:, 3] > 0).mean()
    assert coverage_left > 0.95 and abs(coverage_left - coverage_right) < 0.05
    # one clump: each side's texels hold the droplet's centre in that side's UVs
    np.testing.assert_allclose(wet_left[:, :2] - left_uv(np.array(0.5), np.array(0.5)), 0.0,
                               atol=1e-6)
    np.testing.assert_allclose(wet_right[:, :2] - right_uv(np.array(0.5), np.array(0.5), mirrored),
                               0.0, atol=1e-6)
    np.testing.assert_allclose(wet_right[:, 2], droplet.radius, rtol=1e-6)  # same UV scale
    # the plain blend: cut at the seam
    assert (lookup(plain, right_uv(x[right], z[right], mirrored))[:, 3] > 0).mean() < 0.02


def test_droplet_stays_in_its_chart():
    """A droplet whose UV disc reaches past its chart's edge into a chart packed beside it in
    UV space, but far away on the surface, leaves that chart dry."""
    mesh = two_chart_square(mirrored=False)
    seams = UVSeams(mesh)
    # the left chart's edge at u = 0.45 is the seam; at the droplet's v the right chart's texels
    # from u = 0.55 on are the square's far border x = 1
    droplet = Droplet((0.44, 0.5), 0.2, 0.7, face_at(mesh, 0.49, 0.5))
    kept, plain = dry_mask(128), dry_mask(128)
    seams.blend(kept, droplet)
    blend_droplet(plain, droplet)
    far = right_uv(np.full(50, 0.98), np.linspace(0.4, 0.6, 50), False)
    assert (lookup(plain, far)[:, 3] > 0).all()  # the plain blend wets the far border
    assert (lookup(kept, far)[:, 3] == 0).all()


def test_meshes_without_separate_charts_blend_as_before():
    """One chart (a grid sphere, its pole row of zero-area triangles in none; a plane) or
    charts overlapping in UV space (the cube's faces share the square): the droplets blend
    as before, each once over every texel under it."""
    for mesh in (builtin_sphere(16, 8), builtin_plane(4), builtin_cube()):
        seams = UVSeams(mesh)
        assert not seams.laid_out, mesh.name
        assert seams.chart_texels(64) is None
        droplets = random_droplets(mesh, np.eye(4), 20, 0.2, 0.5, seed=1)
        for droplet in droplets:
            assert seams.copies(droplet) == [(droplet, -1)]
        mask, before = dry_mask(64), dry_mask(64)
        for droplet in droplets:
            seams.blend(mask, droplet)
            blend_droplet(before, droplet)
        np.testing.assert_array_equal(mask, before)
    assert UVSeams(builtin_sphere(16, 8)).chart_count == 1


def test_chart_texels_and_footprint_count_the_copies():
    """Each texel a chart's triangles cover is that chart's, its gutter the nearest chart's;
    the droplet budget counts the copies across seams."""
    mesh = two_chart_square(mirrored=False)
    seams = UVSeams(mesh)
    charts = seams.chart_texels(64)
    left = seams.face_chart[face_at(mesh, 0.1, 0.5)]
    right = seams.face_chart[face_at(mesh, 0.9, 0.5)]
    t = (np.arange(64) + 0.5) / 64
    row = int(0.5 * 64)
    assert (charts[row, (t > 0.06) & (t < 0.44)] == left).all()
    assert (charts[row, (t > 0.56) & (t < 0.94)] == right).all()
    assert (charts[row, (t > 0.46) & (t < 0.46 + 2.5 / 64)] == left).all()  # the gutter
    assert (charts[int(0.02 * 64)] < 0).all()  # far from every chart
    on_seam = Droplet((0.445, 0.5), 0.05, 0.5, face_at(mesh, 0.49, 0.5))
    inside = Droplet((0.2, 0.5), 0.05, 0.5, face_at(mesh, 0.2, 0.5))
    assert len(seams.copies(on_seam)) == 2 and len(seams.copies(inside)) == 1
    one = footprint_texels([on_seam], 64)
    assert footprint_texels([on_seam], 64, seams=seams) == 2 * one
    assert footprint_texels([inside], 64, seams=seams) == footprint_texels([inside], 64)


def write_square_obj(path: Path, mirrored: bool) -> None:
    """The two-chart square as an OBJ, 2 units wide about the origin (facing +y)."""
    mesh = two_chart_square(mirrored)
    lines = [f"v {2 * p[0] - 1:.6f} 0 {2 * p[2] - 1:.6f}" for p in mesh.positions]
    lines += [f"vt {t[0]:.7f} {t[1]:.7f}" for t in mesh.uvs]
    lines += [f"f {a}/{a} {b}/{b} {c}/{c}" for a, b, c in np.asarray(mesh.indices) + 1]
    path.write_text("\n".join(lines) + "\n")


def seam_mismatch(render, scene_dir: Path) -> tuple[float, float]:
    """The wetness view of the square seen from above, 128 px wide with the seam at column
    64: the share of rows where the pixels 3 px apart across the seam differ in wet/dry, and
    the most of that across two lines inside the charts (the droplets' own edges)."""
    from deferred.debug.views import with_material_view
    from deferred.scene.loader import scene_from_dict

    data = {"size": [128, 128], "background": [0.0, 0.0, 0.0], "tonemap": "none",
            "camera": {"position": [0.0, 20.0, 0.0], "target": [0.0, 0.0, 0.0],
                       "up": [0.0, 0.0, -1.0], "fov": 5.8},
            "object": [{"mesh": "square.obj", "material": "shell_fur",
                        "params": {"fur_length": 0.08, "shells": 8, "fins": False,
                                   "gravity": [0.0, 0.0, 0.0], "droplets": 120,
                                   "droplet_radius": 0.12, "droplet_wetness": 1.0,
                                   "seed": 3}}],
            "light": [{"type": "ambient"}]}
    scene = with_material_view(scene_from_dict(data, "square", scene_dir), "shell_fur.wetness")
    result, _ = render(scene)
    wet = result.image[8:120, :, :3].max(-1) > 5
    def differ(a: int) -> float:
        return float((wet[:, a] != wet[:, a + 3]).mean())
    return differ(62), max(differ(30), differ(94))


def test_rendered_clumps_continue_across_the_seam(render, tmp_path, monkeypatch):
    """Rendered (the wetness view, what the shaders read), wet and dry agree across the seam
    about as often as across a line inside a chart; with the seams ignored (the droplets
    blended in their own chart's UVs alone, as before) the wet areas are cut at the seam."""
    write_square_obj(tmp_path / "square.obj", mirrored=True)
    across, inside = seam_mismatch(render, tmp_path)
    assert across <= inside + 0.1, (across, inside)
    monkeypatch.setattr(UVSeams, "laid_out", property(lambda self: False))
    cut, _ = seam_mismatch(render, tmp_path)
    assert cut > across + 0.2, (cut, across)


def quadrant_uv(x: np.ndarray, z: np.ndarray, qx: int, qz: int) -> np.ndarray:
    """Quadrant (qx, qz)'s chart: turned half a turn, in the UV slot diagonally opposite."""
    return np.stack([0.95 - 0.5 * (1 - qx) - 0.8 * (x - 0.5 * qx),
                     0.95 - 0.5 * (1 - qz) - 0.8 * (z - 0.5 * qz)], -1)


def test_a_droplet_reaches_a_chart_meeting_its_own_at_a_corner():
    """The unit square in four charts, one a quadrant: a droplet on the corner where they meet
    wets all four, the quadrant diagonally opposite (which shares no edge with the droplet's)
    through a chart beside both."""
    positions, uvs, indices = [], [], []
    half = CELLS // 2
    for qx in (0, 1):
        for qz in (0, 1):
            base = len(positions)
            for j in range(half + 1):
                for i in range(half + 1):
                    x, z = (qx * half + i) / CELLS, (qz * half + j) / CELLS
                    positions.append((x, 0.0, z))
                    uvs.append(quadrant_uv(np.array(x), np.array(z), qx, qz))
            for j in range(half):
                for i in range(half):
                    a = base + j * (half + 1) + i
                    b, c, d = a + 1, a + half + 1, a + half + 2
                    indices += [(a, c, b), (b, c, d)]
    mesh = build_mesh("quadrants", np.array(positions), np.array(indices),
                      uvs=np.array(uvs, np.float64))
    seams = UVSeams(mesh)
    assert seams.chart_count == 4 and seams.laid_out
    centre = quadrant_uv(np.array(0.49), np.array(0.49), 0, 0)
    droplet = Droplet(tuple(centre), 0.08, 0.6, face_at(mesh, 0.49, 0.49))
    copies = seams.copies(droplet)
    assert len(copies) == 4 and len({chart for _, chart in copies}) == 4
    mask = dry_mask(256)
    seams.blend(mask, droplet)
    for qx in (0, 1):
        for qz in (0, 1):
            x = 0.5 + (0.03 if qx else -0.03)
            z = 0.5 + (0.03 if qz else -0.03)
            texel = lookup(mask, quadrant_uv(np.array(x), np.array(z), qx, qz))
            assert texel[3] == pytest.approx(0.6), (qx, qz)
            # the clump's centre: the droplet's surface point in this chart's UVs
            np.testing.assert_allclose(texel[:2], quadrant_uv(np.array(0.49), np.array(0.49),
                                                              qx, qz), atol=1e-6)
