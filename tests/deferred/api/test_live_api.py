"""Issue #23, the live Python API: a scene built and changed in code, validated as a scene file
is, and a renderer that follows it from one frame to the next; results that read back what is
asked for, save themselves and show in a notebook."""

from __future__ import annotations

import io

import numpy as np
import pytest

from deferred import InputError, Renderer, RenderError, Scene
from deferred.io.images import read_image
from deferred.scene.camera import Camera


def small_scene() -> Scene:
    scene = Scene(camera=Camera(position=(0.0, 0.5, 4.0), target=(0.0, 0.0, 0.0)),
                  size=(96, 64))
    scene.add_object("builtin:sphere", "standard", label="ball",
                     params={"color": (0.8, 0.3, 0.2)})
    scene.add_light("directional", direction=(-0.5, -1.0, -0.3))
    return scene


def lit(image: np.ndarray) -> np.ndarray:
    """Pixels brighter than the background."""
    return image[..., :3].astype(int).sum(axis=-1) > 3 * 60


@pytest.fixture
def renderer(gl):
    made = []

    def make(scene, **kwargs):
        made.append(Renderer(scene, gl=gl, **kwargs))
        return made[-1]

    yield make
    for r in made:
        r.release()


# -- validated edits ------------------------------------------------------------------------------

def test_set_params_is_validated_and_names_the_object_and_key():
    scene = small_scene()
    ball = scene.objects[0]
    before = ball.params
    with pytest.raises(InputError, match=r"^ball: params\.specular_exponent: .*greater than or "
                                         r"equal to 1"):
        ball.set_params(specular_exponent=-5)
    with pytest.raises(InputError, match=r"^ball: params\.shininess: unknown parameter"):
        ball.set_params(shininess=3.0)
    assert ball.params is before  # nothing changed
    assert ball.set_params(specular_exponent=12.0).specular_exponent == 12.0
    assert ball.params.specular_exponent == 12.0 and ball.params.color == (0.8, 0.3, 0.2)


def test_model_copy_validates_the_update():
    """pydantic's model_copy(update=...) takes values unchecked: params' own validates them."""
    params = small_scene().objects[0].params
    with pytest.raises(InputError, match="specular_exponent"):
        params.model_copy(update={"specular_exponent": -5, "color": (5.0, -1.0, 0.0)})
    assert params.model_copy(update={"specular_exponent": 7.0}).specular_exponent == 7.0


def test_scene_building_errors_name_the_argument():
    scene = Scene()  # a default camera
    cases = [
        (lambda: scene.add_object("builtin:sphere", "chrome"), "^material: unknown material"),
        (lambda: scene.add_object("builtin:pyramid"), "^mesh: "),
        (lambda: scene.add_object("builtin:sphere", scale=(1.0, 0.0, 1.0)),
         "^scale: must be at least 1e-06"),
        (lambda: scene.add_object("builtin:sphere", position=(1.0, 2.0)), "^position: "),
        (lambda: scene.add_object("builtin:sphere", params={"shells": 3}),
         r"^sphere0: params\.shells: unknown parameter"),
        (lambda: scene.add_light("laser"), "^type: unknown light 'laser'"),
        (lambda: scene.add_light("point", intensity=float("nan")),
         r"^light\[0\] \(point\): intensity: must be a finite number"),
        (lambda: scene.remove("nobody"), "^item: no object named 'nobody'"),
    ]
    for call, message in cases:
        with pytest.raises(InputError, match=message):
            call()
    assert scene.objects == [] and scene.lights == []
    scene.add_object("builtin:sphere", label="a")
    with pytest.raises(InputError, match="^label: an object is named 'a' already"):
        scene.add_object("builtin:sphere", label="a")


def test_renderer_arguments_are_named_as_python_arguments(gl):
    with pytest.raises(InputError, match="^pipeline: unknown pipeline 'deferredd'"):
        Renderer(small_scene(), "deferredd", gl=gl)
    with pytest.raises(InputError, match="^light_path: unknown light path 'fast'"):
        Renderer(small_scene(), gl=gl, light_path="fast")


# -- a renderer follows the scene ---------------------------------------------------------------

