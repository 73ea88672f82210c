"""What the draw path keeps from one frame to the next (an object pass's program, a material's
inputs, the bound framebuffer): each must follow what it was made from, so a frame after a
change is the frame a fresh renderer draws."""

import numpy as np
import pytest

from deferred.core.passes import Phase
from deferred.interfaces.techniques import GBufferPass
from deferred.io.images import write_image
from deferred.materials.standard import StandardMaterial
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict


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


class PulsingInPlace(StandardMaterial):
    """Reads the frame's time into one dict it keeps and changes in place."""

    def uniforms(self, frame):
        values = self.__dict__.setdefault("_values", dict(super().uniforms(frame)))
        values["u_color"] = (0.5 + 0.5 * np.sin(frame.time), 0.2, 0.2)
        return values


@pytest.mark.parametrize("kind", [PulsingMaterial, PulsingInPlace])
@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_a_material_reading_the_frame_gets_its_uniforms_each_frame(gl, pipeline, kind):
    """A new dict each frame, or one it changes in place: either reaches GL each frame."""
    def scene():
        made = sphere_scene()
        made.objects[0].material = kind(made.objects[0].material.params)
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


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_a_mesh_or_material_replaced_between_frames_is_drawn(gl, pipeline):
    from deferred.scene.meshes import load_mesh

    def replace_mesh(scene):
        scene.objects[0].mesh = load_mesh("builtin:torus")

    def replace_material(scene):
        scene.objects[0].material = StandardMaterial(
            scene.objects[0].material.params.model_copy(update={"color": (0.2, 0.3, 0.9)}))

    for change in (replace_mesh, replace_material):
        scene = sphere_scene()
        with Renderer(scene, pipeline, gl=gl) as renderer:
            first = renderer.render().hdr
            change(scene)
            changed = renderer.render().hdr
        expected = sphere_scene()
        change(expected)
        assert not np.array_equal(first, changed)
        np.testing.assert_array_equal(changed, fresh_render(gl, expected, pipeline))


def test_a_program_released_by_a_changed_virtual_file_is_not_drawn_with(gl):
    """A changed generated file releases the programs that include it (ShaderLibrary
    .generation): an object pass looks its program up again, never drawing with the old."""
    from deferred.gbuffer.layout import data_write_file

    with Renderer(sphere_scene(), "deferred", gl=gl) as renderer:
        first = renderer.render().hdr
        name = data_write_file([])
        shaders = renderer.shaders
        shaders.set_virtual_file(name, shaders.read(name) + "\n// changed\n")
        np.testing.assert_array_equal(renderer.render().hdr, first)


def test_strict_frames_do_not_pile_up_on_kept_inputs(gl):
    scene = sphere_scene()
    with Renderer(scene, "deferred", gl=gl, strict=True) as renderer:
        for _ in range(3):
            renderer.render()
        kept = renderer.kept_inputs.of(scene.objects[0].material, renderer.last_frame)
        assert kept.kept and kept.programs == [] and not kept.declared
        assert renderer.last_frame.material_inputs(scene.objects[0].material).programs


def test_a_pass_keeping_the_hooks_sets_its_constants(gl):
    with Renderer(sphere_scene(), "deferred", gl=gl) as renderer:
        renderer.render()
        frame = renderer.last_frame
        probe = GBufferPass("probe.constants", Phase.GEOMETRY, renderer.scene.objects[0],
                            depth_func="lequal", constants={"u_color": (0.0, 0.0, 1.0)})
        assert probe._hooks_unchanged
        frame.run_pass(probe)
        pixels = np.frombuffer(frame.targets["albedo_specular"].read(), np.uint8)
        centre = pixels.reshape(48, 64, 4)[24, 32]
        assert centre[2] > 200 and centre[0] < 10 and centre[1] < 10


