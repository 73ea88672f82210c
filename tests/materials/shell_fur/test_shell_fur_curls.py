"""Silva et al. Fig. 7 (d), many small curls (examples/shell_fur/fig7_curls.toml): the deferred
layers shade along each layer's curled tangent (shell.frag's layer_light), so the curl's light
and dark bands show in the deferred pipeline as in the forward one."""


import numpy as np
import pytest
from locations import ROOT

from deferred.scene.loader import scene_from_dict

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

FIG7 = ROOT / "examples" / "shell_fur"
LUMA = np.array([0.2126, 0.7152, 0.0722])


def fig7d(size: int) -> dict:
    data = tomllib.loads((FIG7 / "fig7_curls.toml").read_text(encoding="utf-8"))
    data["size"] = [size, size]
    data["object"][0]["params"].update({"curl_radius": 0.015, "curl_frequency": 38.0})
    return data


def fine_detail(image: np.ndarray) -> float:
    """Mean |luminance - its 5-point blur| over the lower part of the ball (the fur's small-scale
    contrast: a curl's bands, the strands' edges)."""
    lum = image[..., :3].astype(np.float64) @ LUMA
    n = lum.shape[0]
    part = lum[int(0.4 * n):, int(0.05 * n):int(0.95 * n)]
    blur = (part[:-2, 1:-1] + part[2:, 1:-1] + part[1:-1, :-2] + part[1:-1, 2:]
            + 4.0 * part[1:-1, 1:-1]) / 8.0
    return float(np.abs(part[1:-1, 1:-1] - blur).mean())


@pytest.fixture(scope="module")
def scene():
    return scene_from_dict(fig7d(200), "fig7 (d)", FIG7)


@pytest.mark.slow
def test_deferred_curls_keep_their_bands(render, scene):
    deferred, _ = render(scene, "deferred")
    forward, _ = render(scene, "forward")
    d, f = fine_detail(deferred.image), fine_detail(forward.image)
    mse = np.mean((deferred.image[..., :3].astype(float) - forward.image[..., :3]) ** 2)
    psnr = 10.0 * np.log10(255.0 ** 2 / mse)
    print(f"fine detail deferred {d:.2f}, forward {f:.2f}; PSNR {psnr:.1f} dB")
    assert abs(d / f - 1.0) < 0.2
    assert psnr > 30.0
