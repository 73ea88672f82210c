"""Object-space silhouette strokes on cartoon hair (Costigan 4.3.7, after Lake et al. and
Northrup et al.): the tubes' triangle adjacency, strokes along the silhouettes only, their width
in pixels, their fade toward the roots and their visibility, in both pipelines."""

from __future__ import annotations

import json

import numpy as np
import pytest

from deferred.materials.techniques.hair_silhouettes import (
    STROKE_SHAPE,
    triangle_adjacency,
    tube_adjacency,
)
from deferred.materials.techniques.hair_tubes import tube_indices
from deferred.materials.techniques.hatching import default_stroke
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

RED = (1.0, 0.0, 0.0)
SIZE = 256
FOV = 40.0


# -- the edge table ------------------------------------------------------------------------------

def brute_force_neighbours(faces: np.ndarray) -> list[list[list[int]]]:
    """For each triangle and each of its edges (ab, bc, ca), the third vertices of every other
    triangle holding both of the edge's vertices."""
    found = []
    for t, face in enumerate(faces.tolist()):
        per_edge = []
        for k in range(3):
            a, b = face[k], face[(k + 1) % 3]
            per_edge.append([next(v for v in other if v not in (a, b))
                             for u, other in enumerate(faces.tolist())
                             if u != t and a in other and b in other])
        found.append(per_edge)
    return found


@pytest.mark.parametrize("strands, samples, sides", [(1, 2, 3), (3, 4, 5), (2, 6, 8)])
def test_tube_adjacency_matches_a_brute_force_search(strands, samples, sides):
    faces = tube_indices(strands, samples, sides).astype(np.int64)
    table = tube_adjacency(strands, samples, sides)
    assert table.shape == (len(faces), 6) and table.dtype == np.uint32
    adjacency = table.astype(np.int64)
    np.testing.assert_array_equal(adjacency[:, 0::2], faces)  # the triangle itself
    np.testing.assert_array_equal(triangle_adjacency(faces), adjacency)  # one strand, offset
    reference = brute_force_neighbours(faces)
    wound = {tuple(np.roll(f, r)) for f in faces.tolist() for r in range(3)}
    for t, face in enumerate(faces.tolist()):
        for k in range(3):
            # a closed tube: each edge has exactly one other triangle, whose third vertex the
            # table holds, wound the same way as the triangle (a, p, b)
            assert reference[t][k] == [adjacency[t, 2 * k + 1]], (t, k)
            a, b = face[k], face[(k + 1) % 3]
            assert (a, int(adjacency[t, 2 * k + 1]), b) in wound


def test_an_edge_with_one_triangle_faces_back_on_itself():
    faces = np.array([[0, 1, 2], [2, 1, 3]], np.uint32)  # two triangles sharing the edge 1-2
    adjacency = triangle_adjacency(faces)
    assert adjacency.dtype == np.uint32
    np.testing.assert_array_equal(adjacency, [[0, 2, 1, 3, 2, 1], [2, 0, 1, 2, 3, 1]])


# -- rendered strokes ---------------------------------------------------------------------------

def head_scene(params: dict, size: int = SIZE):
    return scene_from_dict({
        "size": [size, size], "tonemap": "none", "background": [0.9, 0.9, 0.9],
        "camera": {"position": [0.0, 0.05, 0.55], "target": [0.0, 0.0, 0.0], "fov": FOV},
        "object": [{"name": "head", "mesh": "builtin:head?segments=48&rings=32",
                    "material": "cartoon_hair",
                    "params": {"strands": 60, "style": "spiky", "silhouettes": True,
                               "stroke_color": list(RED), **params}}],
        "light": [{"type": "directional", "direction": [-0.5, -0.6, -0.6]}]})


