"""Every example scene loads and renders (small) in both pipelines."""

from pathlib import Path

import numpy as np
import pytest

from deferred.scene import load_scene

EXAMPLES = sorted((Path(__file__).parents[2] / "examples").glob("*.toml"))


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_renders(render, path):
    scene = load_scene(path)
    for pipeline in ("deferred", "forward"):
        result, _ = render(scene, pipeline, size=(96, 54))
        assert np.isfinite(result.hdr).all()
        assert result.image[..., :3].std() > 2.0  # something is on screen
