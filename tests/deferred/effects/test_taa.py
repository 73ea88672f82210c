"""Issue #25, temporal anti-aliasing (``[[effect]] type = "taa"``): motion vectors against a
numpy reference, a still camera converging, no ghost trail behind a moving edge, the history
starting again on a cut or a seek, the stipple's parity per sample; both pipelines."""

from __future__ import annotations

import numpy as np
import pytest

from deferred.effects.taa import TAA, camera_cut
from deferred.interfaces.effect import FrameMoment
from deferred.io.images import srgb_decode, srgb_encode
from deferred.render.renderer import Renderer
from deferred.scene.camera import Camera
from deferred.scene.loader import scene_from_dict

SIZE = (64, 48)
PIPELINES = ("deferred", "forward")
FPS = 24.0


def scene_with(objects, effects=({"type": "taa"},), camera=None, background=(0.02, 0.02, 0.03),
               size=SIZE, tracks=()):
    return scene_from_dict({
        "track": list(tracks),
        "size": list(size), "tonemap": "none", "background": list(background),
        "camera": camera or {"position": [0.0, 0.3, 3.0], "target": [0.0, 0.0, 0.0],
                             "fov": 45.0},
        "object": list(objects),
        "light": [{"type": "directional", "direction": [-0.4, -1.0, -0.5]},
                  {"type": "ambient", "color": [0.2, 0.2, 0.22]}],
        "effect": list(effects)})


SPHERE = {"mesh": "builtin:sphere", "position": [0.0, 0.0, 0.0], "scale": 0.6,
          "params": {"color": [0.9, 0.7, 0.4]}}
WALL = {"mesh": "builtin:plane", "position": [0.0, 0.0, -1.5], "rotation": [90.0, 0.0, 0.0],
        "scale": 6.0, "params": {"color": [0.3, 0.4, 0.6]}}


def moving_sphere(speed: float):
    """The sphere (named ball) moving +x at ``speed`` world units a second (a linear track)."""
    return [{**SPHERE, "name": "ball"}], [
        {"target": "object:ball", "interpolation": "linear",
         "keys": [{"time": 0.0, "position": [-1.0, 0.0, 0.0]},
                  {"time": 10.0, "position": [-1.0 + 10.0 * speed, 0.0, 0.0]}]}]


def linear(image: np.ndarray) -> np.ndarray:
    return srgb_decode(image[..., :3].astype(np.float64) / 255.0)


def motion_reference(renderer: Renderer, depth: np.ndarray, previous_vp: np.ndarray,
                     moving=None) -> np.ndarray:
    """Each pixel's motion in pixels (bottom row first, as GL): its point from the hardware
    depth through the frame's jittered projection, this frame's unjittered view-projection
    against the last; ``moving`` = (centre, radius, offset): points on that sphere moved by
    offset since the last frame."""
    frame = renderer.last_frame
    width, height = frame.width, frame.height
    x, y = np.meshgrid((np.arange(width) + 0.5) / width * 2 - 1,
                       (np.arange(height) + 0.5) / height * 2 - 1)
    far = depth >= 1.0
    ndc = np.stack([x, y, np.where(far, 1.0, depth * 2 - 1), np.ones_like(x)], axis=-1)
    view = ndc @ np.linalg.inv(frame.projection).T
    view = view[..., :3] / view[..., 3:]
    to_world = np.linalg.inv(frame.view)
    w = np.where(far, 0.0, 1.0)[..., None]
    world = np.concatenate([view, w], axis=-1) @ to_world.T
    before = world.copy()
    if moving is not None:
        centre, radius, offset = moving
        on = ~far & (np.abs(np.linalg.norm(world[..., :3] - centre, axis=-1) - radius) < 0.02)
        before[on, :3] -= offset

    def pixels(clip):
        return clip[..., :2] / clip[..., 3:] * 0.5 * np.array([width, height])

    return pixels(world @ frame.view_projection.T) - pixels(before @ previous_vp.T)


