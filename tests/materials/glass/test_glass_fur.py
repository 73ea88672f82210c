"""Glass and fur composed in depth order, both pipelines, for each fur and hair material
(shell_fur, revie_fur, cartoon_hair): a pane in front of a fur ball is the pane composed over
the fur (its light plus its transmittance times the fur alone), and a pane behind it shows
through the fur's translucent fringe as the background it tints, under the fur, not over it;
each frame's passes put the glass's run where its distance puts it."""

import numpy as np
import pytest

from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SIZE = (64, 64)
RED = [1.0, 0.1, 0.1]
BACKGROUND = (0.2, 0.6, 0.8)
# each material's object: its mesh, scale (the built-in head's radius is 0.1) and parameters
FUR = {"shell_fur": ("builtin:sphere", 0.6, {"fur_length": 0.25, "shells": 12}),
       "revie_fur": ("builtin:sphere", 0.6, {"fur_length": 0.25, "shells": 12}),
       "cartoon_hair": ("builtin:head?segments=24&rings=16", 5.0,
                        {"strands": 120, "length": 0.08})}
# the materials whose edge is a translucent fringe (shells); cartoon_hair's tubes are opaque
FRINGED = ("shell_fur", "revie_fur")


def scene(pane_z=None, background=BACKGROUND, fur=True, material="shell_fur"):
    objects = []
    if fur:
        mesh, scale, params = FUR[material]
        objects.append({"mesh": mesh, "material": material, "scale": scale, "params": params})
    if pane_z is not None:
        objects.append({"mesh": "builtin:plane", "material": "glass", "rotation": [90, 0, 0],
                        "position": [0.0, 0.0, pane_z], "scale": 1.5,
                        "params": {"color": RED, "opacity": 0.0, "specular_intensity": 0.0,
                                   "refraction": 0.0}})
    return scene_from_dict({
        "size": list(SIZE), "tonemap": "none", "background": list(background),
        "camera": {"position": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": objects,
        "light": [{"type": "directional", "direction": [-0.3, -0.5, -1.0]},
                  {"type": "ambient", "color": [0.3, 0.3, 0.3]}]})


def render(gl, scene, pipeline):
    with Renderer(scene, pipeline, gl=gl, strict=True) as renderer:
        image = renderer.render(hdr=True).hdr[..., :3].astype(np.float64)
        names = [p.name for p in renderer.passes]
    return image, names


@pytest.mark.parametrize("material", list(FUR))
@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_a_pane_in_front_of_fur_is_composed_over_it(gl, pipeline, material):
    fur, _ = render(gl, scene(material=material), pipeline)
    both, _ = render(gl, scene(pane_z=1.0, material=material), pipeline)
    light, _ = render(gl, scene(pane_z=1.0, background=(0.0, 0.0, 0.0), fur=False), pipeline)
    white, _ = render(gl, scene(pane_z=1.0, background=(1.0, 1.0, 1.0), fur=False), pipeline)
    expected = light + (white - light) * fur
    np.testing.assert_allclose(both, expected, atol=4e-3)
    # the fur seen through the red pane keeps little of its green and blue
    covered = np.abs(fur - np.asarray(BACKGROUND)).max(axis=-1) > 0.02
    assert covered.sum() > 200
    assert both[covered][:, 1].mean() < 0.2 * fur[covered][:, 1].mean()


@pytest.mark.parametrize("material", list(FUR))
@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_fur_in_front_of_a_pane_is_composed_over_what_the_pane_shows(gl, pipeline, material):
    both, _ = render(gl, scene(pane_z=-1.0, material=material), pipeline)
    tinted, _ = render(gl, scene(pane_z=-1.0, fur=False), pipeline)
    # what the pane shows of the background (its transmittance barely changes over it)
    seen = tinted[SIZE[1] // 2, SIZE[0] // 2]
    fur_over_it, _ = render(gl, scene(background=tuple(seen), material=material), pipeline)
    fur_alone, _ = render(gl, scene(material=material), pipeline)
    covered = np.abs(fur_alone - np.asarray(BACKGROUND)).max(axis=-1) > 0.02
    fringe = covered & (np.abs(fur_over_it - seen).max(axis=-1) > 0.02)
    if material in FRINGED:  # where the background shows through the fur, it shows tinted
        assert fringe.sum() > 50
    else:  # opaque strands: the pane behind is hidden wherever they cover
        np.testing.assert_allclose(both[covered], fur_alone[covered], atol=1e-4)
    np.testing.assert_allclose(both[covered], fur_over_it[covered], atol=1.5e-2)
    # drawn over the fur instead, the pane would take most of the fur's green and blue
    assert np.abs(both[covered] - fur_alone[covered] * RED).max() > 0.05


def test_each_frame_puts_the_glass_run_where_its_distance_does(gl):
    sc = scene(pane_z=1.0)
    with Renderer(sc, "deferred", gl=gl, strict=True) as renderer:
        from deferred.debug.capture import capture_frame
        front = [p.name for p in capture_frame(renderer).passes]
        sc.find("plane0").position = (0.0, 0.0, -1.0)
        behind = [p.name for p in capture_frame(renderer).passes]

    def glass_first(names):
        return names.index("material.glass_composite") < names.index("sphere0.layers")

    assert not glass_first(front) and glass_first(behind)


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_fur_between_two_panes_splits_the_glass_into_two_runs(gl, pipeline):
    sc = scene(pane_z=1.0)
    sc.add_object("builtin:plane", "glass", position=(0.0, 0.0, -1.0),
                  rotation=(90.0, 0.0, 0.0), scale=1.5,
                  params={"color": [0.2, 0.2, 1.0], "refraction": 0.0})
    with Renderer(sc, pipeline, gl=gl, strict=True) as renderer:
        from deferred.debug.capture import capture_frame
        names = [p.name for p in capture_frame(renderer).passes]
    phase = "material" if pipeline == "deferred" else "forward"
    runs = [k for k, name in enumerate(names) if name == f"{phase}.glass_composite"]
    fur = next(k for k, name in enumerate(names) if name.startswith("sphere0.") and
               k > names.index(f"{phase}.glass_clear"))
    assert len(runs) == 2 and runs[0] < fur < runs[1]
    assert names.index("plane1.glass") < runs[0] < names.index("plane0.glass") < runs[1]
