"""A light type's own data (``Light.data``): declared vec4s after the record's four, read in
GLSL by name through a generated struct, checked when packed, listed by ``deferred params``."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import Field

from deferred.api import Light, LightDatum, LightParams, LightVolume, lights, view_points
from deferred.errors import RenderError
from deferred.interfaces.catalogue import catalogue
from deferred.lighting.dispatch import light_dispatch_glsl
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

GLSL = """#include "common/lighting.glsl"
vec3 banded_light(LightRecord light, Surface s, vec3 P, vec3 V) {
    banded_light_Data data = banded_light_data(light);
    if (distance(P, light.position.xyz) > light.position.w) return vec3(0.0);
    // the tint where P.x lies below the datum's split, the other colour above it
    vec3 radiance = P.x < data.split.x ? data.tint.rgb : data.split.yzw;
    return shade_light(s, s.normal, V, radiance);
}
"""


class BandedParams(LightParams):
    position: tuple[float, float, float] = Field((0.0, 1.0, 0.0), description="centre")
    radius: float = Field(20.0, gt=0.0, description="reach")
    tint: tuple[float, float, float] = Field((1.0, 0.0, 0.0), description="left colour")
    other: tuple[float, float, float] = Field((0.0, 0.0, 1.0), description="right colour")


@pytest.fixture
def banded(tmp_path):
    (tmp_path / "banded").mkdir()
    (tmp_path / "banded" / "light.glsl").write_text(GLSL)

    class BandedLight(Light):
        name = "banded_test"
        Params = BandedParams
        glsl_file = "banded/light.glsl"
        glsl_function = "banded_light"
        volume = LightVolume.SPHERE
        shader_root = tmp_path
        data = (LightDatum("tint", "rgb: the colour left of the split"),
                LightDatum("split", "x: the view-space x of the split; yzw: the colour right "
                                    "of it"))
        width = 6  # what records() gives (a test makes it wrong)

        @classmethod
        def records(cls, found, view):
            records = np.zeros((len(found), cls.width, 4), np.float32)
            records[:, 1, :3] = view_points(view, np.array([b.params.position for b in found]))
            records[:, 1, 3] = [b.params.radius for b in found]
            records[:, 4, :3] = [b.params.tint for b in found]
            if cls.width > 5:
                records[:, 5, 0] = records[:, 1, 0]  # split at the light's own x
                records[:, 5, 1:] = [b.params.other for b in found]
            return records

    lights.register(BandedLight)
    yield BandedLight
    lights.unregister("banded_test")


def banded_scene(extra_lights=()):
    return scene_from_dict({
        "size": [64, 48], "tonemap": "none", "background": [0, 0, 0],
        "camera": {"position": [0.0, 4.0, 0.0], "target": [0.0, 0.0, 0.0],
                   "up": [0.0, 0.0, -1.0], "fov": 60.0},
        "object": [{"mesh": "builtin:plane", "scale": 8.0,
                    "params": {"color": [1.0, 1.0, 1.0], "specular_intensity": 0.0}}],
        "light": [{"type": "banded_test", "position": [0.0, 1.0, 0.0]}, *extra_lights]})


@pytest.mark.parametrize("pipeline, light_path", [("deferred", "volumes"),
                                                  ("deferred", "tiled"),
                                                  ("forward", "naive"), ("forward", "tiled")])
def test_a_type_reads_its_data_by_name(gl, banded, pipeline, light_path):
    """The light's two data vec4s reach its GLSL through banded_light_data(light): red left of
    the split, blue right of it, on every path, beside a point light (rows of six vec4s)."""
    if light_path == "tiled" and not gl.features.compute_shaders:
        pytest.skip("the driver has no compute shaders")
    point = {"type": "point", "position": [0.0, 0.5, 1.5], "intensity": 0.0, "radius": 3.0}
    renderer = Renderer(banded_scene([point]), pipeline, gl=gl, light_path=light_path)
    try:
        image = renderer.render(hdr=True).hdr[..., :3]
        assert renderer._setup.light_buffer.texture.width == 6
    finally:
        renderer.release()
    left, right = image[:, :28].reshape(-1, 3), image[:, 36:].reshape(-1, 3)
    np.testing.assert_allclose(left, np.broadcast_to([1.0, 0.0, 0.0], left.shape), atol=2e-3)
    np.testing.assert_allclose(right, np.broadcast_to([0.0, 0.0, 1.0], right.shape), atol=2e-3)


def test_a_scene_without_data_keeps_rows_of_four(gl):
    scene = scene_from_dict({"size": [32, 24], "object": [{"mesh": "builtin:plane"}],
                             "light": [{"type": "point"}, {"type": "directional"}]})
    renderer = Renderer(scene, "deferred", gl=gl)
    try:
        renderer.render()
        assert renderer._setup.light_buffer.texture.width == 4
    finally:
        renderer.release()


def test_records_of_the_wrong_shape_are_refused_naming_the_type(gl, banded):
    banded.width = 5  # one data vec4 short
    renderer = Renderer(banded_scene(), "deferred", gl=gl)
    try:
        with pytest.raises(RenderError, match=r"light type 'banded_test': records\(\) gave an "
                                              r"array of shape \(1, 5, 4\); its four vec4s and "
                                              r"its 2 data vec4s make \(1, 6, 4\)"):
            renderer.render()
    finally:
        renderer.release()


def test_the_generated_struct_names_each_datum(banded):
    text = light_dispatch_glsl([banded])
    assert "struct banded_light_Data {" in text and "vec4 split;" in text
    assert "return banded_light_Data(light_datum(light, 0), light_datum(light, 1));" in text
    # a type without data adds nothing
    from deferred.lights.point import PointLight
    assert "_Data" not in light_dispatch_glsl([PointLight])


def test_bad_declarations_are_refused():
    with pytest.raises(ValueError, match="not a GLSL identifier"):
        LightDatum("two words", "...")

    class Twice(Light):
        name = "twice_test"
        glsl_function = "twice"
        data = (LightDatum("a", "x"), LightDatum("a", "y"))

    with pytest.raises(TypeError, match=r"light class .*Twice declares the light datum names "
                                        r"\['a', 'a'\], some twice"):
        lights.register(Twice)
    assert "twice_test" not in lights


def test_params_lists_a_types_data():
    (entry,) = catalogue("light", "rect")
    assert [datum["name"] for datum in entry["data"]] == ["axis_x", "axis_y"]
    (entry,) = catalogue("light", "point")
    assert entry["data"] == []
