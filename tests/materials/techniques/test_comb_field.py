"""The comb field (materials/techniques/comb_field.py): smooth over the mesh, crowns instead of
spots at the singular points, painted combs kept; measured on the field and on images."""

import numpy as np
import pytest

from deferred.materials.techniques.comb_field import comb_field
from deferred.scene.builtin_meshes import builtin_sphere, builtin_torus
from deferred.scene.geometry import build_mesh
from deferred.scene.loader import scene_from_dict


def edge_angles(mesh, field):
    """Angles (degrees) between the field's directions at the two ends of each mesh edge where
    both lean more than half, and the leans."""
    lean = np.linalg.norm(field, axis=1)
    faces = mesh.indices.reshape(-1, 3).astype(np.int64)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    unit = field / np.maximum(lean, 1e-9)[:, None]
    cosine = np.einsum("ij,ij->i", unit[edges[:, 0]], unit[edges[:, 1]])
    leaning = (lean[edges[:, 0]] > 0.5) & (lean[edges[:, 1]] > 0.5)
    return np.degrees(np.arccos(np.clip(cosine[leaning], -1.0, 1.0))), lean


def test_sphere_field_turns_smoothly_into_crowns_at_the_poles():
    mesh = builtin_sphere()
    field = comb_field(mesh, (0.0, -1.0, 0.0))
    angles, lean = edge_angles(mesh, field)
    assert angles.max() < 10.0  # neighbouring vertices' directions, wherever strands lean
    y = mesh.positions[:, 1]
    assert lean[np.abs(y) > 0.9999].max() < 1e-6  # upright in the crowns, not any which way
    assert lean[np.abs(y) < 0.9].min() > 0.99  # leaning fully away from them
    # tangential, and along the comb where the comb is well defined
    normals = mesh.normals.astype(np.float64)
    assert np.abs(np.einsum("ij,ij->i", field, normals)).max() < 1e-6
    comb = np.array([0.0, -1.0, 0.0]) + normals[:, 1:2] * normals  # c - (c.n) n
    defined = np.linalg.norm(comb, axis=1) > 0.7
    cosine = np.einsum("ij,ij->i", field[defined], comb[defined]) / \
        np.linalg.norm(comb[defined], axis=1)
    assert cosine.min() > np.cos(np.radians(3.0))


def test_torus_has_no_parting_ring():
    """The demo's comb on a torus projects to almost nothing along the tube's ridge, pointing
    down both sides: a constant comb parts there. The field turns across it instead: no ring of
    upright strands, and the only low-lean vertices are a few singular points."""
    mesh = builtin_torus()
    field = comb_field(mesh, (0.0, -1.0, 0.2))
    _, lean = edge_angles(mesh, field)
    assert (lean < 0.5).mean() < 0.01
    ridge = np.abs(mesh.normals[:, 1]) > 0.97
    assert np.median(lean[ridge]) > 0.9


def test_comb_along_the_normal_invents_no_direction():
    """A comb along a flat mesh's normal has no direction anywhere: nothing leans, and no
    direction is made up from rounding."""
    positions = np.array([[x, 0.0, z] for z in range(5) for x in range(5)], np.float64)
    faces = [[r * 5 + c, (r + 1) * 5 + c, r * 5 + c + 1] for r in range(4) for c in range(4)] + \
        [[r * 5 + c + 1, (r + 1) * 5 + c, (r + 1) * 5 + c + 1] for r in range(4) for c in range(4)]
    mesh = build_mesh("plane", positions, np.array(faces))
    field = comb_field(mesh, (0.0, 1.0, 0.0))
    assert np.abs(field).max() < 1e-9


def test_painted_comb_is_kept_and_flat_vertices_filled_from_neighbours():
    sphere = builtin_sphere(segments=16, rings=8)
    positions, normals = sphere.positions.astype(np.float64), sphere.normals.astype(np.float64)
    colours = np.ones((len(positions), 4))
    colours[:, :3] = (np.array([1.0, 0.0, 0.0]) + 1.0) / 2.0  # +x everywhere
    flat = np.abs(normals[:, 0]) > 0.999  # where +x is the normal: no direction painted
    assert flat.any()
    mesh = build_mesh("painted", positions, sphere.indices.reshape(-1, 3), normals, sphere.uvs,
                      colours)
    field = comb_field(mesh)
    painted = np.array([1.0, 0.0, 0.0]) - normals[:, :1] * normals
    length = np.linalg.norm(painted, axis=1)
    kept = length > 0.05
    unit = painted[kept] / length[kept, None]
    np.testing.assert_allclose(field[kept], unit, atol=2e-3)  # as painted, unit length
    assert np.all(np.isfinite(field))


