"""Images are read and uploaded a band of rows at a time (#22: an 8192^2 grey texture inside
the image budget peaked at 7.8 GB): the result is the whole-image conversion's, checked against
a numpy reference of read_image's rules, with bands of a few rows."""

from __future__ import annotations

import numpy as np
import pytest

import deferred.gl.resources as resources
import deferred.io.images as images
from deferred.errors import InputError
from deferred.io.images import read_image, write_image


def reference_rgba(stored: np.ndarray, srgb: bool) -> np.ndarray:
    """read_image's rules on the whole image: grey to RGB, alpha 1 where there is none, values
    under 0 to 0, the sRGB curve on colour."""
    count = stored.shape[2]
    rgb = np.repeat(stored[..., :1], 3, axis=2) if count < 3 else stored[..., :3]
    alpha = stored[..., 1:2] if count == 2 else stored[..., 3:4] if count >= 4 else \
        np.ones(stored.shape[:2] + (1,))
    out = np.maximum(np.concatenate([rgb, alpha], axis=2).astype(np.float64), 0.0)
    if srgb:
        c = out[..., :3]
        out[..., :3] = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return out


@pytest.mark.parametrize("count", [1, 2, 3, 4, 5])
def test_banded_reading_is_the_whole_images(tmp_path, monkeypatch, count):
    monkeypatch.setattr(images, "READ_BAND_PIXELS", 3 * 17)  # three rows a band, one short
    rng = np.random.default_rng(count)
    stored = rng.random((23, 17, count)).astype(np.float32) - 0.0005  # some read as 0
    exr = write_image(tmp_path / "c.exr", stored, channels=("R", "G", "B", "A", "Z")[:count]
                      if count != 2 else ("Y", "A"))
    files = [(exr, stored, False)]
    if count in (1, 3):  # 8-bit, decoded from sRGB
        codes = (rng.random((23, 17, count)) * 255).astype(np.uint8)
        files.append((write_image(tmp_path / "c.png", codes), codes / 255.0, True))
    for path, values, srgb in files:
        got = read_image(path, srgb_to_linear=srgb)
        assert got.dtype == np.float32 and got.shape == (23, 17, 4)
        np.testing.assert_allclose(got, reference_rgba(values, srgb), atol=1e-6)
        half = read_image(path, srgb_to_linear=srgb, dtype=np.float16)
        assert half.dtype == np.float16
        np.testing.assert_array_equal(half, got.astype(np.float16))


def test_bad_values_are_counted_over_every_band(tmp_path, monkeypatch):
    monkeypatch.setattr(images, "READ_BAND_PIXELS", 2 * 8)
    pixels = np.full((10, 8, 3), 0.5, np.float32)
    pixels[3, 5, 1] = np.nan  # the first, in the second band
    pixels[9, 0, :] = -1.0  # three more, in the last band
    write_image(tmp_path / "bad.exr", pixels, channels=("R", "G", "B"))
    with pytest.raises(InputError, match=r"has 4 values that are NaN, infinite or negative "
                                         r"\(the first at pixel 5, 3: "):
        read_image(tmp_path / "bad.exr")


def test_a_texture_uploaded_in_bands_is_the_image_bottom_row_first(tmp_path, gl, monkeypatch):
    monkeypatch.setattr(resources, "UPLOAD_BAND_PIXELS", 4 * 13)  # four rows a band
    rng = np.random.default_rng(2)
    stored = (rng.random((30, 13, 4)) * 255).astype(np.uint8)
    path = write_image(tmp_path / "t.png", stored)
    cache = resources.Resources(gl.ctx)
    try:
        texture = cache.image_texture(path, srgb=False)
        texels = np.frombuffer(texture.read(), np.float16).reshape(30, 13, 4)
        expected = read_image(path, dtype=np.float16)[::-1]
        np.testing.assert_array_equal(texels, expected)
    finally:
        cache.release()


def test_a_comparison_in_bands_is_the_whole_buffers(tmp_path, monkeypatch):
    """dump --compare takes |B - A| a band of rows at a time (two 8192^2 EXRs peaked at six
    times one of them): statistics and difference images as numpy gives them for the whole
    buffers, NaN equal to NaN and infinite against a number, channels matched by name."""
    import json

    import deferred.debug.compare as compare
    from deferred.debug.preview import heat_colors, to_uint8
    from deferred.io.images import read_channels

    monkeypatch.setattr(compare, "COMPARE_BAND_PIXELS", 2 * 11)  # two rows a band
    rng = np.random.default_rng(9)
    a = rng.random((9, 11, 3)).astype(np.float32)
    b = a.copy()
    b[1:4, 2:5, 0] += 0.25
    b[7, 8, 2] = 3.0
    a[5, 5, 1] = b[5, 5, 1] = np.nan  # equal
    b[6, 1, 1] = np.nan  # NaN against a number
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    write_image(tmp_path / "a" / "light.exr", a, channels=("R", "G", "B"))
    # B's channels in another order: matched by name
    write_image(tmp_path / "b" / "light.exr", b[..., [2, 0, 1]], channels=("B", "R", "G"))
    [result] = compare.compare_dumps(tmp_path / "a", tmp_path / "b", tmp_path / "out")
    diff = np.abs(b - a)
    diff[np.isnan(diff)] = np.inf
    diff[np.isnan(a) & np.isnan(b)] = 0.0
    assert result.max == np.inf and result.mean == np.inf
    assert result.pixels == int(np.count_nonzero(diff.max(axis=-1)))
    assert result.per_channel_max == pytest.approx(
        {"R": float(diff[..., 0].max()), "G": np.inf, "B": float(diff[..., 2].max())})
    written, names, _ = read_channels(tmp_path / "out" / "light.exr")
    assert names == ["R", "G", "B"]
    np.testing.assert_array_equal(written, diff)
    heat = read_image(tmp_path / "out" / "light.png")[..., :3]
    np.testing.assert_allclose(heat, to_uint8(heat_colors(diff.max(axis=-1))) / 255.0,
                               atol=1e-6)
    record = json.loads((tmp_path / "out" / "compare.json").read_text())
    assert record["buffers"][0]["pixels"] == result.pixels


