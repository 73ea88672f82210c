"""The example transparent plugin (examples/plugins/deferred-film), installed with pip as a
user would and rendered through the command line in both pipelines: its films tint what lies
behind them in any order and cast coloured shadows."""


import numpy as np
import pytest
from locations import ROOT
from plugin_packages import deferred, install_plugin

from deferred.io.images import read_image

PLUGIN = ROOT / "examples" / "plugins" / "deferred-film"


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    return install_plugin(PLUGIN, tmp_path_factory.mktemp("film"))


def scene_text(films: str) -> str:
    """A white floor under a white light straight above, the films over it (in file order)."""
    return f"""
size = [96, 96]
tonemap = "none"
background = [0.0, 0.0, 0.0]
[camera]
position = [0.0, 4.0, 0.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov = 40.0
[[object]]
name = "floor"
mesh = "builtin:plane"
scale = 3.0
[object.params]
color = [1.0, 1.0, 1.0]
specular_intensity = 0.0
{films}
[[light]]
type = "directional"
direction = [1.0, -1.0, 0.0]
shadows = true
shadow_resolution = 1024
"""


FILMS = {
    "amber": """
[[object]]
name = "amber"
mesh = "builtin:plane"
material = "film"
position = [0.0, 0.5, 0.0]
scale = 0.5
[object.params]
tint = [0.9, 0.5, 0.2]
specular_intensity = 0.0
""",
    "teal": """
[[object]]
name = "teal"
mesh = "builtin:plane"
material = "film"
position = [0.2, 0.7, 0.0]
scale = 0.5
[object.params]
tint = [0.2, 0.8, 0.75]
specular_intensity = 0.0
"""}


def render(site, tmp_path, text, pipeline, name):
    (tmp_path / f"{name}.toml").write_text(text)
    out = tmp_path / f"{name}-{pipeline}.exr"
    result = deferred(site, "render", tmp_path / f"{name}.toml", "--pipeline", pipeline, "-o",
                      out, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    return read_image(out)[..., :3].astype(np.float64)


@pytest.mark.slow
def test_films_tint_in_any_order_and_cast_coloured_shadows(site, tmp_path):
    bare = {p: render(site, tmp_path, scene_text(""), p, "bare") for p in ("deferred", "forward")}
    for pipeline in ("deferred", "forward"):
        one = render(site, tmp_path, scene_text(FILMS["amber"]), pipeline, "one")
        # the floor seen through the film (x within 0.5 of the middle) and the film's shadow
        # beside it (shifted 0.5 along +x by the light): both its tint over the bare floor
        middle = bare[pipeline][48, 40:45]
        np.testing.assert_allclose(one[48, 40:45] / middle, np.tile([0.9, 0.5, 0.2], (5, 1)),
                                   rtol=0.02)
        shadow = bare[pipeline][48, 68:72]
        np.testing.assert_allclose(one[48, 68:72] / shadow, np.tile([0.9, 0.5, 0.2], (4, 1)),
                                   rtol=0.05)
        first = render(site, tmp_path, scene_text(FILMS["amber"] + FILMS["teal"]), pipeline,
                       "ab")
        second = render(site, tmp_path, scene_text(FILMS["teal"] + FILMS["amber"]), pipeline,
                        "ba")
        np.testing.assert_allclose(first, second, atol=2e-3)
    assert np.abs(render(site, tmp_path, scene_text(FILMS["amber"]), "forward", "f") -
                  render(site, tmp_path, scene_text(FILMS["amber"]), "deferred", "d")).max() < 0.01
