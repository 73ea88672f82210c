"""The pipelines: forward == deferred, determinism, resource release, the plugin seam."""

import moderngl
import numpy as np
import pytest
from conftest import psnr

from deferred.core.passes import Phase
from deferred.gbuffer.layout import decode
from deferred.gbuffer.surface_id import surface_id
from deferred.gl.context import Features, GLContext
from deferred.interfaces import registry
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene, scene_from_dict

ALL_LIGHTS = [
    {"type": "ambient", "color": [0.2, 0.22, 0.3], "ground": [0.1, 0.05, 0.02]},
    {"type": "directional", "direction": [-0.5, -1.0, -0.3], "intensity": 0.7},
    {"type": "point", "position": [1.2, 1.2, 1.0], "color": [1.0, 0.6, 0.3], "intensity": 4.0,
     "radius": 4.0},
    {"type": "spot", "position": [-1.0, 2.0, 1.0], "direction": [0.4, -1.0, -0.4],
     "color": [0.3, 0.5, 1.0], "intensity": 6.0, "radius": 5.0, "inner_angle": 12.0,
     "outer_angle": 25.0},
]


def standard_scene(lights=ALL_LIGHTS, size=(200, 150)):
    return scene_from_dict({
        "size": list(size), "light_path": "volumes",
        "camera": {"position": [0.0, 1.5, 3.6], "target": [0.0, 0.4, 0.0]},
        "object": [
            {"mesh": "builtin:plane", "scale": 4.0, "params": {"color": [0.4, 0.4, 0.4]}},
            {"mesh": "builtin:sphere", "position": [-0.6, 0.5, 0.0], "scale": 0.5,
             "params": {"color": [0.8, 0.3, 0.2], "specular_exponent": 64.0}},
            {"mesh": "builtin:torus", "position": [0.7, 0.5, 0.0], "rotation": [70, 0, 0],
             "scale": 0.6, "params": {"color": [0.2, 0.5, 0.8], "specular_intensity": 0.8}},
            {"mesh": "builtin:cube", "position": [0.0, 0.3, -1.0], "rotation": [0, 30, 0],
             "scale": 0.4},
        ],
        "light": lights})


@pytest.mark.parametrize("light", ALL_LIGHTS, ids=lambda light: light["type"])
def test_forward_equals_deferred_per_light_type(render, light):
    scene = standard_scene([light])
    deferred, _ = render(scene, "deferred")
    forward, _ = render(scene, "forward")
    assert psnr(deferred.image[..., :3] / 255.0, forward.image[..., :3] / 255.0) >= 40.0


def test_forward_equals_deferred_all_lights_and_gl33_path(render, gl):
    scene = standard_scene()
    deferred, _ = render(scene, "deferred")
    forward, _ = render(scene, "forward")
    value = psnr(deferred.image[..., :3] / 255.0, forward.image[..., :3] / 255.0)
    assert value >= 40.0
    gl33 = GLContext(gl.ctx, Features(storage_buffers=False))
    with Renderer(scene, "deferred", gl=gl33) as renderer:
        assert np.array_equal(renderer.render().image, deferred.image)


@pytest.mark.slow
def test_demo_scene_is_fur_and_renders_in_both_pipelines(render):
    scene = load_scene()
    assert "revie_fur" in {obj.material.name for obj in scene.objects}
    deferred, _ = render(scene, "deferred", size=(320, 180))
    forward, _ = render(scene, "forward", size=(320, 180))
    # fur is not pixel-equal across pipelines (shell lighting differs by design), but close
    assert psnr(deferred.image[..., :3] / 255.0, forward.image[..., :3] / 255.0) >= 25.0


def test_same_scene_twice_gives_the_same_bytes(render):
    scene = standard_scene()
    first, renderer = render(scene, "deferred")
    again = renderer.render()
    fresh, _ = render(standard_scene(), "deferred")
    assert first.image.tobytes() == again.image.tobytes() == fresh.image.tobytes()


def test_gbuffer_contents(render):
    scene = standard_scene()
    _, renderer = render(scene, "deferred")
    t = renderer.targets
    g = decode(t.read("albedo_specular"), t.read("normal_exponent_id"), t.read("linear_depth"))
    background = g["material_id"] == 0
    assert 0.05 < background.mean() < 0.7
    assert np.all(g["linear_depth"][background] == 0.0)
    assert np.all(g["material_id"][~background] == registry.materials.get("standard").type_id)
    assert np.all(g["shading_model"][~background] ==
                  registry.shading_models.get("blinn_phong").type_id)
    depth = g["linear_depth"][~background]
    assert depth.min() > scene.camera.near and depth.max() < 10.0
    # normals are view-space unit vectors facing the camera (z > 0 in view space)
    normals = g["normal"][~background]
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-3)
    assert np.mean(normals[:, 2] > -0.05) > 0.99
    # the sphere's albedo lands in the G-buffer (8-bit)
    sphere_red = np.isclose(g["albedo"][..., 0], 0.8, atol=1 / 255) & \
        np.isclose(g["albedo"][..., 1], 0.3, atol=1 / 255)
    assert sphere_red.sum() > 500


