"""Packaging: the framework's materials, lights and shaders live under ``deferred.*``, so a
user's own ``materials/``, ``lights/`` or ``shaders/`` folder never shadows them; ``deferred info``
reports the scene's G-buffer layout."""

import fnmatch
import importlib.util
import subprocess
import sys
from pathlib import Path, PurePosixPath

import numpy as np
import pytest
from locations import ROOT
from model_materials import StrandMaterial

from deferred.cli import main
from deferred.gl.shaderlib import GLSL_SUFFIXES
from deferred.interfaces import registry
from deferred.io.images import read_image
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib


def test_nothing_is_importable_as_a_top_level_materials_lights_or_shaders(tmp_path):
    code = ("import importlib.util, deferred.materials, deferred.lights, deferred.shaders; "
            "print([importlib.util.find_spec(n) for n in ('materials', 'lights', 'shaders')])")
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, check=True)
    assert out.stdout.strip() == "[None, None, None]"
    assert importlib.util.find_spec("deferred.materials.standard") is not None


@pytest.mark.slow
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


def test_every_package_and_its_glsl_is_in_the_distribution():
    """pyproject lists every package of the repository's deferred/, materials/, lights/ and
    shaders/ (a feature's folder is a package of its own), and its package data globs take
    every GLSL file there, so a non-editable install carries each feature's shaders."""
    root = ROOT
    setuptools = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]
    folders = {name: root / folder for name, folder in setuptools["package-dir"].items()}
    found = {}
    for top, folder in folders.items():
        for init in folder.rglob("__init__.py"):
            parts = init.parent.relative_to(folder).parts
            found[".".join((top, *parts))] = init.parent
    assert sorted(setuptools["packages"]) == sorted(found)
    data = setuptools["package-data"]
    glsl = [path for folder in folders.values() for path in folder.rglob("*")
            if path.suffix in GLSL_SUFFIXES]
    assert len(glsl) > 100

    def shipped(path: Path) -> bool:
        for package, folder in found.items():
            if folder in path.parents:
                relative = path.relative_to(folder).as_posix()
                globs = [*data.get(package, []), *data.get("*", [])]
                if any(PurePosixPath(relative).match(glob) if "/" not in glob
                       else fnmatch.fnmatch(relative, glob) for glob in globs):
                    return True
        return False

    assert [str(path.relative_to(root)) for path in glsl if not shipped(path)] == []