def test_an_object_added_after_the_first_frame_is_drawn_and_removing_it_restores_the_image(
        renderer):
    scene = small_scene()
    r = renderer(scene)
    first = r.render().image
    cube = scene.add_object("builtin:cube", position=(1.6, 0.0, 0.0), scale=0.5)
    with_cube = r.render().image
    right = np.s_[:, 70:]
    assert lit(with_cube[right]).sum() > lit(first[right]).sum() + 50
    np.testing.assert_array_equal(with_cube[:, :40], first[:, :40])  # the ball's side alike
    scene.remove(cube)
    np.testing.assert_array_equal(r.render().image, first)


def test_lights_added_and_removed_between_frames(renderer):
    scene = small_scene()
    r = renderer(scene)
    first = r.render().image
    light = scene.add_light("point", position=(0.0, 1.0, 2.0), intensity=4.0, radius=6.0)
    brighter = r.render().image
    assert brighter[..., :3].astype(int).sum() > first[..., :3].astype(int).sum() * 1.1
    scene.remove(light)
    np.testing.assert_array_equal(r.render().image, first)


@pytest.mark.slow
def test_parameters_that_add_or_remove_passes_rebuild_the_frame(renderer):
    scene = small_scene()
    fur = scene.add_object("builtin:sphere", "revie_fur", label="fur", position=(1.5, 0.0, 0.0),
                           params={"shells": 4})
    r = renderer(scene)
    assert "fur.shells" in r.render().draws_by_pass
    fur.set_params(shells=0)
    assert "fur.shells" not in r.render().draws_by_pass
    fur.set_params(shells=6)
    assert r.render().draws_by_pass["fur.shells"] >= 1
    # a value change keeps the passes and the programs (no rebuild)
    shaders = r.shaders
    scene.objects[0].set_params(color=(0.1, 0.8, 0.1))
    image = r.render().image
    assert r.shaders is shaders
    assert image[..., 1].astype(int).sum() > image[..., 0].astype(int).sum()


def test_a_new_background_is_the_clear_colour_of_the_next_frame(renderer):
    scene = small_scene()
    r = renderer(scene)
    corner = r.render().image[0, 0, :3].astype(int)
    scene.background = (0.5, 0.1, 0.1)
    now = r.render().image[0, 0, :3].astype(int)
    assert now[0] > corner[0] + 60 and now[0] > now[1] + 60


def test_a_rebuild_that_fails_leaves_the_renderer_as_it_was(renderer):
    """A light the light lists cannot hold is refused at the frame after it is added; removed,
    the renderer renders as before."""
    scene = small_scene()
    r = renderer(scene)
    first = r.render().image
    light = scene.add_light("point", position=(0.0, 1.0, 2.0), radius=100000.0)
    with pytest.raises(InputError, match="radius"):
        r.render()
    scene.remove(light)
    np.testing.assert_array_equal(r.render().image, first)


def test_inserted_passes_survive_a_rebuild(renderer):
    from deferred.core.passes import FullscreenPass, Phase
    from deferred.gbuffer.layout import LINEAR_DEPTH
    from deferred.gl.target_spec import TargetSpec

    scene = small_scene()
    r = renderer(scene)
    probe = FullscreenPass("test.depth_probe", Phase.LIGHTING, "post/copy.frag",
                           {"u_source": LINEAR_DEPTH}, ("probe",),
                           creates={"probe": TargetSpec(1, "f4", "probe", clear=(0.0,))})
    r.insert_pass(probe, before="lighting.cull_tiles")
    r.render()
    scene.add_object("builtin:cube", position=(1.6, 0.0, 0.0), scale=0.5)
    r.render()
    names = [p.name for p in r.passes]
    assert "cube0.gbuffer" in names
    assert names.index("test.depth_probe") == names.index("lighting.cull_tiles") - 1
    np.testing.assert_array_equal(r.targets.read("probe"), r.targets.read(LINEAR_DEPTH))


