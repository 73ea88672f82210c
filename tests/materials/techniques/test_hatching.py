"""Tonal art maps (Costigan 4.3.8, after Praun et al.): tone order, nesting, tiling, stroke width
across mip levels, the disk cache, and the GLSL blend against the numpy reference."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import moderngl
import numpy as np
import pytest
from glsl_harness import draw_values
from locations import FIXTURES
from PIL import Image

from deferred.errors import InputError
from deferred.gl.shaderlib import ShaderLibrary
from deferred.materials.techniques import hatching
from deferred.materials.techniques.hatching import (
    TamSettings,
    ToneArtMap,
    blend_tones,
    cache_folder,
    cache_path,
    default_stroke,
    generate_tam,
    tam_texture,
    tonal_art_map,
)

SMALL = TamSettings(size=128, tones=6, mips=3, strokes=48, candidates=6, seed=3,
                    stroke_length=0.4, stroke_width=3.0)


@pytest.fixture(scope="module")
def tam() -> ToneArtMap:
    return generate_tam(SMALL)


def test_levels_have_the_asked_shapes(tam):
    assert [level.shape for level in tam.levels] == [(6, 128, 128), (6, 64, 64), (6, 32, 32)]
    assert all(level.dtype == np.uint8 for level in tam.levels)


def test_darker_tones_hold_more_ink_at_every_level(tam):
    for m in range(tam.mips):
        means = tam.ink(m).mean(axis=(1, 2))
        assert np.all(np.diff(means) > 0.0), (m, means)
        assert means[0] > 0.0


def test_levels_share_each_tone(tam):
    """Coarser levels drop strokes to keep the tone of the finest level (4.3.8)."""
    means = np.array([tam.ink(m).mean(axis=(1, 2)) for m in range(tam.mips)])
    steps = np.diff(means[0]).min()
    assert np.abs(means[1:] - means[0]).max() < 0.5 * steps, means


def test_lighter_tones_strokes_lie_inside_the_darker_ones(tam):
    for m, level in enumerate(tam.levels):
        ink = level.astype(np.int32)
        assert np.all(ink[:-1] <= ink[1:] + 1), m  # +1: one step of the 8-bit rounding
        # and each darker tone does add strokes of its own
        assert np.all((ink[1:] - ink[:-1] > 64).any(axis=(1, 2))), m


def seam_and_inside(image: np.ndarray) -> tuple[float, np.ndarray]:
    """Mean |difference| across the wrap (last column to first) and between each pair of
    neighbouring columns inside."""
    image = image.astype(np.float64)
    inside = np.abs(np.diff(image, axis=1)).mean(axis=0)
    return float(np.abs(image[:, -1] - image[:, 0]).mean()), inside


@pytest.fixture(scope="module")
def upright(tam) -> ToneArtMap:
    """SMALL hatched along v: strokes crossing the top and bottom edges."""
    return generate_tam(replace(SMALL, angle=90.0))


@pytest.mark.parametrize("axis", ["columns", "rows"])
def test_tiles_wrap_seamlessly(tam, upright, axis):
    """The last column (row) continues into the first as columns (rows) inside do into the
    next (Figs. 4.21-4.22); strokes along u cross the left and right edges, along v the others.
    The seam is one sample of the neighbours' differences, so it may top their largest by
    chance, never by much (a cut tile's seam is over 10x: next test)."""
    along = tam if axis == "columns" else upright
    seams, insides = [], []
    for m in range(along.mips):
        for tone in range(along.tones):
            image = along.ink(m)[tone]
            if axis == "rows":
                image = image.T
            seam, inside = seam_and_inside(image)
            assert seam <= 1.5 * inside.max(), (m, tone, seam, inside.max())
            seams.append(seam)
            insides.append(inside.mean())
    assert np.mean(seams) <= 1.5 * np.mean(insides)


@pytest.mark.parametrize("angle", [0.0, 90.0])
def test_the_seam_measure_tells_a_cut_tile(angle):
    """Strokes cut at the edges (a corner of a larger tile) leave a seam far above any
    neighbouring columns' (rows') difference inside."""
    larger = generate_tam(replace(SMALL, size=256, mips=1, strokes=96, angle=angle))
    for image in larger.ink(0):
        corner = image[:128, :128] if angle == 0.0 else image[:128, :128].T
        seam, inside = seam_and_inside(corner)
        assert seam > 3.0 * inside.max()


def test_cross_hatching_turns_the_darker_tones_strokes(tam):
    """cross_from: the tones from it on add strokes along v; the lighter ones are unchanged."""
    crossed = generate_tam(replace(SMALL, cross_from=4))
    np.testing.assert_array_equal(crossed.levels[0][:4], tam.levels[0][:4])
    added = crossed.ink(0)[5] - crossed.ink(0)[3]
    along_u = np.abs(np.diff(added, axis=1)).mean()  # small for strokes along u
    along_v = np.abs(np.diff(added, axis=0)).mean()
    assert along_v < 0.5 * along_u
    added = tam.ink(0)[5] - tam.ink(0)[3]
    assert np.abs(np.diff(added, axis=0)).mean() > 2.0 * np.abs(np.diff(added, axis=1)).mean()


def stroke_profile_width(image: np.ndarray) -> int:
    """Pixels above half ink across a lone horizontal stroke, at the column holding most ink."""
    column = int(np.argmax(image.sum(axis=0)))
    return int((image[:, column] > 0.5).sum())


def test_mip_levels_keep_stroke_width_in_pixels():
    settings = TamSettings(size=256, tones=1, mips=3, strokes=1, candidates=1, seed=1,
                           stroke_length=0.3, stroke_width=6.0, angle_jitter=0.0,
                           length_jitter=0.0)
    lone = generate_tam(settings)
    widths = [stroke_profile_width(lone.ink(m)[0]) for m in range(lone.mips)]
    assert all(abs(w - widths[0]) <= 1 for w in widths), widths
    assert 4 <= widths[0] <= 7, widths  # the default stroke: above half ink over ~85% of 6 px
    # while the stroke spans the same fraction of the tile at every level
    lengths = [int((lone.ink(m)[0].max(axis=0) > 0.5).sum()) / (256 >> m) for m in range(3)]
    assert max(lengths) - min(lengths) < 0.05, lengths
    # downsampling the finest level instead would have thinned it
    box = lone.ink(0)[0].reshape(64, 4, 64, 4).mean(axis=(1, 3))
    assert stroke_profile_width(box) < widths[0] / 2


def test_the_same_seed_makes_the_same_map_and_another_seed_another():
    settings = replace(SMALL, size=64, mips=2, strokes=12, stroke_length=0.3)
    first, second = generate_tam(settings), generate_tam(settings)
    other = generate_tam(replace(settings, seed=settings.seed + 1))
    for a, b, c in zip(first.levels, second.levels, other.levels, strict=True):
        np.testing.assert_array_equal(a, b)
        assert np.any(a != c)


@pytest.mark.parametrize(("change", "key"), [
    ({"size": 90}, "size"), ({"strokes": 3}, "strokes"), ({"stroke_length": 0.95},
                                                           "stroke_length"),
    ({"cross_from": 6}, "cross_from"), ({"candidates": 0}, "candidates"),
])
def test_bad_settings_name_the_setting(change, key):
    with pytest.raises(InputError, match=f"hatching: {key} "):
        generate_tam(replace(SMALL, **change))


def test_a_stroke_image_without_ink_is_refused(tmp_path):
    path = tmp_path / "white.png"
    Image.fromarray(np.full((8, 32), 255, np.uint8)).save(path)
    with pytest.raises(InputError, match="white.png: the stroke holds no ink"):
        generate_tam(SMALL, path)


# -- the cache ----------------------------------------------------------------------------------

CACHED = replace(SMALL, size=64, mips=2, strokes=12, stroke_length=0.3)


@pytest.fixture
def counted(monkeypatch):
    """generate_tam, counting its calls."""
    calls = []
    real = hatching.generate_tam

    def generate(*args, **kwargs):
        calls.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(hatching, "generate_tam", generate)
    return calls


def test_a_second_call_reads_the_cache(tmp_path, counted):
    first = tonal_art_map(CACHED, cache=tmp_path)
    assert len(counted) == 1
    path = cache_path(CACHED, None, tmp_path)
    assert path.is_file() and [p.name for p in path.parent.iterdir()] == [path.name]
    again = tonal_art_map(CACHED, cache=tmp_path)
    assert len(counted) == 1
    for a, b in zip(first.levels, again.levels, strict=True):
        np.testing.assert_array_equal(a, b)


def test_a_changed_setting_or_stroke_makes_a_new_file(tmp_path, counted):
    tonal_art_map(CACHED, cache=tmp_path)
    tonal_art_map(replace(CACHED, seed=CACHED.seed + 1), cache=tmp_path)
    assert len(counted) == 2
    image = tmp_path / "stroke.png"
    Image.fromarray(np.rint(255 * (1.0 - default_stroke((16, 64)))).astype(np.uint8)).save(image)
    tonal_art_map(CACHED, image, cache=tmp_path)
    tonal_art_map(CACHED, image, cache=tmp_path)
    assert len(counted) == 3
    assert len(list((tmp_path / "hatching").glob("tam-*.npz"))) == 3
    assert not list((tmp_path / "hatching").glob(".tam-*"))  # no temporary left behind


def test_equal_settings_written_differently_share_a_file():
    same = replace(CACHED, size=np.int64(CACHED.size), stroke_width=int(CACHED.stroke_width))
    assert cache_path(same, None, Path("c")) == cache_path(CACHED, None, Path("c"))
    assert cache_path(replace(CACHED, stroke_width=3.5), None, Path("c")) \
        != cache_path(CACHED, None, Path("c"))


@pytest.mark.parametrize("damage", ["garbage", "truncated", "empty", "wrong_shape"])
def test_a_corrupt_cache_file_is_regenerated(tmp_path, counted, damage):
    good = tonal_art_map(CACHED, cache=tmp_path)
    path = cache_path(CACHED, None, tmp_path)
    data = path.read_bytes()
    if damage == "garbage":
        path.write_bytes(b"\x93NUMPY not really" * 20)
    elif damage == "truncated":
        path.write_bytes(data[: len(data) // 2])
    elif damage == "empty":
        path.write_bytes(b"")
    else:
        np.savez(path, level0=np.zeros((2, 8, 8), np.uint8), level1=np.zeros((2, 4, 4), np.uint8))
    again = tonal_art_map(CACHED, cache=tmp_path)
    assert len(counted) == 2
    for a, b in zip(good.levels, again.levels, strict=True):
        np.testing.assert_array_equal(a, b)
    tonal_art_map(CACHED, cache=tmp_path)  # the file was replaced by a good one
    assert len(counted) == 2


def test_the_cache_folder_follows_the_environment(tmp_path, monkeypatch, counted):
    monkeypatch.setenv("DEFERRED_CACHE_DIR", str(tmp_path / "cache"))
    assert cache_folder() == tmp_path / "cache"
    tonal_art_map(CACHED)
    assert cache_path(CACHED).parent == tmp_path / "cache" / "hatching"
    assert cache_path(CACHED).is_file()
    monkeypatch.delenv("DEFERRED_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    if cache_folder().parent == tmp_path / "xdg":  # Linux and the BSDs
        assert cache_folder() == tmp_path / "xdg" / "deferred"


# -- the GLSL blend against numpy ----------------------------------------------------------------

GLSL_TAM = TamSettings(size=64, tones=4, mips=3, strokes=24, candidates=4, seed=7,
                       stroke_length=0.3, stroke_width=2.0)

HARNESS = FIXTURES / "hatching_harness"


@pytest.fixture(scope="module")
def glsl_tam():
    return generate_tam(GLSL_TAM)


def render_ink(gl, tam, tones, uniforms):
    ctx = gl.ctx
    gl.make_current()  # a CLI test may have made and released a context of its own
    gl.park()  # creating a framebuffer re-binds the last one used: ours, not a released one
    height, width = tones.shape
    lib = ShaderLibrary(ctx, 330)
    lib.add_root(HARNESS)
    program = lib.program("hatching_harness.vert", "hatching_harness.frag")
    texture = tam_texture(ctx, tam)
    tone_texture = ctx.texture((width, height), 1, tones.astype(np.float32).tobytes(), dtype="f4")
    tone_texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
    texture.use(0)
    tone_texture.use(1)
    values = {"u_tam": 0, "u_tones": 1, "u_tam_tones": tam.tones, "u_gutter": tam.gutter,
              **uniforms}
    for name, value in values.items():
        program[name].value = value
    ink = draw_values(gl, program, (width, height), 1)[..., 0].astype(np.float64)
    levels = [np.frombuffer(texture.read(level=m), np.uint8) for m in range(tam.mips)]
    for thing in (tone_texture, texture):
        thing.release()
    lib.release()
    assert ctx.error == "GL_NO_ERROR"
    return ink, levels


def pixel_tones(width, height, seed=0):
    tones = np.random.default_rng(seed).uniform(-0.1, 1.1, (height, width))
    tones[0, :6] = [0.0, 1.0, 0.25, 0.5, 0.75, 1.0 - 1e-3]  # the tones exactly, and near paper
    return tones


def frag_coords(width, height):
    y, x = np.mgrid[0:height, 0:width] + 0.5
    return np.stack([x, y], axis=-1).reshape(-1, 2)


def test_the_atlas_holds_the_tams_levels(gl, glsl_tam):
    _, levels = render_ink(gl, glsl_tam, np.zeros((4, 4)), {"u_screen": 0, "u_uv_scale": 1.0,
                                                              "u_uv_offset": (0.0, 0.0),
                                                              "u_scale": 1.0})
    for m, level in enumerate(levels):
        np.testing.assert_array_equal(level, glsl_tam.atlas(m).ravel())
    # each cell is its tone wrapped around by the gutter
    atlas, g = glsl_tam.atlas(0), glsl_tam.gutter
    cell = glsl_tam.size + 2 * g
    np.testing.assert_array_equal(atlas[g:-g, cell + g:2 * cell - g], glsl_tam.levels[0][1])
    np.testing.assert_array_equal(atlas[:g, cell + g:2 * cell - g], glsl_tam.levels[0][1][-g:])


@pytest.mark.parametrize("level", [0, 1])
def test_surface_hatching_blends_as_the_numpy_reference(gl, glsl_tam, level):
    """hatching_ink at one TAM texel a pixel (level 0) and two (level 1), over wrapped uv."""
    width, height = 80, 48
    tones = pixel_tones(width, height)
    scale, offset = (1 << level) / glsl_tam.size, (-1.37, 2.21)
    ink, _ = render_ink(gl, glsl_tam, tones, {"u_screen": 0, "u_uv_scale": scale,
                                              "u_uv_offset": offset, "u_scale": 1.0})
    uv = frag_coords(width, height) * scale + np.array(offset)
    expected = blend_tones(glsl_tam, tones.ravel(), uv, level).reshape(height, width)
    assert expected.std() > 0.1  # strokes and paper
    assert np.abs(ink - expected).max() <= 3.0 / 255.0
    assert np.abs(ink - expected).mean() <= 0.5 / 255.0
    assert np.all(ink[tones >= 1.0] == 0.0)  # lit: paper


@pytest.mark.parametrize(("scale", "level"), [(1.0, 0), (0.5, 1)])
def test_screen_hatching_blends_as_the_numpy_reference(gl, glsl_tam, scale, level):
    """hatching_screen_ink: the TAM laid over the screen, one texel to `scale` pixels."""
    width, height = 80, 48
    tones = pixel_tones(width, height, seed=1)
    ink, _ = render_ink(gl, glsl_tam, tones, {"u_screen": 1, "u_uv_scale": 0.0,
                                              "u_uv_offset": (0.0, 0.0), "u_scale": scale})
    uv = frag_coords(width, height) / (glsl_tam.size * scale)
    expected = blend_tones(glsl_tam, tones.ravel(), uv, level).reshape(height, width)
    assert np.abs(ink - expected).max() <= 3.0 / 255.0
    # the screen pattern repeats every tile on the screen, whatever the tone
    tile = int(glsl_tam.size * scale)
    same = tones[:, :width - tile] == tones[:, tile:]
    assert not same.any() or np.allclose(ink[:, :width - tile][same], ink[:, tile:][same])


def test_the_blend_runs_from_paper_through_every_tone(glsl_tam):
    uv = np.array([[0.3, 0.6]] * 3)
    n = glsl_tam.tones
    for k in range(n):  # tone k + 1 of n exactly: that image alone
        tone = 1.0 - (k + 1) / n
        got = blend_tones(glsl_tam, np.array([tone]), uv[:1])
        single = hatching.sample_wrapped(glsl_tam.ink(0)[k].astype(np.float64), uv[:1])
        np.testing.assert_allclose(got, single, atol=1e-9)
    halfway = blend_tones(glsl_tam, np.array([1.0 - 1.5 / n]), uv[:1])
    a, b = (hatching.sample_wrapped(glsl_tam.ink(0)[k].astype(np.float64), uv[:1])
            for k in (0, 1))
    np.testing.assert_allclose(halfway, (a + b) / 2, atol=1e-9)
    np.testing.assert_allclose(blend_tones(glsl_tam, np.array([1.0, 1.2]), uv[:2]), 0.0)
