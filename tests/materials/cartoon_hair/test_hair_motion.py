"""cartoon_hair's own motion in the motion vectors (#39): with the camera and the head still,
the simulated strands swaying in the wind move in the motion target (HairMotion: the tubes
drawn from their surface of the frame before to this frame's), the hair at rest does not, and
TAA over swaying hair ghosts less with the vectors than without them; both pipelines."""

from __future__ import annotations

import numpy as np
import pytest

from deferred.io.images import srgb_decode
from deferred.materials.cartoon_hair.state import HairMotion
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

FPS = 24.0
PIPELINES = ("deferred", "forward")


def windy_head(wind: float, gravity: float = -9.81, effects=({"type": "taa"},),
               gusts: bool = False):
    """The spiky head of the hair tests, the wind along +x from t = 0 (``gusts``: turning
    back and forth every 0.3 s), no settling: the strands are moving early on."""
    events = [{"time": t, "object": "head", "params": {"wind": [w, 0.0, 0.0]}}
              for t, w in ((0.3, -wind), (0.6, wind), (0.9, -wind))] if gusts else []
    return scene_from_dict({
        "event": events,
        "size": [128, 128], "tonemap": "none", "background": [0.9, 0.9, 0.9],
        "camera": {"position": [0.0, 0.05, 0.55], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"name": "head", "mesh": "builtin:head?segments=48&rings=32",
                    "material": "cartoon_hair",
                    "params": {"strands": 60, "style": "spiky", "wind": [wind, 0.0, 0.0],
                               "gravity": [0.0, gravity, 0.0]}}],
        "light": [{"type": "directional", "direction": [-0.5, -0.6, -0.6]}],
        "effect": list(effects)})


def motion_after(renderer: Renderer, times) -> np.ndarray:
    """Each pixel's motion length (pixels) after rendering ``times`` in turn (top row first)."""
    for time in times:
        renderer.render(time=time)
    assert renderer.last_frame.history_kept
    return np.linalg.norm(renderer.targets.read("motion")[::-1], axis=-1)


@pytest.mark.parametrize("pipeline", PIPELINES)
def test_a_still_camera_sees_the_hair_move_in_the_motion_vectors(gl, pipeline):
    step = 1.0 / FPS
    with Renderer(windy_head(3.0), pipeline, gl=gl) as renderer:
        moving = motion_after(renderer, (0.1, 0.1 + step))
        hair = renderer.targets.read("strand_id")[::-1][..., 0] > 0.5 \
            if pipeline == "deferred" else None
        still = motion_after(renderer, (0.1 + step,))  # the same time again: nothing moved
    with Renderer(windy_head(0.0, gravity=0.0), pipeline, gl=gl) as renderer:
        at_rest = motion_after(renderer, (0.1, 0.1 + step))
    # the strands swaying: a share of the hair moves by a visible fraction of a pixel, the
    # tips by more than a pixel
    assert (moving > 0.1).sum() > 200, (moving > 0.1).sum()
    assert moving.max() > 1.0
    if hair is not None:  # only the hair: the head and the background stay still
        assert moving[~hair].max() < 0.02
    assert still.max() < 0.02
    assert at_rest.max() < 0.02  # no wind, no gravity: the strands stay at rest


def test_the_numpy_tubes_move_as_the_gpu_ones(gl):
    """The tubes built by numpy (a GL 3.3 context) keep their frame before too: the same
    motion vectors as those built by compute shaders."""
    from deferred.gl.context import Features, GLContext

    gl33 = GLContext(gl.ctx, Features(storage_buffers=False, compute_shaders=False))
    times = (0.1, 0.1 + 1.0 / FPS)
    motions = []
    for context in (gl, gl33):
        with Renderer(windy_head(3.0), gl=context) as renderer:
            motions.append(motion_after(renderer, times))
    assert (motions[0] > 0.1).sum() > 200
    assert np.abs(motions[0] - motions[1]).max() < 0.01


def linear(image: np.ndarray) -> np.ndarray:
    return srgb_decode(image[..., :3].astype(np.float64) / 255.0)


@pytest.mark.parametrize("pipeline", PIPELINES)
def test_taa_over_swaying_hair_ghosts_less_with_its_motion(gl, pipeline, monkeypatch):
    """Hair swaying in gusts before a still camera, 16 frames of TAA: the last frames against
    the frames supersampled (16 jittered renders, what a still picture converges to) differ
    less with the hair's motion in the vectors than with the tubes left out of them (the
    history smeared along where the strands were)."""
    times = [0.5 + k / FPS for k in range(16)]
    with Renderer(windy_head(6.0, effects=(), gusts=True), pipeline, gl=gl) as renderer:
        references = [linear(renderer.render_samples(16, time=t).image) for t in times[-3:]]

    def taa_error() -> float:
        with Renderer(windy_head(6.0, gusts=True), pipeline, gl=gl) as renderer:
            images = [renderer.render(time=t).image for t in times]
        return float(np.mean([np.abs(linear(image) - reference).mean()
                              for image, reference in zip(images[-3:], references,
                                                                strict=True)]))

    with_vectors = taa_error()
    monkeypatch.setattr(HairMotion, "surfaces", lambda self, frame, obj: ())
    without = taa_error()
    print(f"{pipeline}: TAA against 16 samples, mean |error| {255 * with_vectors:.2f} levels "
          f"with the hair's motion, {255 * without:.2f} without")
    assert with_vectors < 0.85 * without
