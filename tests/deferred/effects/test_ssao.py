"""SSAO on a reduced grid: the grid targets' size, the depth-aware upsample keeping each
surface's occlusion on its side of a silhouette, resolution = 1 as the full-resolution passes
always were, and a bad resolution refused in one line."""

import numpy as np
import pytest
from command_line import assert_one_line_error, run
from locations import REFERENCE
from PIL import Image

from deferred.errors import InputError
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

# A small sphere floating near the camera, its silhouette over the dark contact shadows of a far
# sphere and cube standing on the floor: occlusion changes sharply across its edge.
OBJECTS = [
    {"mesh": "builtin:plane", "scale": 12.0},
    {"mesh": "builtin:sphere", "position": [0.2, 0.5, -2.0], "scale": 0.5},
    {"mesh": "builtin:cube", "position": [-0.7, 0.4, -2.2], "rotation": [0.0, 30.0, 0.0],
     "scale": 0.4},
    {"mesh": "builtin:sphere", "position": [-0.2, 0.5, 1.6], "scale": 0.2},
]


def scene(size=(320, 240), **ssao):
    return scene_from_dict({
        "size": list(size),
        "camera": {"position": [0.0, 1.1, 4.0], "target": [0.0, 0.4, -2.0]},
        "object": OBJECTS, "light": [{"type": "ambient", "intensity": 1.0}],
        "effect": [{"type": "ssao", "radius": 0.5, **ssao}]})


def render(gl, scene, names=("ssao", "linear_depth"), pipeline="deferred"):
    with Renderer(scene, pipeline, gl=gl) as renderer:
        renderer.render()
        passes = [p.name for p in renderer.passes if "ssao" in p.name]
        return {n: renderer.targets.read_raw(n)[::-1] for n in names}, passes


def dilate(mask, reach):
    out = mask.copy()
    for dy in range(-reach, reach + 1):
        for dx in range(-reach, reach + 1):
            out |= np.roll(mask, (dy, dx), (0, 1))
    return out


def bilinear(grid, size):
    """A plain bilinear upsample of ``grid`` to ``size`` (width, height): no depth test."""
    (h, w), (width, height) = grid.shape, size
    ys = np.clip((np.arange(height) + 0.5) * h / height - 0.5, 0, h - 1)
    xs = np.clip((np.arange(width) + 0.5) * w / width - 0.5, 0, w - 1)
    y0, x0 = np.minimum(ys.astype(int), h - 2), np.minimum(xs.astype(int), w - 2)
    fy, fx = (ys - y0)[:, None], (xs - x0)[None, :]
    rows = grid[y0] * (1 - fy) + grid[y0 + 1] * fy
    return rows[:, x0] * (1 - fx) + rows[:, x0 + 1] * fx


@pytest.mark.parametrize("resolution, size, grid", [(0.5, (320, 240), (160, 120)),
                                                     (0.3, (161, 91), (49, 28))])
def test_the_reduced_grid_has_the_reduced_size_and_the_ssao_target_the_frames(
        gl, resolution, size, grid):
    targets, passes = render(gl, scene(size, resolution=resolution),
                             ("ssao_raw", "ssao_reduced", "ssao"))
    assert passes == ["screen.ssao", "screen.ssao_blur", "screen.ssao_upsample"]
    assert targets["ssao_raw"].shape == targets["ssao_reduced"].shape == (grid[1], grid[0], 2)
    assert targets["ssao"].shape == (size[1], size[0], 1)
    assert targets["ssao"].min() < 200  # something is occluded, up to the frame's corner
    assert targets["ssao"][0, -1, 0] == 255  # the sky, top right: open


def test_the_upsampled_occlusion_does_not_cross_a_depth_edge(gl):
    full, _ = render(gl, scene(resolution=1.0))
    half, _ = render(gl, scene(resolution=0.5), ("ssao", "ssao_reduced"))
    depth = full["linear_depth"][..., 0]
    reference = full["ssao"][..., 0] / 255.0
    upsampled = half["ssao"][..., 0] / 255.0
    # pixels within 3 of a depth break of more than 30 % (both sides of each silhouette)
    seen = depth > 0
    breaks = np.zeros_like(seen)
    for axis in (0, 1):
        for shift in (1, -1):
            other = np.roll(depth, shift, axis)
            breaks |= seen & (other > 0) & (np.maximum(other, depth) >
                                            1.3 * np.minimum(other, depth))
    band = dilate(breaks, 3) & seen
    assert band.sum() > 1000
    error = np.abs(upsampled - reference)[band]
    assert np.percentile(error, 99) < 0.1 and error.mean() < 0.012, \
        (np.percentile(error, 99), error.mean())
    # the scene can tell: the same grid upsampled without the depth test bleeds there
    plain = bilinear(half["ssao_reduced"][..., 0], (320, 240))
    assert np.percentile(np.abs(plain - reference)[band], 99) > 0.2
    # and away from edges the grid is close to the full-resolution occlusion
    inside = seen & ~band
    assert np.abs(upsampled - reference)[inside].mean() < 0.005


