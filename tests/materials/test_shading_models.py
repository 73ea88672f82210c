"""Shading models: kajiya_kay and toon against numpy references of their formulas in both
pipelines, per-pixel dispatch in one frame, the G-buffer data they declare (layout, bytes,
dumps), and the isolation of models a scene does not use."""

import numpy as np
import pytest
from model_materials import StrandMaterial, ToonMaterial
from plane_reference import plane_points

from deferred.debug.capture import capture_frame
from deferred.gbuffer.layout import octahedral_decode
from deferred.interfaces import registry
from deferred.materials.shading_models import toon_ramps
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SIZE = (96, 72)
CAMERA = {"position": [0.0, 4.0, 0.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
          "fov": 60.0}
CAMERA_POSITION = np.array(CAMERA["position"])
LIGHT_POSITION = np.array([0.6, 1.2, -0.3])


@pytest.fixture(scope="module", autouse=True)
def model_materials():
    for cls in (StrandMaterial, ToonMaterial):
        registry.materials.register(cls)
    yield
    for cls in (StrandMaterial, ToonMaterial):
        registry.materials.unregister(cls.name)


def plane_scene(material: str, params: dict, objects: list | None = None, camera=None):
    return scene_from_dict({
        "size": list(SIZE), "tonemap": "none", "camera": camera or CAMERA,
        "object": objects or [{"mesh": "builtin:plane", "scale": 8.0, "material": material,
                               "params": params}],
        "light": [{"type": "point", "position": LIGHT_POSITION.tolist(), "intensity": 3.0,
                   "radius": 6.0, "color": [1.0, 0.9, 0.8]}]})


def render_hdr(gl, scene, pipeline):
    with Renderer(scene, pipeline, gl=gl) as renderer:
        return renderer.render().hdr[::-1, :, :3]  # bottom row first, as plane_points


def light_terms(scene):
    from deferred.lights.point import distance_falloff

    points = plane_points(scene, SIZE)
    to_light = LIGHT_POSITION - points
    d = np.linalg.norm(to_light, axis=-1, keepdims=True)
    L = to_light / d
    V = CAMERA_POSITION - points
    V /= np.linalg.norm(V, axis=-1, keepdims=True)
    radiance = np.array([1.0, 0.9, 0.8]) * 3.0 * distance_falloff(d, 6.0)
    return L, V, radiance


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_kajiya_kay_against_numpy(gl, pipeline):
    color, ks, p = np.array([0.6, 0.4, 0.2]), 0.7, 12.0
    scene = plane_scene("test_strands", {"color": color.tolist(), "specular_intensity": ks,
                                         "specular_exponent": p})
    image = render_hdr(gl, scene, pipeline)
    obj = scene.objects[0]
    tangents = obj.mesh.tangents @ obj.model[:3, :3].T
    T = tangents[0] / np.linalg.norm(tangents[0])
    assert np.allclose(tangents / np.linalg.norm(tangents, axis=-1, keepdims=True), T, atol=1e-6)
    L, V, radiance = light_terms(scene)
    E = -V  # Silva's camera direction: from the eye toward the point
    t_dot_l, t_dot_e = L @ T, E @ T
    sin_tl = np.sqrt(np.clip(1.0 - t_dot_l ** 2, 0.0, None))
    sin_te = np.sqrt(np.clip(1.0 - t_dot_e ** 2, 0.0, None))
    specular = ks * np.clip(t_dot_l * t_dot_e + sin_tl * sin_te, 0.0, None) ** p
    want = radiance * (color * sin_tl[..., None] + specular[..., None])
    np.testing.assert_allclose(image, want, rtol=2e-2, atol=4e-3)
    # the highlight is a band across the strands (along the plane, perpendicular to T), not
    # a spot: brightness varies far less along the band than across it
    spec = specular * radiance[..., 0]
    assert spec.max() > 0.2


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_toon_ramp_and_specular_band_against_numpy(gl, pipeline):
    color, ks, p = np.array([0.9, 0.3, 0.2]), 0.6, 40.0
    scene = plane_scene("test_toon", {"color": color.tolist(), "specular_intensity": ks,
                                      "specular_exponent": p, "ramp": "three_tone"})
    image = render_hdr(gl, scene, pipeline)
    L, V, radiance = light_terms(scene)
    n = np.array([0.0, 1.0, 0.0])
    n_dot_l = L @ n
    ramp = toon_ramps()["three_tone"]
    x = np.clip(n_dot_l * 0.5 + 0.5, 0.0, 1.0) * (len(ramp) - 1)
    tone = np.stack([np.interp(x, np.arange(len(ramp)), ramp[:, c]) for c in range(3)], -1)
    H = L + V
    H /= np.linalg.norm(H, axis=-1, keepdims=True)
    highlight = np.clip(H @ n, 0.0, None) ** p
    t = np.clip((highlight - 0.45) / 0.1, 0.0, 1.0)
    band = np.where(n_dot_l > 0.0, t * t * (3.0 - 2.0 * t), 0.0)
    want = radiance * (color * tone + ks * band[..., None])
    close = np.isclose(image, want, rtol=2e-2, atol=4e-3).all(axis=-1)
    assert close.mean() > 0.995  # filtering at a tone's edge may land a texel apart
    # the ramp's steps: the plane shows its flat tones over most of it, unlike N.L shading
    flat = [np.isclose(tone[..., 0], level, atol=1e-3).mean() for level in (0.05, 0.4, 1.0)]
    assert sum(flat) > 0.8 and min(flat[1:]) > 0.05
    assert band.max() == 1.0 and 0.0 < (band > 0.5).mean() < 0.2


def test_models_dispatch_per_pixel_in_one_frame(gl):
    objects = [
        {"mesh": "builtin:sphere", "position": [-1.5, 0.5, 0.0], "scale": 0.45},
        {"mesh": "builtin:sphere", "position": [0.0, 0.5, 0.0], "scale": 0.45,
         "material": "test_strands"},
        {"mesh": "builtin:sphere", "position": [1.5, 0.5, 0.0], "scale": 0.45,
         "material": "test_toon", "params": {"ramp": "two_tone"}},
    ]
    scene = plane_scene("", {}, objects,
                        {"position": [0.0, 0.6, 4.0], "target": [0.0, 0.5, 0.0]})
    with Renderer(scene, "deferred", gl=gl) as renderer:
        capture = capture_frame(renderer)
        deferred = renderer.render().image
    with Renderer(scene, "forward", gl=gl) as renderer:
        forward = renderer.render().image
    g = capture.gbuffer()
    third = SIZE[0] // 3
    expected = {"blinn_phong": slice(0, third), "kajiya_kay": slice(third, 2 * third),
                "toon": slice(2 * third, SIZE[0])}
    for name, columns in expected.items():
        ids = g["shading.model"][:, columns]
        assert set(np.unique(ids[ids > 0])) == {registry.shading_models.get(name).type_id}
    # the strand tangent lands only where kajiya_kay shades, decoded to unit vectors
    tangent = np.stack([g["strand_tangent.u"], g["strand_tangent.v"]], -1)
    kk = g["shading.model"] == registry.shading_models.get("kajiya_kay").type_id
    assert np.allclose(np.linalg.norm(octahedral_decode(tangent[kk]), axis=-1), 1.0, atol=1e-3)
    assert np.all(tangent[g["shading.model"] == 0] == 0.0)
    mse = np.mean((deferred[..., :3] / 255.0 - forward[..., :3] / 255.0) ** 2)
    assert 10.0 * np.log10(1.0 / mse) >= 40.0


def test_layout_follows_the_materials_present():
    standard = plane_scene("standard", {})
    assert standard.gbuffer_layout().bytes_per_pixel == 20
    assert list(standard.gbuffer_layout().data) == []
    strands = plane_scene("test_strands", {})
    layout = strands.gbuffer_layout()
    assert layout.bytes_per_pixel == 24  # + RG16F strand tangent
    assert layout.describe()["strand_tangent"]["channels"] == ["strand_tangent.u",
                                                               "strand_tangent.v"]
    toon = plane_scene("test_toon", {})
    assert toon.gbuffer_layout().bytes_per_pixel == 21  # + R8 ramp row


def test_only_the_models_a_scene_uses_are_compiled(gl):
    class Broken(registry.shading_models.get("blinn_phong")):
        name = "test_broken_model"
        glsl_file = "shading_models/does_not_exist.glsl"

    registry.shading_models.register(Broken)
    try:
        scene = plane_scene("standard", {})
        assert [m.name for m in scene.shading_models()] == ["blinn_phong"]
        render_hdr(gl, scene, "deferred")  # the broken model is registered, never compiled
    finally:
        registry.shading_models.unregister(Broken.name)