def test_pass_list_is_ordered_by_phase_and_lights_are_bounded(render):
    scene = standard_scene()
    result, renderer = render(scene, "deferred")
    names = [p.name for p in renderer.passes]
    phases = [p.phase for p in renderer.passes]
    order = [Phase.GEOMETRY, Phase.SCREEN, Phase.STIPPLE, Phase.LIGHTING, Phase.MATERIAL,
             Phase.POST]
    assert [order.index(p) for p in phases] == sorted(order.index(p) for p in phases)
    assert names[:2] == ["gbuffer.clear", "plane0.gbuffer"]
    assert {"lighting.point", "lighting.spot", "lighting.directional",
            "lighting.ambient"} <= set(names)
    for p in renderer.passes:
        assert p.writes, p.name


def test_point_light_volume_touches_only_its_pixels(render):
    """A small point light far from the camera shades few pixels: the volume bounds it."""
    light = {"type": "point", "position": [1.5, 0.2, 0.5], "radius": 0.4, "intensity": 3.0}
    scene = standard_scene([light])
    fragments = []

    def count(render_pass, frame):
        if render_pass.name == "lighting.point":
            query = frame.ctx.query(samples=True)
            with query:
                render_pass.execute(frame)
            fragments.append(query.samples)

    render(scene, "deferred", on_pass=count)
    width, height = scene.size
    assert 0 < fragments[0] < 0.1 * width * height


def test_fifty_frames_do_not_grow_live_gl_objects(gl, monkeypatch):
    created = []
    makers = ["buffer", "texture", "depth_texture", "framebuffer", "renderbuffer",
              "vertex_array", "program", "compute_shader", "sampler"]
    for maker in makers:
        original = getattr(moderngl.Context, maker)

        def wrapped(self, *args, _original=original, **kwargs):
            obj = _original(self, *args, **kwargs)
            created.append(obj)
            return obj

        monkeypatch.setattr(moderngl.Context, maker, wrapped)

    def live() -> int:
        return sum(type(o.mglo).__name__ != "InvalidObject" for o in created)

    gl.park()  # the context's own framebuffer exists before the count starts
    baseline = live()
    renderer = Renderer(standard_scene(), "deferred", gl=gl)
    renderer.render()
    after_first = live()
    assert after_first > baseline
    for _ in range(50):
        renderer.render()
    assert live() == after_first
    renderer.release()
    assert live() == baseline


def test_plugin_material_renders_in_both_pipelines(render):
    from plugin_material import CheckerMaterial

    registry.materials.register(CheckerMaterial)
    try:
        scene = scene_from_dict({
            "size": [160, 120], "tonemap": "none",
            "camera": {"position": [0.0, 2.5, 0.01], "target": [0.0, 0.0, 0.0]},
            "object": [{"mesh": "builtin:plane", "material": "test_checker",
                        "params": {"squares": 4}}],
            "light": [{"type": "ambient", "color": [1.0, 1.0, 1.0], "ground": [1, 1, 1]}]})
        deferred, renderer = render(scene, "deferred")
        forward, _ = render(scene, "forward")
        ids = renderer.targets.read("normal_exponent_id")[..., 3]
        blinn_phong = registry.shading_models.get("blinn_phong").type_id
        assert set(np.unique(ids)) == {0.0, float(surface_id(CheckerMaterial.type_id,
                                                             blinn_phong))}
        # both colours of the checkerboard are on screen, in both pipelines
        for result in (deferred, forward):
            blue = (result.hdr[..., 2] > 0.7) & (result.hdr[..., 0] < 0.2)
            white = (result.hdr[..., 0] > 0.8) & (result.hdr[..., 2] > 0.8)
            assert blue.sum() > 1000 and white.sum() > 1000
        assert psnr(deferred.image[..., :3] / 255.0, forward.image[..., :3] / 255.0) >= 40.0
    finally:
        registry.materials.unregister(CheckerMaterial.name)


