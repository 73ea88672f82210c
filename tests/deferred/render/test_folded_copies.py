"""Copies folded into the pass that makes their source (deferred.render.pipeline): the stipple
snapshot into the tiled or clustered lighting, FXAA's source into the tone mapping. The frame
has fewer passes and the same bytes as with the copy passes."""

from __future__ import annotations

import numpy as np
import pytest

from deferred.render import pipeline
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene, scene_from_dict

FXAA_SCENE = {
    "size": [96, 64], "camera": {"position": [0.0, 1.0, 3.0], "target": [0.0, 0.4, 0.0]},
    "object": [{"mesh": "builtin:plane", "scale": 4.0},
               {"mesh": "builtin:cube", "position": [0.0, 0.5, 0.0], "rotation": [0, 30, 0],
                "scale": 0.4}],
    "light": [{"type": "directional", "direction": [-0.5, -1.0, -0.3]},
              {"type": "ambient"}],
    "effect": [{"type": "fxaa"}]}


def frame(gl, scene, pipeline_name="deferred", light_path=None):
    with Renderer(scene, pipeline_name, gl=gl, light_path=light_path) as renderer:
        result = renderer.render(hdr=True)
        return [p.name for p in renderer.passes], result.image, result.hdr


@pytest.mark.parametrize("light_path", ["tiled", "clustered"])
def test_the_stipple_snapshot_made_by_the_lighting_is_the_copy(gl, monkeypatch, light_path):
    if not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    demo = load_scene()
    demo.size = (96, 64)
    names, image, hdr = frame(gl, demo, light_path=light_path)
    assert "material.stipple_snapshot" not in names
    monkeypatch.setattr(pipeline, "leading_snapshots", lambda passes, source="": [])
    copied_names, copied_image, copied_hdr = frame(gl, demo, light_path=light_path)
    assert copied_names == [*names[:names.index(f"lighting.{light_path}") + 1],
                            "material.stipple_snapshot",
                            *names[names.index(f"lighting.{light_path}") + 1:]]
    np.testing.assert_array_equal(image, copied_image)
    np.testing.assert_array_equal(hdr, copied_hdr)


@pytest.mark.parametrize("pipeline_name", ["deferred", "forward"])
def test_fxaa_source_made_by_the_tone_mapping_is_the_copy(gl, monkeypatch, pipeline_name):
    names, image, _ = frame(gl, scene_from_dict(FXAA_SCENE), pipeline_name)
    assert names[-2:] == ["post.tonemap", "post.fxaa"]
    monkeypatch.setattr(pipeline, "leading_snapshots", lambda passes, source="": [])
    copied_names, copied_image, _ = frame(gl, scene_from_dict(FXAA_SCENE), pipeline_name)
    assert copied_names[-3:] == ["post.tonemap", "post.fxaa_source", "post.fxaa"]
    np.testing.assert_array_equal(image, copied_image)