def test_an_object_with_a_timeline_keeps_parameters_assigned_to_it(renderer):
    """Assigning material.params on an object with events makes them its base: the timeline's
    events apply over them in each frame's state, and never overwrite them."""
    scene = small_scene()
    ball = scene.objects[0]
    scene.add_event(ball, 1.0, {"specular_intensity": 0.1})
    r = renderer(scene)
    r.render(time=0.0)
    ball.material.params = ball.params.model_copy(update={"color": (0.1, 0.1, 0.9)})
    r.render(time=0.0)
    assert ball.params.color == (0.1, 0.1, 0.9)
    r.render(time=2.0)
    at_two = r.state.object_state(ball).params  # the frame's: the event over the new base
    assert at_two.color == (0.1, 0.1, 0.9) and at_two.specular_intensity == 0.1
    assert ball.params is ball.base_params and ball.base_params.color == (0.1, 0.1, 0.9)
    assert ball.params.specular_intensity == 0.5  # the scene's own, not the timeline's


# -- results --------------------------------------------------------------------------------------

def test_the_hdr_composite_is_read_when_asked_for(renderer, gl, monkeypatch):
    """A frame reads back its 8-bit image; the float composite is read when result.hdr is
    first asked for, or before the renderer draws over it or is released while the result is
    held; a result dropped unread costs no read."""
    scene = small_scene()
    r = renderer(scene)
    reads = []
    real = r.read_hdr
    monkeypatch.setattr(r, "read_hdr", lambda: reads.append(1) or real())
    result = r.render()
    assert reads == []  # the 8-bit image only
    hdr = result.hdr
    assert reads == [1] and hdr.shape == (64, 96, 4) and hdr.dtype == np.float32
    assert result.hdr is hdr and reads == [1]
    for _ in range(3):
        r.render()  # each result dropped at once: none read
    assert reads == [1]
    held = r.render()
    r.render()  # held and unread: read before this frame draws over it
    assert reads == [1, 1]
    np.testing.assert_array_equal(held.hdr, hdr)
    assert reads == [1, 1]
    eager = r.render(hdr=True)
    np.testing.assert_array_equal(eager.hdr, hdr)
    with pytest.raises(RenderError, match="readback=False"):
        _ = r.render(readback=False).hdr
    # released with a result held: the composite is kept for it
    with Renderer(scene, gl=gl) as other:
        last = other.render()
    np.testing.assert_array_equal(last.hdr, hdr)


def test_a_result_saves_and_shows_in_a_notebook(renderer, tmp_path):
    from PIL import Image

    result = renderer(small_scene()).render(hdr=True)
    saved = read_image(result.save(tmp_path / "f.png"))
    np.testing.assert_array_equal(np.rint(saved * 255.0).astype(np.uint8), result.image)
    exr = read_image(result.save(tmp_path / "f.exr"))
    np.testing.assert_allclose(exr, result.hdr, rtol=1e-6)
    shown = np.asarray(Image.open(io.BytesIO(result._repr_png_())))
    np.testing.assert_array_equal(shown, result.image)
    with pytest.raises(InputError, match=r"^path: saves \.png .* or \.exr"):
        result.save(tmp_path / "f.jpg")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.exr", "f.png"]


# -- review fixes ----------------------------------------------------------------------------------

def coloured_scene(color) -> Scene:
    scene = small_scene()
    scene.objects[0].set_params(color=color)
    return scene


def test_a_result_reads_its_own_renderers_composite(gl):
    """Each renderer owns a pooled context: a result read after another renderer drew reads
    its own frame, not the context that is current."""
    red, blue = Renderer(coloured_scene((0.9, 0.05, 0.05))), \
        Renderer(coloured_scene((0.05, 0.05, 0.9)))
    try:
        a = red.render()
        b = blue.render()
        # the ball at the frame's centre: red in the first renderer's, blue in the second's
        assert a.hdr[32, 48, 0] > 2 * a.hdr[32, 48, 2]
        assert b.hdr[32, 48, 2] > 2 * b.hdr[32, 48, 0]
    finally:
        red.release()
        blue.release()


def test_set_params_is_refused_where_the_timeline_could_not_follow():
    """A new base is checked against every event as an event is: passes the timeline cannot
    change (shells 0 with an event of 8) and parameters it reads once."""
    scene = small_scene()
    fur = scene.add_object("builtin:sphere", "revie_fur", label="fur", params={"shells": 4})
    scene.add_event(fur, 1.0, {"shells": 8})
    with pytest.raises(InputError, match="would change the object's passes"):
        fur.set_params(shells=0)
    assert fur.base_params.shells == 4
    fur.set_params(shells=6)  # allowed: the event's 8 still has shells
    assert fur.base_params.shells == 6


