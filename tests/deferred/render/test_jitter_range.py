"""``Renderer.render(jitter=...)`` is a sub-pixel offset: NaN, infinite, huge or misshapen
jitters are an InputError saying the range, not a flat frame."""

from __future__ import annotations

import numpy as np
import pytest

from deferred.errors import InputError
from deferred.scene.loader import scene_from_dict

SCENE = {"object": [{"mesh": "builtin:sphere"}],
         "light": [{"type": "point", "position": [0.0, 2.0, 2.0]}]}


@pytest.mark.parametrize("jitter", [(float("nan"), 0.0), (1e30, 0.0), (0.0, float("inf")),
                                    (1.5, 0.0), (True, 0.0), ("a", "b"), (0.1, 0.1, 0.1),
                                    "ab", 0.5])
def test_a_jitter_out_of_range_is_refused_saying_the_range(render, jitter):
    with pytest.raises(InputError, match=r"^jitter: a jitter is a sub-pixel offset \(x, y\) of "
                                         r"finite numbers within \+-1 pixel, got "):
        render(scene_from_dict(SCENE), size=(32, 24), jitter=jitter)


def test_a_sub_pixel_jitter_moves_the_image(render):
    still, _ = render(scene_from_dict(SCENE), size=(32, 24))
    moved, _ = render(scene_from_dict(SCENE), size=(32, 24), jitter=np.array([0.5, -0.25]))
    assert np.isfinite(moved.hdr).all() and not np.array_equal(still.image, moved.image)