@pytest.mark.parametrize("pipeline", PIPELINES)
def test_motion_vectors_of_a_moving_camera_match_numpy(gl, pipeline):
    """A still scene, the camera moving sideways: every pixel's motion (the background's as
    a direction) equals its point's reprojection by the two frames' cameras."""
    scene = scene_with([SPHERE, WALL])
    with Renderer(scene, pipeline, gl=gl) as renderer:
        renderer.render(time=0.0)
        before = renderer.last_frame.view_projection
        scene.camera = Camera(position=(0.25, 0.4, 3.0), target=(0.05, 0.0, 0.0))
        renderer.render(time=1.0 / FPS)
        assert renderer.last_frame.history_kept
        motion = renderer.targets.read("motion")
        depth = renderer.targets.read("depth")[..., 0]
        reference = motion_reference(renderer, depth.astype(np.float64), before)
    assert np.abs(reference).max() > 1.0  # the camera did move the image
    error = np.abs(motion - reference).max(axis=-1)
    assert np.percentile(error, 99) < 0.05 and error.max() < 0.25


@pytest.mark.parametrize("pipeline", PIPELINES)
def test_motion_vectors_of_a_moving_object_match_numpy(gl, pipeline):
    """A sphere moving over a still wall, the camera still: the sphere's pixels move by its
    points' projections, the wall's not at all (its silhouette's pixel ring aside, where the
    motion is dilated or mixed)."""
    speed = 0.5
    objects, tracks = moving_sphere(speed)
    scene = scene_with([*objects, WALL], tracks=tracks)
    t0, t1 = 1.0, 1.0 + 1.0 / FPS
    with Renderer(scene, pipeline, gl=gl) as renderer:
        renderer.render(time=t0)
        before = renderer.last_frame.view_projection
        renderer.render(time=t1)
        motion = renderer.targets.read("motion")
        depth = renderer.targets.read("depth")[..., 0].astype(np.float64)
        centre = np.array([-1.0 + speed * t1, 0.0, 0.0])
        reference = motion_reference(renderer, depth, before,
                                     (centre, 0.6, np.array([speed / FPS, 0.0, 0.0])))
    moving = np.linalg.norm(reference, axis=-1) > 0.1
    assert moving.sum() > 50
    ring = np.zeros_like(moving)  # pixels beside the silhouette
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            ring |= np.roll(moving, (dy, dx), axis=(0, 1)) != moving
    error = np.abs(motion - reference).max(axis=-1)
    assert error[~ring].max() < 0.05
    assert np.abs(motion[~moving & ~ring]).max() < 1e-3


@pytest.mark.parametrize("pipeline", PIPELINES)
def test_a_still_camera_converges(gl, pipeline):
    """Frame to frame the jitter changes a frame without taa by many levels on the edges; with
    it the change dies away, and the frame comes near the 4x4 supersampled one."""
    scene = scene_with([SPHERE, WALL])
    with Renderer(scene, pipeline, gl=gl) as renderer:
        images = [renderer.render(time=k / FPS).image.astype(np.float64) for k in range(48)]
        first_change = np.abs(images[1] - images[0]).max()
        last_change = np.abs(images[-1] - images[-2])
    assert first_change > 20
    assert last_change.mean() < 0.05 and last_change.max() <= 6
    plain = scene_with([SPHERE, WALL], effects=(), size=(SIZE[0] * 4, SIZE[1] * 4))
    with Renderer(plain, pipeline, gl=gl) as renderer:
        big = linear(renderer.render().image)
        single = renderer.render().image  # noqa: F841 - the same size: not a reference
    reference = big.reshape(SIZE[1], 4, SIZE[0], 4, 3).mean(axis=(1, 3))
    with Renderer(scene_with([SPHERE, WALL], effects=()), pipeline, gl=gl) as renderer:
        aliased = renderer.render().image
    error_taa = np.abs(images[-1][..., :3] / 255.0 - srgb_encode(reference)).mean()
    error_one = np.abs(aliased[..., :3] / 255.0 - srgb_encode(reference)).mean()
    assert error_taa < 0.6 * error_one


def object_mask(image: np.ndarray) -> np.ndarray:
    """The bright sphere against the dark background."""
    return image[..., :3].astype(np.float64).mean(axis=-1) > 60