def test_session_context_survives_another_context_released(gl):
    """A CLI call inside a session makes and releases its own context; the session's renders
    must still go to the session's context (each renderer makes its context current)."""
    scene = standard_scene(size=(64, 48))
    with Renderer(scene, "deferred", gl=gl) as renderer:
        before = renderer.render().image
        with Renderer(scene, "forward") as own:  # owns (and then releases) a second context
            own.render()
        assert np.array_equal(renderer.render().image, before)
        albedo = renderer.targets.read("albedo_specular")
        assert albedo[..., :3].max() > 0.5


def _raise_gl_error() -> None:
    """Set GL_INVALID_ENUM on the current context, as a driver would (glEnable of no cap)."""
    import ctypes

    ctypes.CDLL("libOpenGL.so.0").glEnable(ctypes.c_uint(0xFFFF))


def test_a_gl_error_while_preparing_a_pass_names_the_pass_not_outside_code(gl, monkeypatch):
    import warnings

    from deferred.errors import RenderError, gl_error
    from deferred.scene.loader import scene_from_dict

    scene = scene_from_dict({"size": [32, 24], "object": [{"mesh": "builtin:sphere"}],
                             "light": [{"type": "directional"}]})
    with Renderer(scene, gl=gl) as renderer:
        target = renderer.passes[1]
        monkeypatch.setattr(type(target), "prepare", lambda self, frame: _raise_gl_error())
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # not "left by code outside the renderer"
            with pytest.raises(RenderError, match=rf"^pass {target.name}: preparing: "
                                                  "GL_INVALID_ENUM$"):
                renderer.render()
        monkeypatch.undo()
        assert renderer.render().image.shape == (24, 32, 4)  # the renderer still works
    message = str(gl_error("pass gbuffer", "GL_OUT_OF_MEMORY", (800, 600)))
    assert message.startswith("pass gbuffer: GL_OUT_OF_MEMORY (the frame's render targets")
    assert "at 800x600" in message and "render smaller" in message


@pytest.mark.parametrize("culprit", [0, 2, 3, "once"])
def test_a_gl_error_in_one_of_a_run_of_object_passes_names_that_pass(gl, monkeypatch, culprit):
    # the error flag is read once a run of passes of one kind (Frame.check_errors): the
    # passes of the run are then run again one by one to name the one that raises it
    from deferred.errors import RenderError
    from deferred.scene.loader import scene_from_dict

    scene = scene_from_dict({"size": [32, 24], "light": [{"type": "directional"}],
                             "object": [{"name": f"ball{i}", "mesh": "builtin:sphere",
                                         "position": [i - 1.5, 0.0, 0.0], "scale": 0.3}
                                        for i in range(4)]})
    with Renderer(scene, gl=gl) as renderer:
        gbuffer = [p for p in renderer.passes if p.name.endswith(".gbuffer")]
        assert len(gbuffer) == 4
        target = gbuffer[1 if culprit == "once" else culprit]
        execute = type(target).execute
        raised = []

        def failing(self, frame):
            execute(self, frame)
            if self is target and not (culprit == "once" and raised):
                raised.append(self)
                _raise_gl_error()

        monkeypatch.setattr(type(target), "execute", failing)
        # an error that does not come again is put on the whole run
        name = r"ball0.gbuffer .. ball3.gbuffer \(4 passes\)" if culprit == "once" else \
            f"ball{culprit}.gbuffer"
        with pytest.raises(RenderError, match=rf"^pass {name}: GL_INVALID_ENUM$"):
            renderer.render()
        monkeypatch.undo()
        assert renderer.render().image.shape == (24, 32, 4)  # the renderer still works


def test_a_pass_failing_after_an_unchecked_gl_error_leaves_no_error_to_the_next_frame(
        gl, monkeypatch):
    # the run's flag is not read before the failure: the failure is what is reported, and the
    # next frame does not find a flag "left by code outside the renderer"
    import warnings

    from deferred.errors import RenderError
    from deferred.scene.loader import scene_from_dict

    scene = scene_from_dict({"size": [32, 24], "light": [{"type": "directional"}],
                             "object": [{"name": f"ball{i}", "mesh": "builtin:sphere",
                                         "position": [i - 0.5, 0.0, 0.0], "scale": 0.3}
                                        for i in range(2)]})
    with Renderer(scene, gl=gl) as renderer:
        first, second = [p for p in renderer.passes if p.name.endswith(".gbuffer")]
        execute = type(first).execute

        def failing(self, frame):
            if self is second:
                raise RuntimeError("broken")
            execute(self, frame)
            _raise_gl_error()

        monkeypatch.setattr(type(first), "execute", failing)
        with pytest.raises(RenderError, match=r"^pass ball1.gbuffer: RuntimeError: broken$"):
            renderer.render()
        monkeypatch.undo()
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert renderer.render().image.shape == (24, 32, 4)


