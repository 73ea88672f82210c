"""Packaging: the framework's materials, lights and shaders live under ``deferred.*``, so a
user's own ``materials/``, ``lights/`` or ``shaders/`` folder never shadows them; ``deferred info``
reports the scene's G-buffer layout."""

import importlib.util
import subprocess
import sys

import numpy as np
from model_materials import StrandMaterial

from deferred.cli import main
from deferred.interfaces import registry
from deferred.io.images import read_image
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene


def test_nothing_is_importable_as_a_top_level_materials_lights_or_shaders(tmp_path):
    code = ("import importlib.util, deferred.materials, deferred.lights, deferred.shaders; "
            "print([importlib.util.find_spec(n) for n in ('materials', 'lights', 'shaders')])")
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, check=True)
    assert out.stdout.strip() == "[None, None, None]"
    assert importlib.util.find_spec("deferred.materials.standard") is not None


def test_render_from_a_folder_with_the_users_own_packages(tmp_path, gl):
    for name in ("materials", "lights", "shaders"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "__init__.py").write_text(
            f"raise ImportError('the user\\'s own {name} package must not be imported')\n")
    (tmp_path / "shaders" / "common").mkdir()
    (tmp_path / "shaders" / "common" / "surface.glsl").write_text("this is not GLSL\n")
    # `python -m` puts the working folder first on sys.path, as a user's script would
    result = subprocess.run([sys.executable, "-m", "deferred.cli", "render", "-o", "demo.png",
                             "--size", "64x48"], cwd=tmp_path, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    image = read_image(tmp_path / "demo.png")
    with Renderer(load_scene(None), size=(64, 48), gl=gl) as renderer:
        expected = renderer.render().image
    np.testing.assert_array_equal((image * 255.0).round().astype(np.uint8), expected)


def test_info_reports_the_scenes_gbuffer_layout(tmp_path, capsys):
    scene = tmp_path / "scene.toml"
    scene.write_text('[[object]]\nmesh = "builtin:sphere"\n')
    assert main(["info", str(scene)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "gbuffer: 20 bytes per pixel"
    assert [line.split()[0] for line in out[1:5]] == ["albedo_specular", "normal_exponent_id",
                                                      "linear_depth", "depth"]
    registry.materials.register(StrandMaterial)
    try:
        scene.write_text('[[object]]\nmesh = "builtin:sphere"\nmaterial = "test_strands"\n')
        assert main(["info", str(scene)]) == 0
        out = capsys.readouterr().out.splitlines()
        assert out[0] == "gbuffer: 24 bytes per pixel"
        assert out[5].split()[:3] == ["strand_tangent", "RG16F", "4"]
        assert "[strand_tangent.u strand_tangent.v]" in out[5]
    finally:
        registry.materials.unregister(StrandMaterial.name)


def test_info_on_a_bad_scene_is_bad_input(tmp_path, capsys):
    scene = tmp_path / "scene.toml"
    scene.write_text('[[object]]\nmesh = "builtin:sphere"\nmaterial = "nope"\n')
    assert main(["info", str(scene)]) == 2
    assert "object[0].material: unknown material 'nope'" in capsys.readouterr().err