def strand_scene(tmp_path, strands: list[list[list[float]]], params: dict):
    """Straight strands from a file on a black head, blue hair, on black: the red channel is
    the strokes' alpha alone."""
    path = tmp_path / "strands.json"
    path.write_text(json.dumps({"strands": strands}))
    return scene_from_dict({
        "size": [SIZE, SIZE], "tonemap": "none", "background": [0.0, 0.0, 0.0],
        "camera": {"position": [0.0, 0.0, 1.0], "target": [0.0, 0.0, 0.0], "fov": FOV},
        "object": [{"name": "head", "mesh": "builtin:head", "material": "cartoon_hair",
                    "params": {"strands_file": str(path), "gravity": [0.0, 0.0, 0.0],
                               "collision_spheres": [], "skin_color": [0.0, 0.0, 0.0],
                               "color": [0.0, 0.0, 1.0], "radius": 0.02,
                               "taper": [0.0, 0.0, 1.0], "silhouettes": True,
                               "stroke_color": list(RED), **params}}],
        "light": [{"type": "directional", "direction": [0.0, 0.0, -1.0]}]})


def horizontal(z: float, y: float = 0.0, half_length: float = 0.2) -> list[list[float]]:
    return [[float(x), y, z] for x in np.linspace(-half_length, half_length, 8)]


def column_of(x: float, z: float) -> int:
    """The pixel column of the point (x, 0, z) seen by strand_scene's camera."""
    half_width = (1.0 - z) * np.tan(np.radians(FOV / 2.0))
    return int((x / half_width * 0.5 + 0.5) * SIZE)


def render(gl, scene, pipeline: str) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The HDR image (row 0 at the top) and, deferred, the G-buffer's strand ids and depth."""
    with Renderer(scene, pipeline, gl=gl) as renderer:
        hdr = renderer.render(time=0.0, hdr=True).hdr[..., :3]
        targets = {name: renderer.targets.read(name)[::-1][..., 0]
                   for name in ("strand_id", "linear_depth") if name in renderer.targets.specs}
    return hdr, targets


def grow(mask: np.ndarray, pixels: int) -> np.ndarray:
    """``mask`` dilated by a square of ``pixels`` either side."""
    grown = mask.copy()
    for _ in range(pixels):
        step = grown.copy()
        for axis in (0, 1):
            for shift in (1, -1):
                step |= np.roll(grown, shift, axis)
        grown = step
    return grown