def test_a_pass_after_a_clear_through_another_framebuffer_gets_its_depth_mask(gl):
    # moderngl's clear sets GL's depth mask to the cleared framebuffer's and binds the bound
    # one back without its own: Frame sets the mask again after a pass's clears, though the
    # bound framebuffer's remembered mask has not changed
    import ctypes
    from types import SimpleNamespace

    from deferred.gbuffer.layout import DEPTH, GBUFFER_COLOR_TARGETS

    def gl_depth_mask() -> bool:
        value = ctypes.c_ubyte(9)
        ctypes.CDLL("libOpenGL.so.0").glGetBooleanv(ctypes.c_uint(0x0B72), ctypes.byref(value))
        return bool(value.value)  # GL_DEPTH_WRITEMASK

    with Renderer(standard_scene(size=(32, 24)), "deferred", gl=gl) as renderer:
        renderer.render()
        frame = renderer.last_frame
        seen = []

        def draw(frame):
            frame.use_framebuffer(GBUFFER_COLOR_TARGETS, DEPTH, depth_write=False)
            seen.append(gl_depth_mask())

        names = (*GBUFFER_COLOR_TARGETS, DEPTH)
        probe = SimpleNamespace(name="probe", creates=(), reads=names, writes=names,
                                execute=draw)
        frame.run_pass(probe)  # binds the G-buffer's framebuffer, mask off
        probe.creates = (DEPTH,)  # cleared through the depth target's own framebuffer
        frame.run_pass(probe)
        assert seen == [False, False]


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_an_object_moved_between_frames_is_drawn_where_it_is_now(gl, pipeline):
    """The objects' transform uniforms are kept across frames while nothing they come from
    changes (ObjectTransforms): a model written in place and a model replaced each reach the
    next frame."""
    def scene():
        return scene_from_dict({
            "size": [96, 64], "camera": {"position": [0.0, 1.0, 4.0]},
            "object": [{"mesh": "builtin:plane", "scale": 4.0},
                       {"mesh": "builtin:cube", "position": [-0.6, 0.5, 0.0], "scale": 0.5},
                       {"mesh": "builtin:sphere", "position": [0.7, 0.5, 0.0], "scale": 0.5}],
            "light": [{"type": "directional", "direction": [-0.3, -1.0, -0.5]},
                      {"type": "ambient"}]})

    def fresh(changed):
        with Renderer(changed, pipeline, gl=gl) as renderer:
            return renderer.render().hdr

    kept = scene()
    with Renderer(kept, pipeline, gl=gl) as renderer:
        first = renderer.render().hdr
        kept.objects[1].position = (-0.2, 0.5, 0.0)  # one part of the placement
        in_place = renderer.render().hdr
        kept.objects[2].model = kept.objects[2].model @ np.diag([1.0, 1.6, 1.0, 1.0])
        replaced = renderer.render().hdr
    assert not np.array_equal(first, in_place) and not np.array_equal(in_place, replaced)
    expected = scene()
    expected.objects[1].position = (-0.2, 0.5, 0.0)
    np.testing.assert_array_equal(in_place, fresh(expected))
    expected.objects[2].model = expected.objects[2].model @ np.diag([1.0, 1.6, 1.0, 1.0])
    np.testing.assert_array_equal(replaced, fresh(expected))


@pytest.mark.parametrize("tonemap", ["none", "reinhard", "aces"])
def test_tonemap_operator_matches_a_numpy_reference(gl, tonemap):
    """The final image is the composition times the exposure, through the scene's operator
    (a define of the pass), sRGB encoded: checked against numpy for each operator."""
    from deferred.debug.capture import capture_frame
    from deferred.scene.loader import load_scene

    scene = load_scene(None)
    scene.tonemap = tonemap
    scene.exposure = 1.7
    renderer = Renderer(scene, "deferred", (96, 54), gl=gl)
    try:
        capture = capture_frame(renderer)
    finally:
        renderer.release()
    x = np.maximum(capture.target("composite")[..., :3].astype(np.float64), 0.0) * 1.7
    if tonemap == "reinhard":
        x = x / (1.0 + x)
    elif tonemap == "aces":
        x = np.clip(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)
    x = np.clip(x, 0.0, 1.0)
    encoded = np.where(x < 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    final = capture.target("final")[..., :3].astype(np.float64)
    assert np.abs(final - encoded).max() <= 1.5 / 255
    assert np.abs(final - encoded).mean() < 0.3 / 255