def test_assigned_params_move_only_what_they_change_into_the_base(renderer):
    scene = small_scene()
    ball = scene.objects[0]
    ball.set_params(specular_intensity=0.9)
    scene.add_event(ball, 1.0, {"specular_intensity": 0.1})
    r = renderer(scene)
    r.render(time=2.0)
    ball.material.params = ball.params.model_copy(update={"color": (0.1, 0.9, 0.1)})
    r.render(time=0.0)
    assert ball.params.specular_intensity == 0.9 and ball.params.color == (0.1, 0.9, 0.1)


@pytest.mark.slow
def test_parameters_read_once_remake_the_state_of_a_live_renderer(gl, renderer):
    """shell_fur reads its seed and mask size once: changed with set_params, a live renderer
    starts the simulation over and draws what a fresh renderer draws."""
    scene = small_scene()
    fur = scene.add_object("builtin:sphere", "shell_fur", label="fur", position=(1.2, 0, 0),
                           params={"shells": 4, "seed": 1})
    live = renderer(scene)
    live.render()
    fur.set_params(seed=7, fur_length=0.3)
    changed = live.render().image
    with Renderer(scene, gl=gl) as fresh:
        np.testing.assert_array_equal(changed, fresh.render().image)


def test_scene_values_set_in_python_are_checked_at_the_next_frame(renderer):
    from deferred import Camera

    scene = small_scene()
    r = renderer(scene)
    first = r.render().image
    for attribute, value, message in [
            ("tonemap", "filmic", "^tonemap: unknown tone mapping operator 'filmic'"),
            ("background", (float("nan"), 0.0, 0.0), "^background: expected three finite"),
            ("camera", Camera(position=(0, 0, 0), target=(0, 0, 0)),
             "^camera: position and target are the same point"),
            ("exposure", -1.0, "^exposure: expected a finite number > 0")]:
        kept = getattr(scene, attribute)
        setattr(scene, attribute, value)
        with pytest.raises(InputError, match=message):
            r.render()
        setattr(scene, attribute, kept)
    np.testing.assert_array_equal(r.render().image, first)


@pytest.mark.slow
def test_a_frame_at_a_time_already_checked_checks_nothing_again(renderer, monkeypatch):
    """check_times passes for the latest time cover every earlier one while the parameters
    stay (the droplet count was weighed again each frame: 30-50 ms at 10,000 droplets)."""
    from deferred.materials.shell_fur.state import ShellFurSimulation

    scene = small_scene()
    fur = scene.add_object("builtin:sphere", "shell_fur", label="fur", position=(1.2, 0, 0),
                           params={"shells": 2, "droplets": 5})
    calls = []
    real = ShellFurSimulation.check_time
    monkeypatch.setattr(ShellFurSimulation, "check_time",
                        lambda self, *a: calls.append(a[1]) or real(self, *a))
    r = renderer(scene)
    r.check_times([0.5])
    for t in (0.0, 0.25, 0.5):
        r.render(time=t)
    assert calls == [0.5]
    r.render(time=0.75)
    fur.set_params(droplets=6)
    r.render(time=0.75)
    assert calls == [0.5, 0.75, 0.75]


def test_hdr_without_readback_is_refused(renderer):
    with pytest.raises(ValueError, match="readback=False"):
        renderer(small_scene()).render(readback=False, hdr=True)


@pytest.mark.slow
def test_a_plain_png_render_reads_no_composite(tmp_path, capsys, monkeypatch):
    import deferred.render.renderer as renderer_module
    from deferred.cli import main

    reads = []
    real = renderer_module.Renderer.read_hdr
    monkeypatch.setattr(renderer_module.Renderer, "read_hdr",
                        lambda self: reads.append(1) or real(self))
    assert main(["render", "-o", str(tmp_path / "x.png"), "--size", "32x18"]) == 0
    assert reads == []
    assert main(["render", "-o", str(tmp_path / "x.exr"), "--size", "32x18"]) == 0
    assert reads == [1]
