"""Scene effects and scene-wide passes: [[effect]] tables, fxaa against a supersampled frame,
edges on silhouettes and depth breaks but not on a plane, a plugin effect, the old [ssao]
table, materials' scene passes once per scene, and a composable material phase."""

import numpy as np
import pytest
from model_materials import InvertEffect, TintMaterial

from deferred.errors import InputError
from deferred.interfaces import registry
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

OBJECTS = [
    {"mesh": "builtin:plane", "scale": 6.0, "params": {"color": [0.6, 0.6, 0.6]}},
    {"mesh": "builtin:cube", "position": [-0.9, 0.5, 0.0], "rotation": [0.0, 30.0, 0.0],
     "scale": 0.5, "params": {"color": [0.9, 0.2, 0.1]}},
    {"mesh": "builtin:sphere", "position": [0.8, 0.6, 0.3], "scale": 0.6,
     "params": {"color": [0.2, 0.4, 0.9]}},
    {"mesh": "builtin:cube", "position": [0.0, 0.25, 1.2], "rotation": [0.0, 10.0, 0.0],
     "scale": 0.25},
]
LIGHTS = [{"type": "directional", "direction": [-0.5, -1.0, -0.4], "intensity": 2.5},
          {"type": "ambient", "intensity": 0.6}]
CAMERA = {"position": [0.0, 1.6, 4.2], "target": [0.0, 0.4, 0.0]}


def scene(effects=(), objects=OBJECTS, size=(320, 240), camera=CAMERA, **extra):
    return scene_from_dict({"size": list(size), "camera": camera, "object": list(objects),
                            "light": LIGHTS, "effect": list(effects), **extra})


def render(gl, scene, pipeline="deferred", size=None):
    with Renderer(scene, pipeline, size, gl=gl) as renderer:
        result = renderer.render()
        targets = {name: renderer.targets.read(name)[::-1] for name in renderer.targets.specs}
        return result, targets, [p.name for p in renderer.passes]


def srgb_to_linear(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(c):
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * np.clip(c, 0, None) ** (1 / 2.4) - 0.055)


def psnr(a, b):
    return 10.0 * np.log10(1.0 / np.mean((a - b) ** 2))


@pytest.mark.slow
def test_fxaa_brings_a_frame_closer_to_its_supersampled_render(gl):
    plain, _, _ = render(gl, scene())
    fxaa, _, names = render(gl, scene([{"type": "fxaa"}]))
    # after every other post pass; its source made by the tone mapping (a second output)
    assert names[-2:] == ["post.tonemap", "post.fxaa"]
    big, _, _ = render(gl, scene(), size=(1280, 960))
    reference = linear_to_srgb(srgb_to_linear(big.image[..., :3] / 255.0)
                               .reshape(240, 4, 320, 4, 3).mean(axis=(1, 3)))
    before = psnr(plain.image[..., :3] / 255.0, reference)
    after = psnr(fxaa.image[..., :3] / 255.0, reference)
    assert after > before + 2.0, (before, after)  # measured: 33.9 -> 37.9 dB
    # it only touches edges: flat regions are bit-identical
    changed = np.any(plain.image != fxaa.image, axis=-1)
    assert 0.01 < changed.mean() < 0.2


def test_edges_draw_on_silhouettes_and_depth_breaks(gl):
    result, targets, names = render(gl, scene([{"type": "edges"}]))
    first_light = next(i for i, name in enumerate(names) if name.startswith("lighting."))
    assert names.index("screen.edges") < first_light
    assert names.index("post.edges") > names.index("post.tonemap")
    edges = targets["edges"][..., 0] > 0.5
    depth = targets["linear_depth"][..., 0]
    ids = targets["normal_exponent_id"][..., 3]
    # near side of every depth break of more than 20 %, and of every id change toward farther
    near = np.zeros_like(edges)
    for axis, shift in ((0, 1), (0, -1), (1, 1), (1, -1)):
        other_depth = np.roll(depth, shift, axis)
        other_id = np.roll(ids, shift, axis)
        farther = (other_depth == 0.0) | (other_depth > depth * 1.2)
        near |= (depth > 0.0) & farther & ((other_id != ids) | (other_depth > depth * 1.2))
    near[[0, -1], :] = near[:, [0, -1]] = False
    assert near.sum() > 400
    assert edges[near].mean() > 0.97
    # lines are drawn in black over the frame
    assert np.all(result.image[edges][:, :3] == 0)


