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


# -- X-toon ramps (Costigan 4.3.3-4.3.6) ---------------------------------------------------------

@pytest.fixture
def xtoon_material():
    from model_materials import XToonMaterial

    registry.materials.register(XToonMaterial)
    yield
    registry.materials.unregister(XToonMaterial.name)


XTOON_STOPS = [[0.0, "#202040"], [0.3, "#606090"], [0.7, "#c0c0f0"]]


def sphere_scene(params: dict, lights=None, size=(96, 96), objects=None):
    return scene_from_dict({
        "size": list(size), "tonemap": "none", "background": [0.0, 0.0, 0.0],
        "camera": {"position": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0], "fov": 45.0},
        "object": objects or [{"mesh": "builtin:sphere?segments=96&rings=48",
                               "material": "test_xtoon", "params": params}],
        "light": lights or [{"type": "directional", "direction": [-0.6, -0.5, -0.6],
                             "intensity": 1.0}]})


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_an_xtoon_sphere_has_no_more_tones_than_its_ramp_has_bands(gl, xtoon_material, pipeline):
    from deferred.materials.techniques.xtoon import hex_to_linear

    scene = sphere_scene({"ramp": XTOON_STOPS})
    with Renderer(scene, pipeline, gl=gl) as renderer:
        hdr = renderer.render(hdr=True).hdr
    covered = hdr[..., 3] > 0.999
    bands = np.array([hex_to_linear(c) for _, c in XTOON_STOPS])
    colours = hdr[covered][:, :3]
    distance = np.abs(colours[:, None, :] - bands[None, :, :]).max(axis=-1)  # (pixels, bands)
    # exactly the ramp's tones (to the composite's half-float precision), nothing between
    assert distance.min(axis=1).max() < 2e-3
    assert len(set(distance.argmin(axis=1))) == 3  # and the sphere shows each band


def test_xtoon_forward_and_deferred_agree_on_one_light(gl, xtoon_material):
    from conftest import psnr

    scene = sphere_scene({"ramp": XTOON_STOPS, "ramp_metric": "backlight",
                          "backlight_power": 0.5})
    images = {}
    for pipeline in ("deferred", "forward"):
        with Renderer(scene, pipeline, gl=gl) as renderer:
            images[pipeline] = renderer.render(hdr=True).hdr[..., :3]
    assert psnr(images["deferred"], images["forward"]) > 40.0


def test_the_depth_metric_washes_out_far_objects(gl, xtoon_material):
    """D = 1 - log(z/z_min)/log(z_max/z_min): the far sphere's tones move toward grey (less
    contrast between its lit and shadowed bands) against the near one of the same ramp."""
    params = {"ramp": [[0.0, "#101030"], [0.5, "#e0e0ff"]], "ramp_metric": "depth",
              "depth_range": [2.5, 14.0]}
    objects = [{"mesh": "builtin:sphere?segments=64&rings=32", "material": "test_xtoon",
                "position": [-0.9, 0.0, 0.5], "scale": 0.5, "params": params},
               {"mesh": "builtin:sphere?segments=64&rings=32", "material": "test_xtoon",
                "position": [2.5, 0.0, -10.0], "scale": 2.0, "params": params}]
    scene = sphere_scene({}, objects=objects, size=(128, 64))
    with Renderer(scene, gl=gl) as renderer:
        hdr = renderer.render(hdr=True).hdr
    luminance = hdr[..., :3].mean(axis=-1)
    covered = hdr[..., 3] > 0.999
    near, far = covered.copy(), covered.copy()
    near[:, 64:] = False
    far[:, :64] = False
    contrast = [luminance[m].max() - luminance[m].min() for m in (near, far)]
    assert contrast[1] < 0.7 * contrast[0]
    assert luminance[far].min() > luminance[near].min() + 0.05  # washed toward light grey


def test_xtoon_generated_ramps_against_the_formulas():
    from deferred.materials.techniques.xtoon import (
        HIGHLIGHT_EDGE,
        RIM_EDGE,
        generated_ramp,
        hex_to_linear,
        stop_colours,
    )

    stops = [(0.0, "#000000"), (0.25, "#808080"), (0.5, "#ffffff")]
    row = stop_colours(stops, 8)  # texel centres 1/16, 3/16, ...: each stop holds to the next
    grey = ((128 / 255 + 0.055) / 1.055) ** 2.4
    assert hex_to_linear("#808080") == pytest.approx((grey, grey, grey))
    np.testing.assert_allclose(row[:, 0], [0, 0, grey, grey, 1, 1, 1, 1], atol=1e-6)
    rim = generated_ramp(stops, "backlight", (0.5, 0.0, 0.0), width=8, height=10)
    y = (np.arange(10) + 0.5) / 10
    np.testing.assert_allclose(rim[:, 0, 0], np.where(y < RIM_EDGE, 0.5, 0.0))
    spec = generated_ramp(stops, "specular", highlight_color=(0.25, 0.25, 0.25), width=8,
                          height=10)
    np.testing.assert_allclose(spec[:, 7, 1], 1.0 + np.where(y >= HIGHLIGHT_EDGE, 0.25, 0.0))
    depth = generated_ramp(stops, "depth", width=8, height=10)
    np.testing.assert_allclose(depth[-1, :, 0], row[:, 0], atol=0.1)  # near: about the ramp
    assert np.ptp(depth[0, :, 0]) < 0.5 * np.ptp(depth[-1, :, 0])  # far: less contrast


def test_xtoon_params_are_refused_with_the_key():
    from deferred.errors import InputError
    from deferred.materials.techniques.xtoon import XToonParams

    for values, fragment in [({"ramp": [[0.1, "#000000"]]}, "start at 0"),
                             ({"ramp": [[0.0, "#000000"], [0.0, "#ffffff"]]}, "rise"),
                             ({"ramp": [[0.0, "red"]]}, "#rrggbb"),
                             ({"ramp": []}, "at least one"),
                             ({"depth_range": [5.0, 1.0]}, "z_min < z_max"),
                             ({"ramp_metric": "fog"}, "ramp_metric")]:
        with pytest.raises(InputError, match=fragment):
            from deferred.params import validate_params

            validate_params(XToonParams, values, None)


def test_an_edited_ramp_replaces_the_toon_textures(gl, xtoon_material):
    """A ramp changed between frames makes new toon textures and releases the old ones (each
    edit kept another texture array for the renderer's life)."""
    scene = sphere_scene({"ramp": XTOON_STOPS})
    with Renderer(scene, gl=gl) as renderer:
        renderer.render()
        before = renderer.resources._cached[("slot", "toon_ramps")][1]
        count = len(renderer.resources._cached)
        scene.objects[0].set_params(ramp=[[0.0, "#000000"], [0.5, "#ffffff"]])
        image = renderer.render(hdr=True).hdr
        after = renderer.resources._cached[("slot", "toon_ramps")][1]
        assert after is not before and len(renderer.resources._cached) == count
        assert type(before.mglo).__name__ == "InvalidObject"  # the old array was released
        covered = image[..., 3] > 0.999
        assert np.unique(np.round(image[covered][:, 0], 3)).size == 2  # the new two tones
