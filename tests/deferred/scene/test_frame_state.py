"""Each frame evaluates the user's scene into an immutable frame state and never writes to the
scene: edits show from the next frame on and nowhere else, renderers at different times over
one scene do not disturb each other, and change detection follows revisions."""

from __future__ import annotations

import numpy as np
import pytest

from deferred import Renderer
from deferred.scene import Camera, Scene, scene_from_toml
from deferred.scene.timeline import SceneEvaluator

ANIMATED = """
size = [64, 48]
[camera]
position = [0.0, 1.0, 5.0]
target = [0.0, 0.3, 0.0]

[[light]]
name = "key"
type = "directional"
direction = [-0.5, -1.0, -0.4]

[[group]]
name = "rig"

[[object]]
name = "ball"
parent = "rig"
mesh = "builtin:sphere"
params = { color = [0.8, 0.1, 0.1] }

[[object]]
name = "box"
mesh = "builtin:cube"
position = [1.5, 0.0, 0.0]
scale = 0.5

[[event]]
time = 1.0
object = "ball"
params = { color = [0.1, 0.8, 0.1] }

[[track]]
target = "object:rig"
keys = [{ time = 0.0, position = [-1.0, 0.0, 0.0] }, { time = 2.0, position = [1.0, 0.5, 0.0] }]

[[track]]
target = "light:key"
keys = [{ time = 0.0, intensity = 1.0 }, { time = 2.0, intensity = 3.0 }]

[[track]]
target = "camera"
keys = [{ time = 0.0, fov = 45.0 }, { time = 2.0, fov = 35.0 }]
"""


def frame_at(gl, text: str, time: float, pipeline: str = "deferred") -> np.ndarray:
    with Renderer(scene_from_toml(text, "a.toml"), pipeline, gl=gl) as renderer:
        return renderer.render(time=time).image


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_two_renderers_at_different_times_do_not_disturb_each_other(gl, pipeline):
    expected = {time: frame_at(gl, ANIMATED, time, pipeline) for time in (0.25, 1.75)}
    assert not np.array_equal(expected[0.25], expected[1.75])
    scene = scene_from_toml(ANIMATED, "a.toml")
    with Renderer(scene, pipeline, gl=gl) as early, Renderer(scene, pipeline, gl=gl) as late:
        for _ in range(2):
            assert np.array_equal(late.render(time=1.75).image, expected[1.75])
            assert np.array_equal(early.render(time=0.25).image, expected[0.25])
        assert early.state.object_state(scene.objects[0]).params.color == (0.8, 0.1, 0.1)
        assert late.state.object_state(scene.objects[0]).params.color == (0.1, 0.8, 0.1)


def two_balls() -> tuple[Scene, object, object]:
    scene = Scene(camera=Camera(position=(0.0, 0.0, 6.0), target=(0.0, 0.0, 0.0)),
                  size=(96, 48))
    scene.add_light("directional", direction=(-0.3, -0.5, -1.0))
    left = scene.add_object("builtin:sphere", label="left", position=(-1.5, 0.0, 0.0),
                            params={"color": (0.8, 0.2, 0.2)})
    right = scene.add_object("builtin:sphere", label="right", position=(1.5, 0.0, 0.0),
                             params={"color": (0.2, 0.2, 0.8)})
    return scene, left, right


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_an_edit_between_frames_changes_the_next_frame_and_nothing_else(gl, pipeline):
    scene, left, right = two_balls()
    with Renderer(scene, pipeline, gl=gl) as renderer:
        before = renderer.render(hdr=True).hdr
        kept = renderer.state.object_state(right)
        revision = left.revision
        left.set_params(color=(0.2, 0.9, 0.2))
        assert left.revision != revision and right.material.params.color == (0.2, 0.2, 0.8)
        after = renderer.render(hdr=True).hdr
        # the object nobody edited keeps its state (and what caches made of it)
        assert renderer.state.object_state(right) is kept
        again = renderer.render(hdr=True).hdr
    half = before.shape[1] // 2
    np.testing.assert_array_equal(before[:, half:], after[:, half:])  # the right ball
    assert np.abs(before[:, :half] - after[:, :half]).max() > 0.1  # the left ball
    np.testing.assert_array_equal(after, again)  # the edit holds; nothing else moves


def test_a_placement_edit_moves_the_object_from_the_next_frame(gl):
    scene, left, _ = two_balls()
    with Renderer(scene, gl=gl) as renderer:
        first = renderer.render().image
        left.position = (-1.0, 0.5, 0.0)
        moved = renderer.render().image
        np.testing.assert_allclose(renderer.state.object_state(left).model[:3, 3],
                                   (-1.0, 0.5, 0.0))
    assert not np.array_equal(first, moved)


def test_the_evaluator_keeps_what_did_not_change():
    scene = scene_from_toml(ANIMATED, "a.toml")
    ball, box = scene.objects
    evaluator = SceneEvaluator(scene)
    first = evaluator.evaluate(0.5)
    second = evaluator.evaluate(0.5)
    assert second.object_state(box) is first.object_state(box)  # static: the same state
    assert second.object_state(ball).version == first.object_state(ball).version
    assert second.lights[0] is first.lights[0]  # same evaluated parameters: the same copy
    later = evaluator.evaluate(1.5)
    assert later.object_state(box) is first.object_state(box)
    assert later.object_state(ball).version != first.object_state(ball).version
    assert later.lights[0] is not scene.lights[0]
    assert later.lights[0].params.intensity == pytest.approx(2.5)
    assert scene.lights[0].params.intensity == 1.0
    box.scale = 0.75  # an edit: a new revision, a new state
    assert evaluator.evaluate(1.5).object_state(box) is not first.object_state(box)
    with pytest.raises(ValueError, match="read-only"):
        later.object_state(ball).model[0, 3] = 1.0
