"""Every example scene loads and renders (small) in both pipelines."""


import numpy as np
import pytest
from locations import ROOT

from deferred.gl.context import Features, GLContext
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene

EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))


@pytest.mark.slow
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_renders(gl, path):
    """Both pipelines, both GLSL levels (a GL 4.3 context, one limited to GL 3.3): every
    program of every material compiles and links on this driver and draws something."""
    scene = load_scene(path)
    contexts = [gl, GLContext(gl.ctx, Features(storage_buffers=False))]
    images = []
    for context in contexts:
        for pipeline in ("deferred", "forward"):
            # volumes / naive: the paths both light-buffer variants run
            with Renderer(scene, pipeline, (96, 54), gl=context,
                          light_path="volumes") as renderer:
                result = renderer.render()
            assert np.isfinite(result.hdr).all()
            assert result.image[..., :3].std() > 2.0  # something is on screen
            images.append(result.image)
    if gl.features.storage_buffers:  # GLSL 430 and 330 give the same frame
        assert np.array_equal(images[0], images[2]) and np.array_equal(images[1], images[3])