def pole_scene(camera_y, view=None, size=(160, 160), camera_z=0.02):
    return scene_from_dict({
        "size": list(size), "background": [0.015, 0.017, 0.022],
        **({"tonemap": "none"} if view else {}),
        "camera": {"position": [0.0, camera_y, camera_z], "target": [0.0, 0.0, 0.0], "fov": 30.0},
        "object": [{"name": "ball", "mesh": "builtin:sphere", "material": "revie_fur",
                    "scale": 0.5,
                    "params": {"fur_length": 0.12, "shells": 12, "albedo_base": [0.04] * 3,
                               "albedo_tip": [0.55, 0.58, 0.65],
                               **({"debug": view} if view else {})}}],
        "light": [{"type": "ambient", "color": [0.3, 0.3, 0.35]},
                  {"type": "directional", "direction": [-0.3, -0.2 * np.sign(camera_y), -0.5],
                   "intensity": 1.0},
                  {"type": "spot", "position": [-2.0, 2.5 * np.sign(camera_y), 1.5],
                   "direction": [0.7, -0.9 * np.sign(camera_y), -0.6],
                   "color": [0.5, 0.7, 1.0], "intensity": 4.0, "radius": 7.0,
                   "inner_angle": 18.0, "outer_angle": 30.0}]})


@pytest.mark.parametrize("camera_y", [2.4, -2.4], ids=["top", "bottom"])
def test_comb_view_is_continuous_into_the_crown(render, camera_y):
    """The comb debug view (view-space comb x lean) seen down the axis onto a pole: the angle
    between neighbouring pixels' directions is bounded everywhere but at the singular point
    itself (no disc of per-triangle tangents around the pole)."""
    result, _ = render(pole_scene(camera_y, "comb"))
    rgb = result.hdr[..., :3].astype(np.float64)  # linear: the packed comb as written
    comb = rgb * 2.0 - 1.0
    lean = np.linalg.norm(comb, axis=-1)
    background = np.all(np.abs(rgb - rgb[0, 0]) < 1e-3, axis=-1)
    h, w = lean.shape
    y, x = np.mgrid[0:h, 0:w]
    # the singular point: the least lean on the ball's middle (the pole, seen down the axis)
    middle = ~background & (np.hypot(y - h / 2.0, x - w / 2.0) < 0.15 * w)
    pole = np.unravel_index(np.argmin(np.where(middle, lean, np.inf)), lean.shape)
    radius = np.hypot(y - pole[0], x - pole[1])
    ball = ~background & (radius < 0.35 * w)
    assert ball.sum() > 3000
    unit = comb / np.maximum(lean, 1e-6)[..., None]
    worst = 0.0
    for dy, dx in ((0, 1), (1, 0)):
        a, b = unit[:h - dy, :w - dx], unit[dy:, dx:]
        both = ball[:h - dy, :w - dx] & ball[dy:, dx:] & \
            (lean[:h - dy, :w - dx] > 0.3) & (lean[dy:, dx:] > 0.3) & \
            (radius[:h - dy, :w - dx] > 3.0)
        angle = np.degrees(np.arccos(np.clip(np.sum(a * b, -1), -1.0, 1.0)))[both]
        worst = max(worst, float(angle.max()))
    assert worst < 25.0
    # the singular point: nothing leans at it, everything leans a little way off it
    assert lean[radius < 1.5].max() < 0.3
    assert lean[ball & (radius > 12.0)].min() > 0.8


@pytest.mark.slow
@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
@pytest.mark.parametrize("camera_y", [2.4, -2.4], ids=["top", "bottom"])
def test_pole_is_no_spot(render, camera_y, pipeline):
    """The lit fur seen down onto a pole: a crop of the pole within a small range of the ring
    around it, in luminance and in blue (the old pole cap caught the blue spot light)."""
    result, _ = render(pole_scene(camera_y), pipeline)
    rgb = result.image[..., :3].astype(np.float64)
    h, w = rgb.shape[:2]
    y, x = np.mgrid[0:h, 0:w]
    radius = np.hypot(y - (h - 1) / 2.0, x - (w - 1) / 2.0)
    crop, ring = radius < 6.0, (radius >= 6.0) & (radius < 14.0)
    luminance = rgb @ np.array([0.2126, 0.7152, 0.0722])
    assert abs(luminance[crop].mean() - luminance[ring].mean()) < \
        0.08 * luminance[ring].mean() + 2.0
    blue = rgb[..., 2] / np.maximum(rgb.sum(-1), 1.0)
    assert abs(blue[crop].mean() - blue[ring].mean()) < 0.02


@pytest.mark.slow
@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_pole_at_the_silhouette_is_no_spot(render, pipeline):
    """The demo's view of its ball: the top pole just inside the silhouette, under the blue spot
    light. The strip of fur along the top of the outline is the same colour at the pole as
    either side of it (the old pole cap showed a blue spot there)."""
    scene = pole_scene(0.75, size=(320, 320), camera_z=3.6)
    result, _ = render(scene, pipeline)
    rgb = result.hdr[..., :3].astype(np.float64)
    luminance = rgb @ np.array([0.2126, 0.7152, 0.0722])
    fur = luminance > 2.0 * luminance[0, 0] + 1e-3
    rows = np.flatnonzero(fur.any(axis=1))
    top = rows[0]
    strip = rgb[top:top + 6]  # the outline's top, where the pole is
    centre = strip[:, 152:168].reshape(-1, 3)
    sides = np.concatenate([strip[:, 120:136], strip[:, 184:200]], axis=1).reshape(-1, 3)
    centre, sides = centre[centre.sum(-1) > 0.05], sides[sides.sum(-1) > 0.05]
    chroma = [float(np.mean(c[:, 2] / c.sum(-1))) for c in (centre, sides)]
    assert abs(chroma[0] - chroma[1]) < 0.013, chroma
