"""The translucent example plugin (examples/plugins/deferred-wax), installed with pip as a user
would and rendered through the command line in both pipelines: its shading model answers the
diffuse and specular light apart and takes light through thin parts from a shadowed light."""


import numpy as np
import pytest
from locations import ROOT
from plugin_packages import deferred, install_plugin

from deferred.io.images import read_image

PLUGIN = ROOT / "examples" / "plugins" / "deferred-wax"


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    return install_plugin(PLUGIN, tmp_path_factory.mktemp("wax"))


@pytest.mark.slow
def test_the_wax_plugin_renders_alike_in_both_pipelines_and_lets_light_through(site, tmp_path):
    images = {}
    for pipeline in ("deferred", "forward"):
        out = tmp_path / f"{pipeline}.exr"
        result = deferred(site, "render", PLUGIN / "scene.toml", "--pipeline", pipeline,
                          "-o", out, cwd=tmp_path)
        assert result.returncode == 0, result.stderr
        images[pipeline] = read_image(out)[..., :3]
    deferred_image, forward_image = images["deferred"], images["forward"]
    peak = float(deferred_image.max())
    mse = np.mean((np.clip(deferred_image / peak, 0, 1) - np.clip(forward_image / peak, 0, 1)) ** 2)
    assert 10.0 * np.log10(1.0 / mse) >= 40.0
    # both slabs face the camera, the shadowed light behind them: the thin one (0.04 thick,
    # exp(-0.4) of the light through) far brighter than the thick one (0.4, exp(-4))
    thin = deferred_image[80:100, 90:105].mean()
    thick = deferred_image[80:100, 150:170].mean()
    assert thin > 2.0 * thick, (thin, thick)


@pytest.mark.slow
def test_the_wax_plugin_declares_its_channel_and_parameters(site, tmp_path):
    result = deferred(site, "info", PLUGIN / "scene.toml", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    wax = next(line for line in result.stdout.splitlines() if line.strip().startswith("wax"))
    assert "RG16F" in wax and "[wax.wrap wax.mean_free_path]" in wax
    result = deferred(site, "params", "material", "wax", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "shading model wax" in result.stdout
    assert "mean_free_path" in result.stdout and "wrap" in result.stdout