def test_edges_against_the_background_without_ids(gl):
    sphere = [{"mesh": "builtin:sphere", "scale": 0.8}]
    camera = {"position": [0.0, 0.0, 4.0], "target": [0.0, 0.0, 0.0]}
    _, targets, _ = render(gl, scene([{"type": "edges", "ids": False}], objects=sphere,
                                     size=(96, 72), camera=camera))
    depth = targets["linear_depth"][..., 0]
    covered = depth > 0.0
    rim = covered & ~(np.roll(covered, 1, 0) & np.roll(covered, -1, 0) &
                      np.roll(covered, 1, 1) & np.roll(covered, -1, 1))
    edges = targets["edges"][..., 0] > 0.5
    assert rim.sum() > 50 and edges[rim].mean() > 0.95  # depth breaks against infinity
    assert edges[~covered].sum() == 0


def test_edges_nowhere_on_a_flat_lit_plane(gl):
    plane = [{"mesh": "builtin:plane", "scale": 40.0}]
    tilted = {"position": [0.3, 2.5, 2.0], "target": [0.0, 0.0, 0.0]}
    _, targets, _ = render(gl, scene([{"type": "edges", "width": 3}], objects=plane,
                                     camera=tilted))
    depth = targets["linear_depth"][..., 0]
    assert depth.min() > 0.0  # the plane fills the frame, lit and sloping away
    assert targets["edges"].max() == 0.0


def run_through(row: np.ndarray, x: int) -> int:
    """Length of the run of True in ``row`` that contains ``x``."""
    left = x
    while left > 0 and row[left - 1]:
        left -= 1
    right = x
    while right + 1 < len(row) and row[right + 1]:
        right += 1
    return right - left + 1