def red_strokes(hdr: np.ndarray) -> np.ndarray:
    return (hdr[..., 0] > 0.5) & (hdr[..., 1] < 0.25) & (hdr[..., 2] < 0.25)


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_strokes_follow_the_hair_silhouettes_and_nothing_else(gl, pipeline):
    width = 3
    params = {"stroke_width": width, "stroke_fade": [0.0, 0.0, 1.0]}
    _, gbuffer = render(gl, head_scene(params), "deferred")
    hdr, _ = render(gl, head_scene(params), pipeline)
    hair = gbuffer["strand_id"] > 0.5
    background = gbuffer["linear_depth"] <= 0.0
    red = red_strokes(hdr)
    assert red.sum() > 1500  # many strokes
    # every stroke pixel within half a stroke (and a pixel) of the hair
    assert not (red & ~grow(hair, width // 2 + 1)).any()
    # the hair's outline against the background is stroked nearly all along
    outline = hair & (grow(background, 1))
    assert outline.sum() > 300
    assert (outline & grow(red, 1)).sum() > 0.9 * outline.sum()
    # strokes inside the hair too: its silhouettes against other strands
    inner = hair & ~grow(background, width)
    assert (red & inner).sum() > 0.3 * red.sum()


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_stroke_width_follows_stroke_width(gl, tmp_path, pipeline):
    """A strand across the view has a stroke along each side: each ``stroke_width`` pixels
    across, holding the stroke image's ink across it."""
    middle = default_stroke(STROKE_SHAPE)[:, STROKE_SHAPE[1] // 2].mean()
    columns = slice(column_of(-0.04, 0.3), column_of(0.04, 0.3))
    for width in (2, 4, 8):
        hdr, _ = render(gl, strand_scene(tmp_path, [horizontal(0.3)],
                                         {"stroke_width": width,
                                          "stroke_fade": [0.0, 0.0, 1.0]}), pipeline)
        alpha = hdr[:, columns, 0]
        drawn = alpha > 0.05
        for column in range(drawn.shape[1]):
            rows = np.flatnonzero(drawn[:, column])
            runs = np.split(rows, np.flatnonzero(np.diff(rows) > 1) + 1)
            assert [len(run) for run in runs] == [width, width], (width, column, rows)
        ink = alpha.sum(axis=0) / 2.0
        np.testing.assert_allclose(ink, width * middle, rtol=0.1)


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_strokes_fade_toward_the_roots(gl, tmp_path, pipeline):
    """``stroke_fade = [0, 1, 0]``: alpha = the parameter along the strand, so a quarter of the
    way from the root holds a third of the ink three quarters of the way (the stroke image is
    symmetric along); without fade the two hold the same."""
    root_side = slice(column_of(-0.105, 0.3), column_of(-0.095, 0.3))
    tip_side = slice(column_of(0.095, 0.3), column_of(0.105, 0.3))
    ratios = {}
    for fade in ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)):
        hdr, _ = render(gl, strand_scene(tmp_path, [horizontal(0.3)],
                                         {"stroke_width": 6, "stroke_fade": list(fade)}),
                        pipeline)
        ink = hdr[..., 0]
        ratios[fade] = ink[:, root_side].sum() / ink[:, tip_side].sum()
    assert 0.27 < ratios[(0.0, 1.0, 0.0)] < 0.4
    assert 0.9 < ratios[(0.0, 0.0, 1.0)] < 1.1


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_strands_behind_the_head_draw_no_stroke(gl, tmp_path, pipeline):
    """One strand before the face, one behind the head: over the head only the front one's
    strokes show; the hidden one's show where it sticks out past the head."""
    front, behind = horizontal(0.3, y=-0.04), horizontal(-0.3, y=0.03, half_length=0.4)
    scene = strand_scene(tmp_path, [front, behind], {"stroke_width": 4})
    _, gbuffer = render(gl, scene, "deferred")
    hdr, _ = render(gl, scene, pipeline)
    red = hdr[..., 0] > 0.05
    head = (gbuffer["linear_depth"] > 0.0) & (gbuffer["strand_id"] < 0.5)
    front_hair = gbuffer["strand_id"] == 1.0
    assert head.sum() > 2000 and front_hair.sum() > 500
    assert (red & grow(front_hair, 3)).sum() > 400  # the front strand is stroked
    assert not (red & head & ~grow(front_hair, 3)).any()  # nothing of the hidden one
    assert (red & ~grow(head | front_hair, 3)).sum() > 50  # ... except past the head


def test_no_silhouette_pass_unless_asked(gl):
    for silhouettes in (False, True):
        scene = head_scene({"silhouettes": silhouettes}, size=64)
        for pipeline in ("deferred", "forward"):
            with Renderer(scene, pipeline, gl=gl) as renderer:
                names = [p.name for p in renderer.passes]
            assert any("silhouettes" in name for name in names) == silhouettes


# -- the edges found by a compute shader -------------------------------------------------------

def numpy_silhouette_edges(positions: np.ndarray, normals: np.ndarray, faces: np.ndarray
                           ) -> set[tuple[int, int]]:
    """The edges between a front- and a back-facing triangle (view space, the eye at the
    origin; a face without area faces as its vertices' normals), by brute force over the
    edges' triangles."""
    a, b, c = (positions[faces[:, k]] for k in range(3))
    n = np.cross(b - a, c - a)
    at = a.copy()
    flat = (n * n).sum(-1) <= 1e-12 * ((b - a) ** 2).sum(-1) * ((c - a) ** 2).sum(-1)
    n[flat] = normals[faces[flat]].sum(axis=1)
    at[flat] = positions[faces[flat]].mean(axis=1)
    front = -(n * at).sum(-1) > 0.0
    sides: dict[tuple[int, int], list[bool]] = {}
    for face, facing in zip(faces.tolist(), front, strict=True):
        for k in range(3):
            edge = tuple(sorted((face[k], face[(k + 1) % 3])))
            sides.setdefault(edge, []).append(bool(facing))
    return {edge for edge, facings in sides.items() if len(facings) == 2 and
            facings[0] != facings[1]}


def test_the_compute_pass_strokes_exactly_the_silhouette_edges(gl):
    """SilhouetteEdges (Costigan 4.3.7 on the GPU): an invocation a strand walks its tube from
    the tubes' vertex order alone (no adjacency buffer) and strokes every edge between a front-
    and a back-facing triangle, once: its strokes' ends are those edges' vertices, against a
    brute-force numpy classification of the same mesh (wavy tapered tubes, caps included; the
    tips kept a little wide, so that each vertex projects apart from the others)."""
    from deferred.gl.shaderlib import ShaderLibrary
    from deferred.materials.techniques.hair_silhouettes import SilhouetteEdges, edges_on_gpu
    from deferred.materials.techniques.hair_tubes import build_tubes

    if not edges_on_gpu(gl):
        pytest.skip("the context has no compute shaders or no vertex shader storage buffers")
    rng = np.random.default_rng(3)
    count, samples, sides = 12, 9, 7
    t = np.linspace(0.0, 1.0, 6)
    strands = np.stack([np.stack([0.3 * np.sin(3 * t + k), t - 0.5, 0.2 * np.cos(2 * t * k)], -1)
                        + rng.normal(scale=0.05, size=3) for k in range(count)])
    tubes = build_tubes(strands, samples, sides, 0.04, taper=(0.0, -0.7, 1.0))
    model_view = np.eye(4)
    model_view[:3, 3] = (0.1, -0.05, -2.5)
    view_positions = tubes.positions.astype(np.float64) + model_view[:3, 3]
    expected = numpy_silhouette_edges(view_positions, tubes.normals.astype(np.float64),
                                      tubes.indices.astype(np.int64))
    ctx = gl.ctx
    gl.make_current()
    vertices = ctx.buffer(np.hstack([tubes.positions, tubes.normals]).astype(np.float32))
    edges = SilhouetteEdges(ctx, count, samples, sides)
    shaders = ShaderLibrary(ctx, gl.features.glsl_version())
    projection = np.array([[1.2, 0, 0, 0], [0, 1.2, 0, 0], [0, 0, -1.02, -0.2], [0, 0, -1, 0]])
    stroke = {"u_projection": tuple(projection.T.reshape(-1)), "u_resolution": (400.0, 400.0),
              "u_stroke_width": 2.0, "u_stroke_world_width": 0.0, "u_tube_radius": 1.0,
              "u_tube_taper": (0.0, 0.0, 1.0), "u_stroke_tolerance": 0.0}
    assert edges.capacity >= len(expected)
    try:
        edges.find(shaders, vertices, model_view, stroke)
        corners = edges.corners()
    finally:
        for thing in (edges, vertices, shaders):
            thing.release()
    # each stroke's two ends, back to the vertices they were made from (by their NDC position)
    clip = np.hstack([view_positions, np.ones((len(view_positions), 1))]) @ projection.T
    ndc = clip[:, :2] / clip[:, 3:]
    ends = (corners[:, 0::2, :2] + corners[:, 1::2, :2]) / 2.0  # the middle of each end
    nearest = np.linalg.norm(ends[:, :, None, :] - ndc[None, None], axis=-1).argmin(axis=-1)
    found = {tuple(sorted(map(int, pair))) for pair in nearest}
    assert len(expected) > 100
    assert len(corners) == len(found)  # each edge once
    assert found == expected
