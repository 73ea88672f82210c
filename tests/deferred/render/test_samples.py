"""Issue #25, accumulated samples: a frame averaged over sub-pixel offsets of the Halton (2, 3)
sequence, in linear light, converges to the supersampled frame (render --samples N)."""

from __future__ import annotations

import numpy as np
import pytest

from deferred.io.images import srgb_decode, srgb_encode
from deferred.render.renderer import Renderer, halton, halton_offsets
from deferred.scene.loader import scene_from_dict

SIZE = (96, 64)


def bare_scene(size=SIZE):
    return scene_from_dict({
        "size": list(size), "tonemap": "none", "background": [0.02, 0.02, 0.03],
        "camera": {"position": [0.0, 0.6, 3.2], "target": [0.0, 0.0, 0.0], "fov": 45.0},
        "object": [{"mesh": "builtin:sphere", "position": [-0.6, 0.0, 0.0], "scale": 0.7,
                    "params": {"color": [0.9, 0.6, 0.3]}},
                   {"mesh": "builtin:cube", "position": [0.8, 0.0, -0.3], "scale": 0.5,
                    "rotation": [20.0, 35.0, 0.0], "params": {"color": [0.3, 0.6, 0.9]}}],
        "light": [{"type": "directional", "direction": [-0.4, -1.0, -0.5]},
                  {"type": "ambient", "color": [0.15, 0.15, 0.18]}]})


def linear(image: np.ndarray) -> np.ndarray:
    return srgb_decode(image[..., :3].astype(np.float64) / 255.0)


def supersampled(gl, factor: int = 4) -> np.ndarray:
    """The frame rendered at ``factor`` times the size, box filtered in linear light."""
    with Renderer(bare_scene((SIZE[0] * factor, SIZE[1] * factor)), gl=gl) as renderer:
        big = linear(renderer.render().image)
    return big.reshape(SIZE[1], factor, SIZE[0], factor, 3).mean(axis=(1, 3))


def edge_psnr(image: np.ndarray, reference: np.ndarray) -> float:
    """PSNR in sRGB over the pixels on the reference's edges (a 3x3 range over 0.1)."""
    encoded = srgb_encode(reference)
    padded = np.pad(encoded.mean(axis=-1), 1, mode="edge")
    windows = np.lib.stride_tricks.sliding_window_view(padded, (3, 3))
    edges = (windows.max(axis=(2, 3)) - windows.min(axis=(2, 3))) > 0.1
    assert edges.sum() > 100
    error = np.mean((image[..., :3][edges] / 255.0 - encoded[edges]) ** 2)
    return float(10.0 * np.log10(1.0 / error))


def test_halton_offsets_are_the_radical_inverses_centred():
    assert [halton(k, 2) for k in (1, 2, 3, 4)] == [0.5, 0.25, 0.75, 0.125]
    assert [halton(k, 3) for k in (1, 2, 3)] == pytest.approx([1 / 3, 2 / 3, 1 / 9])
    offsets = np.array(halton_offsets(16))
    assert offsets.shape == (16, 2) and np.all(np.abs(offsets) < 0.5)
    assert np.abs(offsets.mean(axis=0)).max() < 0.05  # spread over the pixel


def test_sixteen_samples_converge_to_the_supersampled_edges(gl):
    """On a bare object's edges, one sample scores about 22-24 dB against the 4x4 supersampled
    frame; sixteen at least 33 dB."""
    reference = supersampled(gl)
    with Renderer(bare_scene(), gl=gl) as renderer:
        one = renderer.render().image
        sixteen = renderer.render_samples(16)
    single, averaged = edge_psnr(one, reference), edge_psnr(sixteen.image, reference)
    assert single < 28.0
    assert averaged >= 33.0, (single, averaged)
    # the float composite is the samples' mean too
    assert sixteen.hdr.shape == (SIZE[1], SIZE[0], 4)
    assert sixteen.draws_by_pass and sixteen.draw_calls > 16


def test_samples_of_a_scene_with_taa_are_each_alone(gl):
    """With taa in the scene, each of render_samples' renders starts its own history (else
    each would already be TAA's running mean, averaged again: the first sample weighted
    most), so the average is the plain scene's; and a single still with taa is the unmoved
    frame (the first of a history is not jittered)."""
    from deferred.effects.taa import TAA

    def with_taa():
        scene = bare_scene()
        scene.effects.append(TAA())
        return scene

    with Renderer(bare_scene(), gl=gl) as renderer:
        plain_one = renderer.render(hdr=True).hdr
        plain = renderer.render_samples(8).hdr
    with Renderer(with_taa(), gl=gl) as renderer:
        taa = renderer.render_samples(8).hdr
    with Renderer(with_taa(), gl=gl) as renderer:
        taa_one = renderer.render(hdr=True).hdr
    np.testing.assert_allclose(taa, plain, atol=2e-3)
    np.testing.assert_allclose(taa_one, plain_one, atol=2e-3)


def test_bad_sample_counts_are_refused(gl):
    from deferred.errors import InputError

    with Renderer(bare_scene(), gl=gl) as renderer:
        for bad in (0, -1, 2.5, True, 10**6):
            with pytest.raises(InputError, match="^samples: must be a whole number 1..1024"):
                renderer.render_samples(bad)


@pytest.mark.slow
def test_the_command_line_averages_samples(tmp_path, capsys):
    from deferred.cli import main
    from deferred.io.images import read_image

    assert main(["render", "-o", str(tmp_path / "one.png"), "--size", "64x36"]) == 0
    assert main(["render", "-o", str(tmp_path / "four.png"), "--size", "64x36",
                 "--samples", "4"]) == 0
    one, four = read_image(tmp_path / "one.png"), read_image(tmp_path / "four.png")
    differs = np.any(np.abs(one - four) > 1e-3, axis=-1)
    assert 0.0 < differs.mean() < 0.5  # the edges change, the flat insides hardly
    assert main(["render", "-o", str(tmp_path / "v.png"), "--samples", "4", "--view",
                 "albedo"]) == 2
    assert "--samples: --view shows one buffer" in capsys.readouterr().err
    assert not (tmp_path / "v.png").exists()