@pytest.mark.parametrize("width", [1, 2, 3, 5])
def test_edges_width_is_the_line_width_in_pixels(gl, width):
    # a cube seen face on: its silhouette is a square of vertical and horizontal lines
    cube = [{"mesh": "builtin:cube", "scale": 0.8}]
    _, targets, _ = render(gl, scene([{"type": "edges", "width": width}], objects=cube,
                                     size=(96, 72), camera={"position": [0.0, 0.0, 5.0],
                                                            "target": [0.0, 0.0, 0.0]}))
    raw, edges = targets["edges_raw"][..., 0] > 0.5, targets["edges"][..., 0] > 0.5
    middle = raw.shape[0] // 2
    x = np.nonzero(raw[middle])[0]
    assert len(x) == 2  # one pixel on each side of the square
    assert run_through(edges[middle], x[0]) == width
    assert run_through(edges[middle], x[1]) == width
    y = np.nonzero(raw[:, raw.shape[1] // 2])[0]
    assert len(y) == 2 and run_through(edges[:, raw.shape[1] // 2], y[0]) == width


def test_g_buffer_effects_are_skipped_in_forward_with_a_warning(gl):
    with pytest.warns(UserWarning, match="effect edges applies to the deferred pipeline only; "
                                         r"skipped in the forward pipeline \(forward = true"):
        _, _, names = render(gl, scene([{"type": "edges"}, {"type": "fxaa"}]), "forward")
    assert "post.fxaa" in names and "screen.edges" not in names


def forward_and_deferred_scene(forward):
    return scene_from_dict({
        "size": [120, 90], "tonemap": "none",
        "camera": {"position": [0.0, 1.5, 3.5], "target": [0.0, 0.3, 0.0]},
        "object": [{"mesh": "builtin:plane", "scale": 3.0},
                   {"mesh": "builtin:sphere", "position": [0.0, 0.5, 0.0], "scale": 0.5},
                   {"mesh": "builtin:torus", "material": "pbr", "position": [0.9, 0.3, 0.3],
                    "scale": 0.4, "params": {"base_color": [0.7, 0.4, 0.3]}}],
        "light": [{"type": "ambient", "color": [0.6, 0.6, 0.6]},
                  {"type": "directional", "direction": [0.3, -1.0, -0.4], "intensity": 0.8}],
        "effect": [{"type": "ssao", "forward": forward, "radius": 0.4},
                   {"type": "edges", "forward": forward}]})


@pytest.mark.parametrize("light_path", ["naive", "tiled"])
def test_g_buffer_effects_run_in_forward_when_asked_and_agree_with_deferred(gl, light_path):
    """With forward = true the forward pipeline writes the G-buffer first (the objects'
    G-buffer passes), runs the screen phase over it, and its opaque lit passes take the
    ambient occlusion: SSAO and edges as in the deferred pipeline."""
    with Renderer(forward_and_deferred_scene(True), "deferred", gl=gl, strict=True) as renderer:
        deferred = renderer.render().image[..., :3] / 255.0
    with Renderer(forward_and_deferred_scene(True), "forward", gl=gl, strict=True,
                  light_path=light_path) as renderer:
        forward = renderer.render().image[..., :3] / 255.0
        names = [p.name for p in renderer.passes]
    assert names.index("torus0.gbuffer") < names.index("screen.ssao") < \
        names.index("torus0.forward") < names.index("post.edges")
    assert not any(name.endswith("depth_prepass") for name in names)  # the G-buffer's depth
    assert psnr(forward, deferred) >= 40.0
    with pytest.warns(UserWarning, match="effect ssao applies"):
        with Renderer(forward_and_deferred_scene(False), "forward", gl=gl,
                      light_path=light_path) as renderer:
            plain = renderer.render().image[..., :3] / 255.0
    assert psnr(plain, deferred) < 30.0  # no occlusion, no outlines


@pytest.mark.parametrize("effect, message", [
    ({"type": "blur"}, r"effect\[0\].type: unknown effect 'blur' \(choose from"),
    ({"type": "edges", "width": 0}, r"effect\[0\].width: Input should be greater than or equal"),
    ({"type": "fxaa", "strength": 1}, r"effect\[0\].strength: unknown parameter"),
    ([{"type": "fxaa"}, {"type": "fxaa"}], r"effect\[1\].type: effect 'fxaa' is given twice"),
])
def test_bad_effect_tables_name_the_key(effect, message):
    with pytest.raises(InputError, match=message):
        scene(effect if isinstance(effect, list) else [effect])


def test_the_ssao_table_still_works_and_is_not_given_twice(gl):
    _, targets, names = render(gl, scene(ssao={"radius": 0.3}, light_path="volumes"))
    assert names.index("screen.ssao") < names.index("screen.ssao_blur") < \
        names.index("lighting.ambient")
    assert targets["ssao"].min() < 0.9
    with pytest.raises(InputError, match="ssao is given both as"):
        scene([{"type": "ssao"}], ssao={})


def test_a_plugin_effect_runs_with_its_own_shaders(gl):
    registry.effects.register(InvertEffect)
    try:
        plain, _, _ = render(gl, scene())
        inverted, _, names = render(gl, scene([{"type": "test_invert", "amount": 1.0}]))
        assert "post.test_invert" in names
        np.testing.assert_allclose(inverted.image[..., :3].astype(int),
                                   255 - plain.image[..., :3].astype(int), atol=1)
    finally:
        registry.effects.unregister(InvertEffect.name)


def test_materials_scene_passes_run_once_per_scene(gl):
    fur = {"material": "revie_fur", "params": {"shells": 2}}
    objects = [OBJECTS[0], {**fur, "mesh": "builtin:sphere", "position": [-0.8, 0.6, 0.0],
                            "scale": 0.5},
               {**fur, "mesh": "builtin:sphere", "position": [0.8, 0.6, 0.0], "scale": 0.5},
               {"mesh": "builtin:cube", "material": "stipple_glass", "position": [0, 0.6, 1.5],
                "scale": 0.3}]
    _, _, names = render(gl, scene(objects=objects, size=(96, 72)))
    # the tiled lighting makes the snapshot (deferred.render.pipeline.leading_snapshots)
    assert names.count("material.stipple_snapshot") == 0
    snapshot = names.index("lighting.tiled")
    obliterations = [k for k, n in enumerate(names) if n.endswith("stipple_obliteration")]
    assert len(obliterations) == 3 and min(obliterations) > snapshot


def period2_energy(image):
    """Mean absolute difference between each pixel and the mean of its 4 neighbours: a
    checkerboard or 1-in-4 dot grid has much of it, a smooth image little."""
    core = image[1:-1, 1:-1]
    neighbours = (image[:-2, 1:-1] + image[2:, 1:-1] + image[1:-1, :-2] + image[1:-1, 2:]) / 4
    return np.abs(core - neighbours).sum(axis=-1)


@pytest.mark.slow
def test_obliteration_restores_what_another_material_made_of_its_pixels(gl):
    """Fur stipple over an object that tints its pixels in the material phase: the stipple
    samples are restored from the tinted composition, so the frame matches the same frame
    without stipple (no checkerboard of untinted samples)."""
    registry.materials.register(TintMaterial)
    try:
        def frame(stipple):
            objects = [
                {"mesh": "builtin:plane", "material": "test_tint", "rotation": [90.0, 0.0, 0.0],
                 "position": [0.0, 0.0, -1.0], "scale": 3.0,
                 "params": {"color": [0.9, 0.9, 0.9], "tint": [1.0, 0.2, 0.2]}},
                {"mesh": "builtin:sphere", "material": "revie_fur", "scale": 0.6,
                 "params": {"shells": 0, "stipple": stipple, "fur_length": 0.3,
                            "rim_strength": 0.0}}]
            result, targets, _ = render(gl, scene(objects=objects, size=(160, 120),
                                                  camera={"position": [0, 0, 3.0],
                                                          "target": [0, 0, 0]}))
            return result.hdr[..., :3], targets
        with_stipple, targets = frame(True)
        without, _ = frame(False)
        # the plane without fur in front of it, in the frame without stipple ...
        plane_only = np.linalg.norm(without - without[0, 0], axis=-1) < 0.05
        # ... holds the outer shell's stipple samples in the frame with stipple
        fur_id = registry.materials.get("revie_fur").type_id
        samples = plane_only & (targets["normal_exponent_id"][..., 3] % 64 == fur_id)
        assert samples.sum() > 50
        inner = plane_only[1:-1, 1:-1]
        energy_with = period2_energy(with_stipple)[inner].mean()
        energy_without = period2_energy(without)[inner].mean()
        assert energy_with <= 2.0 * energy_without + 1e-3
        # the tint survives on the restored samples: red, not white (away from the fur, whose
        # base pixel may be the neighbour a sample copies: fur issue's "teeth")
        away = samples & np.roll(plane_only, 1, 1) & np.roll(plane_only, -1, 1)
        assert away.sum() > 50
        restored = with_stipple[away]
        bad = restored[:, 1] > 0.5 * restored[:, 0]
        assert not bad.any(), restored[bad]
    finally:
        registry.materials.unregister(TintMaterial.name)


def disc_dilation(raw: np.ndarray, width: int) -> np.ndarray:
    """The edge mask dilated by a disc ``width`` pixels across (an even width centred between
    pixels), directly in 2D: every offset of the disc tried (the reference)."""
    low, high = (width - 1) // 2, width // 2
    centre = 0.5 if width % 2 == 0 else 0.0
    radius = 0.5 * width
    height, breadth = raw.shape
    out = np.zeros_like(raw)
    for dy in range(-low, high + 1):
        for dx in range(-low, high + 1):
            if (dx - centre) ** 2 + (dy - centre) ** 2 > radius * radius + 1e-3:
                continue
            # out[p] |= raw[p + (dx, dy)] where p + (dx, dy) lies inside the image
            shifted = np.zeros_like(raw)
            ys = slice(max(0, -dy), min(height, height - dy))
            xs = slice(max(0, -dx), min(breadth, breadth - dx))
            shifted[ys, xs] = raw[ys.start + dy:ys.stop + dy, xs.start + dx:xs.stop + dx]
            out |= shifted
    return out


@pytest.mark.parametrize("width", [1, 2, 4, 7, 12, 16])
def test_the_two_pass_dilation_is_the_disc(gl, width):
    """A row pass then a column pass give exactly the 2D disc dilation of the raw edges
    (whose cost grew with the width's square), against a numpy reference, on a frame with
    curved silhouettes and creases."""
    objects = [{"mesh": "builtin:torus", "position": [-0.6, 0.0, 0.0], "rotation": [60, 0, 0]},
               {"mesh": "builtin:cube", "position": [0.9, 0.2, -0.5], "rotation": [20, 30, 0],
                "scale": 0.6}]
    _, targets, names = render(gl, scene([{"type": "edges", "width": width}], objects=objects,
                                         size=(120, 80), camera={"position": [0.0, 0.5, 4.0],
                                                                 "target": [0.0, 0.0, 0.0]}))
    assert "screen.edges_dilate_rows" in names and "screen.edges_dilate_columns" in names
    raw = targets["edges_raw"][..., 0] > 0.5
    edges = targets["edges"][..., 0] > 0.5
    assert raw.sum() > 200
    # in GL's orientation (bottom row first), where an even width's disc sits up and right
    np.testing.assert_array_equal(edges[::-1], disc_dilation(raw[::-1], width))


def test_creases_fire_on_a_cube_not_on_a_smooth_surface_however_tight(gl):
    """Creases (a turn of the normal in one pixel step with none beside it) line a cube's
    edges inside its silhouette, and never a smooth surface's curvature: a torus thin enough
    that its tube is a few pixels across, whose rims a Sobel of the normals outlines."""
    camera = {"position": [0.0, 0.0, 4.0], "target": [0.0, 0.0, 0.0]}
    cube = [{"mesh": "builtin:cube", "rotation": [25.0, 35.0, 0.0], "scale": 0.8}]
    _, targets, _ = render(gl, scene([{"type": "edges", "ids": False, "depth_threshold": 10.0}],
                                     objects=cube, size=(120, 90), camera=camera))
    raw = targets["edges_raw"][..., 0] > 0.0
    covered = targets["linear_depth"][..., 0] > 0.0
    inner = covered.copy()
    for axis, shift in ((0, 1), (0, -1), (1, 1), (1, -1)):
        inner &= np.roll(covered, shift, axis)
    assert raw[inner].sum() > 60  # the three visible faces meet along three creases
    for torus_scale in (1.0, 0.25):
        torus = [{"mesh": "builtin:torus?minor=0.08", "rotation": [70.0, 0.0, 0.0],
                  "scale": torus_scale}]
        _, targets, _ = render(gl, scene([{"type": "edges", "ids": False,
                                           "depth_threshold": 10.0}],
                                         objects=torus, size=(120, 90), camera=camera))
        assert (targets["linear_depth"][..., 0] > 0.0).sum() > 30
        assert targets["edges_raw"].max() == 0.0, torus_scale


def test_world_width_lines_thin_with_distance(gl):
    """world_width: the line is that many view units wide at its surface's depth: a cube twice
    as far has lines half as wide (in pixels, within [1, width])."""
    cubes = [{"mesh": "builtin:cube", "position": [-0.6, 0.0, 0.0], "scale": 0.3},
             {"mesh": "builtin:cube", "position": [1.2, 0.0, -4.0], "scale": 0.6}]
    camera = {"position": [0.0, 0.0, 4.0], "target": [0.3, 0.0, -2.0], "fov": 40.0}
    _, targets, _ = render(gl, scene([{"type": "edges", "width": 16, "world_width": 0.1}],
                                     objects=cubes, size=(240, 120), camera=camera))
    raw = targets["edges_raw"][..., 0]
    edges = targets["edges"][..., 0] > 0.5
    depth = targets["linear_depth"][..., 0]
    # the half width in pixels each edge pixel holds: 0.05 units at its depth
    focal = 0.5 * 120 / np.tan(np.radians(20.0))
    lined = raw > 0.0
    np.testing.assert_allclose(raw[lined], np.clip(0.05 * focal / depth[lined], 0.5, 8.0),
                               rtol=1e-3)
    # the lines' area over their length: their width, each cube in its half of the frame
    widths = [edges[:, half].sum() / lined[:, half].sum()
              for half in (slice(0, 120), slice(120, 240))]
    assert lined[:, :120].sum() > 40 and lined[:, 120:].sum() > 40
    assert widths[0] > 3.0 and 1.6 < widths[0] / widths[1] < 2.6, widths