@pytest.mark.parametrize("pipeline", PIPELINES)
def test_a_moving_object_leaves_no_ghost_trail(gl, pipeline):
    """The sphere crossing the frame at about 1.5 pixels a frame: where the taa frame differs
    from the frame without taa, it is within 2 pixels of the sphere's edge there."""
    objects, tracks = moving_sphere(0.6)
    scene = scene_with(objects, background=(0.0, 0.0, 0.0), tracks=tracks)
    times = [1.0 + k / FPS for k in range(24)]
    with Renderer(scene, pipeline, gl=gl) as renderer:
        for time in times:
            taa = renderer.render(time=time).image
    with Renderer(scene_with(objects, effects=(), background=(0.0, 0.0, 0.0), tracks=tracks),
                  pipeline, gl=gl) as renderer:
        reference = renderer.render(time=times[-1]).image
    mask = object_mask(reference)
    assert 100 < mask.sum() < mask.size / 2
    edge = mask & ~(np.roll(mask, 1, 0) & np.roll(mask, -1, 0) & np.roll(mask, 1, 1) &
                    np.roll(mask, -1, 1))
    wrong = np.abs(taa[..., :3].astype(np.float64) - reference[..., :3]).max(axis=-1) > 40
    ey, ex = np.nonzero(edge)
    wy, wx = np.nonzero(wrong)
    if len(wy):
        distance = np.sqrt((wy[:, None] - ey[None]) ** 2 + (wx[:, None] - ex[None]) ** 2)
        assert distance.min(axis=1).max() <= 2.0
    # the trailing side: no bright pixel of the sphere's history left behind it
    ghost = object_mask(taa) & ~mask
    gy, gx = np.nonzero(ghost)
    if len(gy):
        distance = np.sqrt((gy[:, None] - ey[None]) ** 2 + (gx[:, None] - ex[None]) ** 2)
        assert distance.min(axis=1).max() <= 2.0


@pytest.mark.parametrize("pipeline", PIPELINES)
def test_a_cut_or_a_seek_starts_the_history_again(gl, pipeline):
    """After a camera jump, or a time that is not the next frame's, the frame is the one a
    fresh renderer makes there (no history, the first jitter)."""
    scene = scene_with([SPHERE, WALL])
    jumped = Camera(position=(2.5, 1.0, 1.5), target=(0.0, 0.0, 0.0))
    with Renderer(scene, pipeline, gl=gl) as renderer:
        for k in range(6):
            renderer.render(time=k / FPS)
        scene.camera = jumped
        cut = renderer.render(time=6 / FPS).image
        assert not renderer.last_frame.history_kept
        renderer.render(time=7 / FPS)
        assert renderer.last_frame.history_kept
        seek = renderer.render(time=2 / FPS).image  # back in time
        assert not renderer.last_frame.history_kept
    with Renderer(scene, pipeline, gl=gl) as fresh:
        assert np.array_equal(fresh.render(time=6 / FPS).image, cut)
    with Renderer(scene, pipeline, gl=gl) as fresh:
        assert np.array_equal(fresh.render(time=2 / FPS).image, seek)


def test_only_a_step_back_or_over_max_step_is_a_seek():
    """A step of another length than the last (a viewer playing by the window's frames) keeps
    the history; a step back, or over ``max_step``, starts it again."""
    taa, camera = TAA(), Camera(position=(0.0, 0.3, 3.0))
    last = FrameMoment(0.0, camera, None, 1 / 60)
    assert taa.keeps_history(last, FrameMoment(0.1, camera, None, 1 / 59))
    assert taa.keeps_history(last, FrameMoment(0.0, camera, None, 0.0))  # a still frame
    assert not taa.keeps_history(last, FrameMoment(0.0, camera, None, -1 / 60))
    assert not taa.keeps_history(last, FrameMoment(0.3, camera, None, 0.3))  # max_step 0.25