@pytest.mark.slow
def test_a_mesh_whose_comb_makes_another_define_gets_another_program(gl):
    """revie_fur's comb field reads the mesh (its comb colours where it has them, the comb
    field texture made again for another mesh): an object given such a mesh between frames is
    drawn as a fresh renderer draws it."""
    import dataclasses

    from deferred.scene.meshes import load_mesh

    def fur_scene():
        return scene_from_dict({
            "size": [64, 48], "camera": {"position": [0.0, 0.6, 2.6]},
            "object": [{"mesh": "builtin:sphere", "material": "revie_fur",
                        "params": {"shells": 0, "stipple": False, "comb_strength": 1.0}}],
            "light": [{"type": "directional", "direction": [-0.3, -1.0, -0.5]}]})

    sphere = load_mesh("builtin:sphere")
    comb = np.tile(np.array([1.0, 0.5, 0.5, 1.0], np.float32), (sphere.vertex_count, 1))
    combed = dataclasses.replace(sphere, comb=comb, has_comb=True)
    scene = fur_scene()
    with Renderer(scene, "deferred", gl=gl) as renderer:
        before = renderer.render().hdr
        scene.objects[0].mesh = combed
        changed = renderer.render().hdr
    assert np.abs(changed - before).max() > 0.01  # the painted comb, not the `comb` parameter
    expected = fur_scene()
    expected.objects[0].mesh = combed
    np.testing.assert_array_equal(changed, fresh_render(gl, expected, "deferred"))


def test_the_same_framebuffer_request_gets_the_full_viewport_and_its_depth_mask(gl):
    """A pass may change the framebuffer it was given; the next pass asking for the same one
    gets it as it asks (the request memo checks what the last pass may have set)."""
    from deferred.gbuffer.layout import DEPTH, GBUFFER_COLOR_TARGETS

    with Renderer(sphere_scene(), "deferred", gl=gl) as renderer:
        renderer.render()
        frame = renderer.last_frame
        # a G-buffer pass: it declares the targets
        frame.current_pass = next(p for p in renderer.passes if p.name.endswith(".gbuffer"))
        fbo = frame.use_framebuffer(GBUFFER_COLOR_TARGETS, DEPTH)
        full = fbo.viewport
        fbo.viewport = (0, 0, 8, 8)
        fbo.depth_mask = False
        again = frame.use_framebuffer(GBUFFER_COLOR_TARGETS, DEPTH)
        assert again is fbo and again.viewport == full and again.depth_mask


def test_materials_replaced_on_their_objects_are_not_kept_for_long(gl):
    scene = sphere_scene()
    with Renderer(scene, "deferred", gl=gl) as renderer:
        for index in range(5):
            scene.objects[0].material = StandardMaterial(
                scene.objects[0].material.params.model_copy(update={"color": (0.1 * index,
                                                                              0.2, 0.3)}))
            renderer.render()
        kept = renderer.kept_inputs._kept
        assert len(kept) <= len(scene.objects) + 1
        assert {inputs.material for inputs in kept.values()} >= {
            obj.material for obj in scene.objects}


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_a_camera_moved_between_frames_is_drawn_from_where_it_is_now(gl, pipeline):
    """The view is a uniform of its own (common/object_transform.glsl): the objects' kept
    transforms are drawn through the camera as it is now."""
    import dataclasses

    scene = sphere_scene()
    with Renderer(scene, pipeline, gl=gl) as renderer:
        first = renderer.render().hdr
        scene.camera = dataclasses.replace(scene.camera, position=(0.8, 1.0, 2.2))
        moved = renderer.render().hdr
    expected = sphere_scene()
    expected.camera = dataclasses.replace(expected.camera, position=(0.8, 1.0, 2.2))
    assert not np.array_equal(first, moved)
    np.testing.assert_array_equal(moved, fresh_render(gl, expected, pipeline))


def test_the_normal_matrix_of_view_and_model_is_the_views_times_the_models():
    """What object_normal_matrix relies on: for a look-at view V and any invertible model M,
    inverse-transpose((V M)_3x3) = (V)_3x3 inverse-transpose(M_3x3) (numpy, float64)."""
    from deferred.scene.camera import Camera

    rng = np.random.default_rng(3)
    for _ in range(20):
        camera = Camera(position=tuple(rng.uniform(-5, 5, 3)), target=tuple(rng.uniform(-1, 1, 3)))
        view = np.asarray(camera.view(), np.float64)
        model = np.eye(4)
        model[:3, :3] = rng.normal(size=(3, 3)) + 2.0 * np.eye(3)
        model[:3, 3] = rng.uniform(-3, 3, 3)
        direct = np.linalg.inv((view @ model)[:3, :3]).T
        split = view[:3, :3] @ np.linalg.inv(model[:3, :3]).T
        np.testing.assert_allclose(split, direct, atol=1e-9)
