"""What the draw path keeps from one frame to the next (an object pass's program, a material's
inputs, the bound framebuffer): each must follow what it was made from, so a frame after a
change is the frame a fresh renderer draws."""

import numpy as np
import pytest

from deferred.imageio import write_image
from deferred.material import GBufferPass
from deferred.materials.standard import StandardMaterial
from deferred.passes import Phase
from deferred.renderer import Renderer
from deferred.scene import scene_from_dict


def sphere_scene():
    return scene_from_dict({
        "size": [64, 48], "camera": {"position": [0.0, 0.6, 2.6]},
        "object": [{"mesh": "builtin:sphere", "params": {"color": [0.8, 0.3, 0.2]}},
                   {"mesh": "builtin:cube", "position": [0.0, -0.8, 0.0], "scale": 0.3}],
        "light": [{"type": "directional", "direction": [-0.3, -1.0, -0.5]},
                  {"type": "ambient"}]})


def fresh_render(gl, scene, pipeline, time=0.0):
    with Renderer(scene, pipeline, gl=gl) as renderer:
        return renderer.render(time=time).hdr


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_params_replaced_between_frames_are_drawn_as_a_fresh_renderer_draws_them(
        gl, tmp_path, pipeline):
    """A new colour (a kept uniform) and a texture (a define: another program) reach the next
    frame, and the first params again give the first image."""
    texture = tmp_path / "red.png"
    write_image(texture, np.tile(np.array([0.9, 0.1, 0.1, 1.0], np.float32), (4, 4, 1)))
    scene = sphere_scene()
    sphere = scene.objects[0]
    first_params = sphere.material.params
    recoloured = first_params.model_copy(update={"color": (0.1, 0.7, 0.3)})
    textured = first_params.model_copy(update={"texture": str(texture)})
    with Renderer(scene, pipeline, gl=gl) as renderer:
        first = renderer.render().hdr
        sphere.material.params = recoloured
        second = renderer.render().hdr
        sphere.material.params = textured
        third = renderer.render().hdr
        sphere.material.params = first_params
        again = renderer.render().hdr
    assert not np.array_equal(first, second) and not np.array_equal(second, third)
    np.testing.assert_array_equal(again, first)
    for params, image in ((recoloured, second), (textured, third)):
        expected = sphere_scene()
        expected.objects[0].material.params = params
        np.testing.assert_array_equal(image, fresh_render(gl, expected, pipeline))


class PulsingMaterial(StandardMaterial):
    """Its colour is a function of the frame's time: it overrides ``uniforms`` and sets no
    ``inputs_from_params``, so its inputs are made each frame."""

    def uniforms(self, frame):
        return {**super().uniforms(frame), "u_color": (0.5 + 0.5 * np.sin(frame.time), 0.2, 0.2)}


class PulsingFromParams(PulsingMaterial):
    inputs_from_params = True


def test_which_materials_keep_their_inputs_across_frames():
    assert StandardMaterial.keeps_inputs()
    assert not PulsingMaterial.keeps_inputs()  # Standard's flag is not its own
    assert PulsingFromParams.keeps_inputs()  # its own flag, set below the override


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_a_material_reading_the_frame_gets_its_uniforms_each_frame(gl, pipeline):
    def scene():
        made = sphere_scene()
        made.objects[0].material = PulsingMaterial(made.objects[0].material.params)
        return made

    with Renderer(scene(), pipeline, gl=gl) as renderer:
        at_zero = renderer.render(time=0.0).hdr
        at_one = renderer.render(time=1.0).hdr
    assert not np.array_equal(at_zero, at_one)
    np.testing.assert_array_equal(at_one, fresh_render(gl, scene(), pipeline, time=1.0))


@pytest.mark.parametrize("strict", [False, True])
def test_kept_inputs_are_made_once_while_the_params_hold(gl, monkeypatch, strict):
    made = []
    uniforms = StandardMaterial.uniforms

    def counted(self, frame):
        made.append(self)
        return uniforms(self, frame)

    monkeypatch.setattr(StandardMaterial, "uniforms", counted)
    monkeypatch.setattr(StandardMaterial, "inputs_from_params", True)
    scene = sphere_scene()
    with Renderer(scene, "deferred", gl=gl, strict=strict) as renderer:
        for _ in range(3):
            renderer.render()
        assert len(made) == 2  # the sphere's and the cube's, in the first frame only
        scene.objects[1].material.params = scene.objects[1].material.params.model_copy(
            update={"specular_exponent": 8.0})
        renderer.render()
        assert made[2:] == [scene.objects[1].material]


def test_an_object_pass_whose_own_defines_change_gets_another_program(gl):
    """A pass overriding ``defines`` is asked every frame: the program follows them."""

    class Flagged(GBufferPass):
        flag = "0"

        def defines(self, frame):
            return {**super().defines(frame), "PROBE_FLAG": self.flag}

    with Renderer(sphere_scene(), "deferred", gl=gl) as renderer:
        renderer.render()
        frame = renderer.last_frame
        probe = Flagged("probe", Phase.GEOMETRY, renderer.scene.objects[0])
        frame.current_pass = probe
        off = probe.program(frame)
        assert probe.program(frame) is off
        probe.flag = "1"
        on = probe.program(frame)
        assert on is not off and renderer.shaders.program(
            probe.vertex, probe.fragment, defines={**probe.defines(frame)}) is on
        probe.flag = "0"
        assert probe.program(frame) is off


def test_an_object_pass_subclass_overriding_a_hook_is_asked_for_it(gl):
    """Passes keeping ObjectPass's hooks draw once with nothing of their own; a subclass that
    overrides one is asked (its uniforms set, its draws made)."""

    class Twice(GBufferPass):
        def draws(self, frame):
            return 2

    class Green(GBufferPass):
        def uniforms(self, frame):
            return {"u_color": (0.0, 1.0, 0.0)}

    assert GBufferPass._hooks_unchanged and not Twice._hooks_unchanged
    with Renderer(sphere_scene(), "deferred", gl=gl) as renderer:
        sphere = renderer.scene.objects[0]
        renderer.render()
        frame = renderer.last_frame
        albedo = {}
        for kind in (GBufferPass, Twice, Green):
            # lequal: drawn over the frame's own G-buffer, at the depths it holds
            probe = kind(f"probe.{kind.__name__}", Phase.GEOMETRY, sphere, depth_func="lequal")
            draws = frame.stats.draw_calls
            frame.run_pass(probe)
            assert frame.stats.draw_calls - draws == (2 if kind is Twice else 1)
            texture = frame.targets["albedo_specular"]
            pixels = np.frombuffer(texture.read(), np.float16 if texture.dtype == "f2" else
                                   np.uint8).reshape(48, 64, -1)
            albedo[kind] = pixels[24, 32, :3].astype(np.float64)
    np.testing.assert_array_equal(albedo[Twice], albedo[GBufferPass])
    assert albedo[GBufferPass][0] > albedo[GBufferPass][1]  # the sphere's own red
    assert albedo[Green][1] > albedo[Green][0]  # the pass's uniform won
