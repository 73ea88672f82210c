"""The pbr model's G-buffer data within its stated budget: 21 bytes a pixel of its 24; a
material of the model declaring more is refused, naming the budget."""

import pytest

from deferred.api import GBufferData
from deferred.errors import InputError
from deferred.materials.pbr import PbrMaterial
from deferred.materials.shading_models import PBR_GBUFFER_BUDGET, Pbr
from deferred.scene.loader import scene_from_dict


def test_a_pbr_scene_keeps_within_the_budget():
    scene = scene_from_dict({"object": [{"mesh": "builtin:sphere", "material": "pbr"}]})
    layout = scene.gbuffer_layout()
    assert layout.bytes_per_pixel == 21 <= PBR_GBUFFER_BUDGET == Pbr.gbuffer_budget
    assert "pbr_occlusion" in layout.describe()


def test_data_over_the_budget_is_refused():
    class Wider(PbrMaterial):
        gbuffer_data = (GBufferData("pbr_extra", "RGBA16F", ("a", "b", "c", "d")),)

    with pytest.raises(InputError, match="29 bytes a pixel, over its shading model pbr's "
                                         "budget of 24"):
        Wider().written_data()
