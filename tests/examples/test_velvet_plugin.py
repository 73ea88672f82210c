"""The example plugin package (examples/plugins/deferred-velvet), installed with pip as a user
would and rendered through the command line: its own shading model, G-buffer channel, light
type and effect, in both pipelines; and what a broken plugin may and may not break."""


import numpy as np
import pytest
from locations import ROOT
from plugin_packages import deferred, install_plugin

from deferred.io.images import read_image

PLUGIN = ROOT / "examples" / "plugins" / "deferred-velvet"
FRAMEWORK = [ROOT / "deferred", ROOT / "materials", ROOT / "lights", ROOT / "shaders"]


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """A folder with the plugin installed into it (pip --target), plus a broken plugin."""
    target = install_plugin(PLUGIN, tmp_path_factory.mktemp("plugin"))
    info = target / "broken_plugin-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: broken-plugin\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[deferred.lights]\nbroken = no_such_module:Light\n")
    # a material written against the hooks the base class had: refused when it loads
    (target / "old_velvet.py").write_text(
        "from deferred.api import Material\n\n\n"
        "class OldVelvet(Material):\n"
        "    name = 'old_velvet'\n"
        "    surface_shader = 'materials/standard/surface.glsl'\n\n"
        "    def material_passes(self, obj):\n"
        "        return []\n")
    info = target / "old_plugin-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: old-plugin\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(
        "[deferred.materials]\nold_velvet = old_velvet:OldVelvet\n")
    return target


@pytest.mark.slow
def test_the_plugin_renders_in_both_pipelines(site, tmp_path):
    images = {}
    for pipeline in ("deferred", "forward"):
        out = tmp_path / f"{pipeline}.png"
        result = deferred(site, "render", PLUGIN / "scene.toml", "--pipeline", pipeline,
                          "--size", "240x160", "-o", out, cwd=tmp_path)
        assert result.returncode == 0, result.stderr
        images[pipeline] = read_image(out)[..., :3]
    mse = np.mean((images["deferred"] - images["forward"]) ** 2)
    assert 10.0 * np.log10(1.0 / mse) >= 40.0
    # the velvet objects are there and lit, the vignette darkens the corners
    assert images["deferred"][:, :, 0].max() > 0.5
    assert images["deferred"][0, 0].sum() < images["deferred"][5, 120].sum()


@pytest.mark.slow
def test_the_plugin_declares_its_gbuffer_channel(site, tmp_path):
    result = deferred(site, "info", PLUGIN / "scene.toml", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0] == "gbuffer: 24 bytes per pixel"
    sheen = next(line for line in lines if line.strip().startswith("sheen"))
    assert "RGBA8" in sheen and "[sheen.R sheen.G sheen.B sheen.wrap]" in sheen


def test_no_file_of_the_framework_names_the_plugin():
    for folder in FRAMEWORK:
        for path in folder.rglob("*"):
            if path.is_file() and path.suffix in (".py", ".glsl", ".frag", ".vert", ".toml"):
                assert "velvet" not in path.read_text(encoding="utf-8").lower(), path


@pytest.mark.slow
def test_a_broken_plugin_fails_only_the_scenes_that_use_it(site, tmp_path):
    result = deferred(site, "render", "--size", "64x48", "-o", tmp_path / "demo.png",
                      cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    scene = tmp_path / "broken.toml"
    scene.write_text('[[object]]\nmesh = "builtin:sphere"\n[[light]]\ntype = "broken"\n')
    result = deferred(site, "render", scene, "-o", tmp_path / "broken.png", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.strip().splitlines()[-1].startswith(
        "error: broken.toml: light[0].type: cannot load light plugin 'broken' (broken-plugin): "
        "ModuleNotFoundError")
    assert not (tmp_path / "broken.png").exists()
    # listing every light names the broken plugin in a warning and goes on
    result = deferred(site, "info", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "cannot load light plugin 'broken'" in result.stderr
    assert "rim" in next(line for line in result.stdout.splitlines()
                         if line.strip().startswith("lights:"))


@pytest.mark.slow
def test_a_plugin_overriding_a_hook_that_became_a_part_is_told_what_to_write(site, tmp_path):
    scene = tmp_path / "old.toml"
    scene.write_text('[[object]]\nmesh = "builtin:sphere"\nmaterial = "old_velvet"\n')
    result = deferred(site, "render", scene, "-o", tmp_path / "old.png", cwd=tmp_path)
    assert result.returncode == 2
    line = result.stderr.strip().splitlines()[-1]
    assert line.startswith("error: old.toml: object[0].material: cannot load material plugin "
                           "'old_velvet' (old-plugin): TypeError: material class "
                           "old_velvet.OldVelvet defines material_passes, which the framework "
                           "no longer asks: "), line
    assert "PhasePasses(Phase.MATERIAL, build)" in line
    assert not (tmp_path / "old.png").exists()
