"""A full-screen pass selects one material's or shading model's pixels by name
(select_surfaces and gbuffer/select.glsl): it changes those pixels and no other."""

from pathlib import Path

import numpy as np
import pytest

from deferred.api import (
    COMPOSITE,
    NORMAL_EXPONENT_ID,
    FullscreenPass,
    InputError,
    Phase,
    register_shader_root,
    select_surfaces,
)
from deferred.debug.capture import capture_frame
from deferred.gbuffer.surface_id import split_surface_id
from deferred.interfaces import registry
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SHADERS = Path(__file__).parents[2] / "fixtures" / "selection_shaders"


def scene():
    return scene_from_dict({
        "size": [64, 48], "tonemap": "none",
        "camera": {"position": [0.0, 0.0, 4.0], "target": [0.0, 0.0, 0.0], "fov": 45.0},
        "object": [{"mesh": "builtin:sphere", "material": "standard", "position": [-0.9, 0, 0],
                    "scale": 0.8},
                   {"mesh": "builtin:sphere", "material": "pbr", "position": [0.9, 0, 0],
                    "scale": 0.8},
                   {"mesh": "builtin:torus", "material": "standard", "position": [0, 0, -1.5],
                    "params": {"color": [0.2, 0.4, 0.8]}}],
        "light": [{"type": "directional", "direction": [0.0, -0.5, -1.0]}]})


@pytest.mark.parametrize("selection, kind", [
    ({"materials": ("pbr",)}, "material"),
    ({"shading_models": ("blinn_phong",)}, "shading_model")])
def test_a_full_screen_pass_changes_the_selected_pixels_only(gl, selection, kind):
    register_shader_root(SHADERS)
    defines = select_surfaces(**selection)
    with Renderer(scene(), "deferred", gl=gl, strict=True, light_path="volumes") as plain:
        before = plain.render(hdr=True).hdr
    with Renderer(scene(), "deferred", gl=gl, strict=True, light_path="volumes") as renderer:
        renderer.insert_pass(FullscreenPass(
            "material.mark", Phase.MATERIAL, "selection_test/mark.frag",
            {"u_normal_exponent_id": NORMAL_EXPONENT_ID}, (COMPOSITE,), blend="add",
            defines=defines), after="material.composite_copy")
        capture = capture_frame(renderer)
        after = capture.target(COMPOSITE)
        ids = np.rint(capture.target(NORMAL_EXPONENT_ID)[..., 3])
    material, model = split_surface_id(ids)
    if kind == "material":
        expected = material == registry.materials.get("pbr").type_id
    else:
        expected = (model == registry.shading_models.get("blinn_phong").type_id) & (ids > 0)
    changed = np.abs(after[..., 0] - before[..., 0]) > 0.5
    assert expected.sum() > 100 and (~expected & (ids > 0)).sum() > 100
    np.testing.assert_array_equal(changed, expected)
    np.testing.assert_array_equal(after[..., 1:3], before[..., 1:3])


def test_unknown_names_are_refused():
    with pytest.raises(InputError, match="glas"):
        select_surfaces(materials=("glas",))
    with pytest.raises(TypeError, match="sequences"):
        select_surfaces(materials="pbr")
