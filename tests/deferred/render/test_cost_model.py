"""The cost model of a render (deferred.render.cost): what it counts grows with what drives the
work, and what it counts before the meshes load is a lower bound of what it counts after."""

from __future__ import annotations

import pytest
from locations import EXAMPLES

from deferred.cli.budget import render_work
from deferred.io.cost import Per
from deferred.render.cost import loaded_objects, predict_render
from deferred.scene.loader import load_scene, scene_from_toml
from deferred.scene.timeline import SceneEvaluator

FUR = """size = [320, 240]
[camera]
position = [0.0, 0.0, {distance}]
target = [0.0, 0.0, 0.0]
[[object]]
name = "ball"
mesh = "builtin:sphere?segments=32&rings=16"
material = "revie_fur"
[object.params]
shells = {shells}
min_shells = {shells}
{extra}
[[light]]
type = "directional"
"""


def predicted(scene, size=None, samples=1, times=(0.0,)):
    size = size or scene.size
    state = SceneEvaluator(scene).evaluate(0.0)
    return predict_render(render_work(size, samples, list(times), "deferred"), state.lights,
                          state.effects, loaded_objects(state, size))


def term(prediction, fragment):
    return sum(w.seconds for w in prediction.works if fragment in w.what)


def fur(distance=3.0, shells=16, extra=""):
    return scene_from_toml(FUR.format(distance=distance, shells=shells, extra=extra), "f.toml")


def test_shells_count_with_the_shells_and_the_pixels_they_cover():
    near = predicted(fur(shells=16))
    assert term(predicted(fur(shells=32)), "shells over") == \
        pytest.approx(2 * term(near, "shells over"))
    assert term(predicted(fur(shells=32)), "shells x") == pytest.approx(2 * term(near, "shells x"))
    assert 0.0 < term(predicted(fur(distance=12.0)), "shells over") < \
        term(near, "shells over") / 4
    assert term(predicted(fur(), size=(640, 480)), "shells over") == \
        pytest.approx(4 * term(near, "shells over"), rel=0.01)
    assert term(predicted(fur(extra="fins = false")), "fins") == 0.0 < term(near, "fins")


def test_samples_and_frames_repeat_what_they_repeat():
    scene = fur()
    one = predicted(scene)
    many = predicted(scene, samples=8, times=[0.0, 0.1, 0.2])
    assert many.sample_seconds() == pytest.approx(one.sample_seconds() + term(many, "read back"))
    render_terms = sum(w.seconds for w in one.works if w.per is Per.RENDER)
    assert many.seconds > 24 * one.sample_seconds() + render_terms


def test_hair_counts_strands_samples_and_sides_and_its_strokes():
    text = (EXAMPLES / "cartoon_hair" / "spiky_head.toml").read_text()
    base = predicted(scene_from_toml(text, "h.toml"))
    double = predicted(scene_from_toml(text.replace("strands = 150", "strands = 300"), "h.toml"))
    assert term(double, "tubes of") == pytest.approx(2 * term(base, "tubes of"))
    assert term(double, "making the tubes") == pytest.approx(2 * term(base, "making the tubes"))
    stroked = predicted(scene_from_toml(text.replace("strands = 150", "strands = 150\n"
                                                     "silhouettes = true"), "h.toml"))
    assert term(base, "silhouettes") == 0.0 < term(stroked, "silhouettes")
    later = predicted(scene_from_toml(text, "h.toml"), times=[2.0])
    assert term(later, "steps x") > term(base, "steps x")


@pytest.mark.parametrize("path", [None, EXAMPLES / "fig2_21_final.toml",
                                  EXAMPLES / "cartoon_hair" / "spiky_head.toml",
                                  EXAMPLES / "shell_fur" / "table1_torus.toml"])
def test_what_is_counted_before_the_meshes_load_is_a_lower_bound(path):
    before = []

    def weigh(scene, objects):
        state = scene  # no objects yet: the lights and effects are the scene's
        before.append(predict_render(render_work(scene.size, 4, [0.0], "deferred"),
                                     state.lights, state.effects, objects))

    scene = load_scene(path, before_meshes=weigh)
    after = predicted(scene, samples=4)
    assert 0.0 < before[0].seconds <= after.seconds