def test_steps_of_varying_length_keep_the_history(gl):
    """Frames at irregular times forward (a window's frame rate) carry one history on."""
    scene = scene_with([SPHERE, WALL])
    with Renderer(scene, "deferred", gl=gl) as renderer:
        for k, time in enumerate((0.0, 1 / 60, 1 / 60 + 1 / 59, 0.05, 0.09)):
            renderer.render(time=time)
            assert renderer.last_frame.history_kept == (k > 0)
            assert renderer.last_frame.sample_index == k


def test_what_is_a_cut():
    base = Camera(position=(0.0, 0.0, 4.0), target=(0.0, 0.0, 0.0))
    assert not camera_cut(base, base, 20.0, 0.25)
    turned = Camera(position=(4.0 * np.sin(0.05), 0.0, 4.0 * np.cos(0.05)))
    assert not camera_cut(base, turned, 20.0, 0.25)  # a turntable's step
    assert camera_cut(base, Camera(position=(0.0, 0.0, 4.0), target=(4.0, 0.0, 0.0)),
                      20.0, 0.25)  # turned 45 degrees
    assert camera_cut(base, Camera(position=(0.0, 0.0, 2.0)), 20.0, 0.25)  # moved half way
    assert camera_cut(base, Camera(position=(0.0, 0.0, 4.0), fov=90.0), 20.0, 0.25)


def test_the_jitter_follows_the_history(gl):
    """Each frame of a history after the first its Halton (2, 3) offset (the first, a still
    with taa, is not moved); a frame without taa none."""
    scene = scene_with([SPHERE])
    with Renderer(scene, gl=gl) as renderer:
        jitters = []
        for k in range(3):
            renderer.render(time=k / FPS)
            jitters.append(renderer.last_frame.jitter)
            assert renderer.last_frame.sample_index == k
    assert jitters == [(0.0, 0.0), (-0.25, pytest.approx(1 / 6)),
                       (0.25, pytest.approx(-7 / 18))]
    with Renderer(scene_with([SPHERE], effects=()), gl=gl) as renderer:
        renderer.render(time=0.0)
        renderer.render(time=1 / FPS)
        assert renderer.last_frame.jitter == (0.0, 0.0)
        assert renderer.last_frame.sample_index == 0


