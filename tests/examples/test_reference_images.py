"""Example scenes against reference images made on llvmpipe.

Regenerate after an intended change of the images (and look at them before committing):

    DEFERRED_UPDATE_REFERENCES=1 python -m pytest tests/examples/test_reference_images.py

On a mismatch the rendered image and an amplified difference are written to tests/_failures/.
"""

import os

import numpy as np
import pytest
from locations import ROOT

from deferred.io.images import read_image, write_image
from deferred.scene.loader import load_scene

REFERENCES = ROOT / "tests" / "reference"
FAILURES = ROOT / "tests" / "_failures"
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))
SIZE = (192, 108)
MEAN_ERROR = 1.0 / 255.0  # mean absolute error over all pixels and channels
FAR_OFF = 0.01  # at most this fraction of pixels may differ by more than 16/255


@pytest.mark.slow
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_matches_reference(render, path):
    result, _ = render(load_scene(path), size=SIZE)
    image = result.image
    reference = REFERENCES / f"{path.stem}.png"
    if os.environ.get("DEFERRED_UPDATE_REFERENCES") == "1" or not reference.exists():
        if os.environ.get("DEFERRED_UPDATE_REFERENCES") != "1":
            pytest.fail(f"no reference image {reference.name}; see this module's docstring")
        write_image(reference, image)
        pytest.skip(f"wrote {reference.name}")
    want = np.round(read_image(reference) * 255.0)
    got = image.astype(np.float64)
    difference = np.abs(got - want)[..., :3] / 255.0
    mean_error = difference.mean()
    far_off = (difference.max(axis=-1) > 16 / 255).mean()
    if mean_error > MEAN_ERROR or far_off > FAR_OFF:
        FAILURES.mkdir(exist_ok=True)
        write_image(FAILURES / f"{path.stem}.png", image)
        amplified = np.clip(difference.max(axis=-1) * 8.0, 0.0, 1.0)
        write_image(FAILURES / f"{path.stem}.diff.png", (amplified * 255).astype(np.uint8))
        pytest.fail(f"{path.stem}: mean error {mean_error * 255:.2f}/255, "
                    f"{far_off:.1%} of pixels off by >16/255 (see {FAILURES})")