@pytest.mark.slow
def test_textures_and_material_state_count_against_the_memory_budget(tmp_path, capsys,
                                                                      monkeypatch):
    """Before GL starts, each object's material says what it will hold (held_memory: a texture
    by its header, a wetness mask by mask_size); with the render targets past the budget the
    scene is refused naming the largest. A texture two objects share counts once. (Eight
    8192^2 textures were each inside the image budget and 5.3 GiB together.)"""
    from deferred.cli import main
    from deferred.gl.resources import image_texture_bytes
    from deferred.render.renderer import held_memory
    from deferred.scene.loader import load_scene

    write_image(tmp_path / "a.png", np.zeros((64, 128, 3), np.uint8))
    write_image(tmp_path / "b.png", np.zeros((32, 32, 3), np.uint8))
    objects = "".join(f'[[object]]\nmesh = "builtin:sphere"\nmaterial = "standard"\n'
                      f'position = [{k}, 0, 0]\n[object.params]\ntexture = "{name}"\n'
                      for k, name in enumerate(["a.png", "a.png", "b.png"]))
    objects += ('[[object]]\nmesh = "builtin:plane"\nmaterial = "shell_fur"\n'
                '[object.params]\nmask_size = 512\n')
    scene_file = tmp_path / "s.toml"
    scene_file.write_text("size = [32, 18]\n" + objects)
    held = held_memory(load_scene(scene_file))
    assert held == {f"texture {tmp_path / 'a.png'}": image_texture_bytes(128, 64),
                    f"texture {tmp_path / 'b.png'}": image_texture_bytes(32, 32),
                    "wetness mask of plane0": 2 * 512 * 512 * 16}
    assert image_texture_bytes(128, 64) == 128 * 64 * 8 * 4 // 3
    # a budget the targets fit in, and not the wetness mask with them
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", str(8 << 20))
    code = main(["render", str(scene_file), "-o", str(tmp_path / "out.png")])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith(
        "error: s.toml: the materials' textures and state (3, the largest wetness mask "
        "of plane0: 8.0 MiB) and the render targets at 32x18 need 8."), err
    assert not (tmp_path / "out.png").exists()
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", str(16 << 20))
    assert main(["render", str(scene_file), "-o", str(tmp_path / "out.png")]) == 0


def test_a_texture_set_in_python_counts_against_the_memory_budget(gl, tmp_path, monkeypatch):
    """``set_params`` with a larger texture between frames is counted again before the next
    frame: refused past the budget (the renderer keeps its last frame), counted when it fits."""
    from deferred.errors import InputError
    from deferred.gl.resources import image_texture_bytes
    from deferred.render.renderer import Renderer
    from deferred.scene.scene import Scene

    write_image(tmp_path / "small.png", np.zeros((8, 8, 3), np.uint8))
    write_image(tmp_path / "large.png", np.zeros((512, 1024, 3), np.uint8))
    scene = Scene(size=(32, 18))
    ball = scene.add_object("builtin:sphere", material="standard",
                            params={"texture": str(tmp_path / "small.png")})
    with Renderer(scene, gl=gl) as renderer:
        renderer.render()
        targets = renderer.memory_bytes() - image_texture_bytes(8, 8)
        monkeypatch.setenv("DEFERRED_TARGET_MEMORY", str(targets + (1 << 20)))
        ball.set_params(texture=str(tmp_path / "large.png"))  # 5.3 MiB with its mipmaps
        with pytest.raises(InputError, match=r"the largest texture .*large\.png"):
            renderer.render()
        monkeypatch.setenv("DEFERRED_TARGET_MEMORY", str(targets + (8 << 20)))
        renderer.render()
        assert renderer.memory_bytes() == targets + image_texture_bytes(1024, 512)


def test_what_a_renderer_holds_counts_shadow_maps_and_histories_after_an_edit(gl):
    """memory_bytes counts the shadow atlas and TAA's history besides the targets and the
    materials' holdings, when built and after a parameter edit alike."""
    from deferred.lighting.shadows.atlas import atlas_memory
    from deferred.render.renderer import Renderer, renderer_holdings
    from deferred.scene.loader import scene_from_dict

    def build(shadows: bool, taa: bool):
        return scene_from_dict({
            "size": [32, 18], "shadows": {"atlas_size": 512},
            "object": [{"mesh": "builtin:sphere", "material": "standard"}],
            "light": [{"type": "directional", "shadows": shadows, "cascades": 1,
                       "shadow_resolution": 128}],
            "effect": [{"type": "taa"}] if taa else []})

    def held(scene):
        with Renderer(scene, gl=gl) as renderer:
            renderer.render()
            built = renderer.memory_bytes()
            scene.objects[0].set_params(specular_exponent=12.0)
            renderer.render()
            assert renderer.memory_bytes() == built
            return built

    plain = held(build(False, False))
    assert held(build(True, False)) - plain == sum(atlas_memory(
        build(True, False).shadow_budget, False).values())
    history = {key: size for key, size in renderer_holdings(build(False, True), "deferred",
                                                             (32, 18)).items()
               if key.startswith("taa history")}
    assert list(history.values()) == [32 * 18 * 16]  # RGBA32F, besides taa's own targets
    held(build(False, True))