def test_resolution_1_is_the_full_resolution_occlusion_as_before(gl):
    """The ``ssao`` target at resolution = 1, byte for byte as the full-resolution passes made
    it before the reduced grid existed (tests/reference/ssao_full_resolution.png, llvmpipe)."""
    targets, passes = render(gl, scene((160, 120), resolution=1.0), ("ssao_raw", "ssao"))
    assert passes == ["screen.ssao", "screen.ssao_blur"]
    assert targets["ssao_raw"].shape == (120, 160, 1)
    want = np.asarray(Image.open(REFERENCE / "ssao_full_resolution.png"))
    np.testing.assert_array_equal(targets["ssao"][..., 0], want)


def test_forward_runs_the_reduced_grid_as_deferred_does(gl):
    deferred, _ = render(gl, scene((160, 120), forward=True), ("ssao",))
    forward, passes = render(gl, scene((160, 120), forward=True), ("ssao",), "forward")
    assert passes == ["screen.ssao", "screen.ssao_blur", "screen.ssao_upsample"]
    np.testing.assert_array_equal(forward["ssao"], deferred["ssao"])


@pytest.mark.parametrize("value, message", [
    (0.1, "effect[0].resolution: Input should be greater than or equal to 0.25"),
    (1.5, "effect[0].resolution: Input should be less than or equal to 1"),
    ("half", "effect[0].resolution: expected a number, not a string"),
])
def test_a_bad_resolution_is_refused_naming_the_key(value, message):
    with pytest.raises(InputError) as caught:
        scene(resolution=value)
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_the_command_line_refuses_a_bad_resolution_in_one_line(tmp_path, capsys):
    path = tmp_path / "scene.toml"
    path.write_text('[[object]]\nmesh = "builtin:sphere"\n\n[[effect]]\ntype = "ssao"\n'
                    "resolution = 0\n")
    code, _, err = run(capsys, "render", path, "-o", tmp_path / "out.png")
    assert_one_line_error(code, err, "resolution", "greater than or equal to 0.25")
    assert not (tmp_path / "out.png").exists()


def test_a_dump_and_a_pixel_history_take_the_reduced_grid(gl, tmp_path):
    from deferred.debug.capture import capture_frame
    from deferred.debug.dump import write_dump
    from deferred.debug.pixel_history import pixel_history

    with Renderer(scene((160, 120)), gl=gl) as renderer:
        capture = capture_frame(renderer)
        assert capture["screen.ssao"].arrays["ssao_raw"].shape == (60, 80, 2)
        write_dump(capture, tmp_path)
        assert (tmp_path / "contact.png").exists()
        y, x = np.unravel_index(np.argmin(capture.target("ssao")[..., 0]), (120, 160))
        events = {e.name: e for e in pixel_history(renderer, x, y)}
        # the grid passes are probed at the texel under the pixel
        raw = events["screen.ssao"].after["ssao_raw"]
        np.testing.assert_array_equal(raw, capture.target("ssao_raw")[y // 2, x // 2])
        occlusion = events["screen.ssao_upsample"].after["ssao"]
        np.testing.assert_array_equal(occlusion, capture.target("ssao")[y, x])
        assert occlusion[0] < 0.5  # the darkest pixel
        # the probes leave the frame as it was
        assert np.array_equal(renderer.render().image, capture.image)


def test_the_cost_model_counts_the_grid_and_the_upsample():
    from deferred.effects.ssao import SSAO, UPSAMPLE_SHARE
    from deferred.interfaces.work import RenderWork

    job = RenderWork((1280, 720))
    full, = SSAO(SSAO.Params(resolution=1.0)).work(job)
    half, = SSAO(SSAO.Params()).work(job)
    assert full.units == 1280 * 720
    assert half.units == pytest.approx(full.units * (0.25 + UPSAMPLE_SHARE))
    assert "resolution 0.5" in half.what
