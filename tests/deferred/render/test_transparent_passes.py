"""A pass marked transparent gets no Forward+ depth pre-pass: what lies behind it is drawn and
seen through it, as in the naive forward pipeline. Unmarked, the pre-pass would lay its depth
down and hide what it shows."""

import numpy as np
import pytest

from deferred.api import ForwardLitPass, Order, SurfacePasses, materials
from deferred.materials.stipple_glass import StippleGlassMaterial
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict


def lit_pass(transparent):
    class SeeThroughForward(ForwardLitPass):
        fragment = "materials/stipple_glass/forward.frag"
        blend = "alpha"
        depth_write = False
        order = Order.TRANSPARENT

    SeeThroughForward.transparent = transparent
    return SeeThroughForward


@materials.register
class SeeThrough(StippleGlassMaterial):
    name = "test_see_through"
    techniques = (SurfacePasses(forward=lit_pass(True)),)


@materials.register
class SeeThroughUnmarked(StippleGlassMaterial):
    name = "test_see_through_unmarked"
    techniques = (SurfacePasses(forward=lit_pass(False)),)


def scene(material):
    return scene_from_dict({
        "size": [48, 48], "tonemap": "none",
        "camera": {"position": [0.0, 0.0, 4.0], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"mesh": "builtin:plane", "material": material, "rotation": [90, 0, 0],
                    "position": [0.0, 0.0, 1.0], "params": {"opacity": 0.3}},
                   {"mesh": "builtin:sphere", "material": "standard", "scale": 0.8}],
        "light": [{"type": "directional", "direction": [0.0, -0.5, -1.0]}]})


@pytest.mark.parametrize("material, marked", [("test_see_through", True),
                                              ("test_see_through_unmarked", False)])
def test_forward_plus_leaves_a_transparent_pass_out_of_its_depth_prepass(gl, material, marked):
    images = {}
    for path in ("naive", "tiled"):
        with Renderer(scene(material), "forward", gl=gl, strict=True,
                      light_path=path) as renderer:
            images[path] = renderer.render(hdr=True).hdr
            prepasses = [p.name for p in renderer.passes if p.name.endswith("depth_prepass")]
    assert prepasses == (["sphere0.depth_prepass"] if marked else
                         ["plane0.depth_prepass", "sphere0.depth_prepass"])
    sphere = np.abs(images["naive"][24, 24] - images["tiled"][24, 24]).max()
    assert (sphere < 1e-3) if marked else (sphere > 0.05)