@pytest.mark.slow
def test_the_stipple_parity_covers_every_pixel_over_four_samples(gl):
    """Revie's 1-in-4 pattern moves per sample: the pixels the fur's stipple pass writes in
    four samples are one pixel of each 2x2 tile each, disjoint, and cover the fur's interior."""
    scene = scene_with([{"mesh": "builtin:sphere", "material": "revie_fur", "scale": 0.8,
                         "params": {"shells": 4}}], effects=())
    written = []
    with Renderer(scene, gl=gl) as renderer:
        for index in range(4):
            seen = {}

            def before(render_pass, frame, seen=seen):
                if render_pass.name.endswith(".stipple"):
                    seen["before"] = frame.targets.read("linear_depth")[..., 0].copy()

            def after(render_pass, frame, seen=seen):
                if render_pass.name.endswith(".stipple"):
                    seen["after"] = frame.targets.read("linear_depth")[..., 0].copy()

            renderer.render(before_pass=before, on_pass=after, jitter=(0.0, 0.0),
                            sample_index=index)
            written.append(seen["before"] != seen["after"])
    union = np.zeros_like(written[0], dtype=int)
    for mask in written:
        ys, xs = np.nonzero(mask)
        assert len(ys) > 50
        assert len(set(zip(ys // 2, xs // 2, strict=True))) == len(ys)  # one pixel a tile
        union += mask
    assert union.max() == 1  # disjoint
    interior = np.ones_like(union, dtype=bool)
    fur = written[0] | written[1] | written[2] | written[3]
    for dy in (-2, -1, 0, 1, 2):
        for dx in (-2, -1, 0, 1, 2):
            interior &= np.roll(fur, (dy, dx), axis=(0, 1))
    assert interior.sum() > 50 and np.all(union[interior] == 1)


def test_transparent_surfaces_are_sorted_each_frame(gl):
    """Two glass panes swapping places in depth on a track: each frame draws the far one
    first, as a renderer built at that time does (they were sorted once, when the passes
    were built)."""
    glass = {"material": "stipple_glass", "mesh": "builtin:plane",
             "rotation": [90.0, 0.0, 0.0], "scale": 1.2}
    objects = [{**glass, "name": "red", "position": [0.0, 0.0, 0.5],
                "params": {"color": [1.0, 0.1, 0.1], "opacity": 0.7}},
               {**glass, "name": "blue", "position": [0.1, 0.0, -0.5],
                "params": {"color": [0.1, 0.1, 1.0], "opacity": 0.7}}]
    tracks = [{"target": "object:red", "interpolation": "linear",
               "keys": [{"time": 0.0, "position": [0.0, 0.0, 0.5]},
                        {"time": 1.0, "position": [0.0, 0.0, -1.0]}]}]
    scene = scene_with([*objects, SPHERE], effects=(), tracks=tracks)
    with Renderer(scene, "forward", gl=gl) as renderer:
        renderer.render(time=0.0)
        moved = renderer.render(time=1.0).image
    with Renderer(scene, "forward", gl=gl) as fresh:
        assert np.array_equal(fresh.render(time=1.0).image, moved)


@pytest.mark.parametrize("pipeline", PIPELINES)
def test_fur_beyond_the_mesh_moves_with_its_object(gl, pipeline):
    """A furred sphere moving sideways over the empty background: the fur's fringe, where its
    shells and fins are drawn beyond the mesh's silhouette, has the object's motion (its
    material's motion_extent), not the background's none."""
    speed = 1.2
    objects, tracks = moving_sphere(speed)
    objects = [{**objects[0], "material": "revie_fur",
                "params": {"shells": 8, "fur_length": 0.25}}]
    scene = scene_with(objects, background=(0.0, 0.0, 0.0), tracks=tracks)
    t0, t1 = 1.0, 1.0 + 1.0 / FPS
    with Renderer(scene, pipeline, gl=gl) as renderer:
        renderer.render(time=t0)
        before = renderer.last_frame.view_projection
        image = renderer.render(time=t1).image
        frame = renderer.last_frame
        motion = renderer.targets.read("motion")[::-1]
        depth = renderer.targets.read("depth")[::-1, :, 0]
    shown = image[..., :3].max(axis=-1) > 8
    fringe = shown & (depth >= 1.0)  # fur drawn where the mesh is not
    assert fringe.sum() > 20

    def pixels(vp, point):
        clip = vp @ np.append(point, 1.0)
        return clip[:2] / clip[3] * 0.5 * np.array([frame.width, frame.height])

    centre = np.array([-1.0 + speed * t1, 0.0, 0.0])
    expected = pixels(frame.view_projection, centre) - \
        pixels(before, centre - [speed / FPS, 0.0, 0.0])
    assert expected[0] > 0.8
    assert np.allclose(motion[fringe].mean(axis=0), expected, atol=0.2 * expected[0])


def test_view_motion_shows_the_frame_before(tmp_path, capsys):
    """``render --view motion --time T`` renders the frame before T first, so the view holds
    this frame's motion: the camera on a track moves the image, the background too."""
    from deferred.cli import main
    from deferred.io.images import read_channels

    scene = tmp_path / "moving.toml"
    scene.write_text(
        'size = [64, 48]\n[camera]\nposition = [0.0, 0.3, 3.0]\n'
        '[[object]]\nmesh = "builtin:sphere"\n[[light]]\ntype = "ambient"\n'
        '[[effect]]\ntype = "taa"\n'
        '[[track]]\ntarget = "camera"\ninterpolation = "linear"\n'
        'keys = [{ time = 0.0, position = [0.0, 0.3, 3.0] },'
        ' { time = 2.0, position = [2.0, 0.3, 3.0] }]\n')
    out = tmp_path / "motion.exr"
    assert main(["render", str(scene), "--view", "motion", "--time", "1", "-o", str(out)]) == 0
    capsys.readouterr()
    motion = read_channels(out)[0][..., :2]
    assert np.median(np.linalg.norm(motion, axis=-1)) > 0.3  # the image moved
    png = tmp_path / "motion.png"
    assert main(["render", str(scene), "--view", "motion", "--time", "1", "-o", str(png)]) == 0
