"""The pass graph: declarations checked before any GL work, targets created and cleared from
them, passes named in failures, strict uniforms, passes inserted from Python."""

import numpy as np
import pytest

from deferred.core.graph import PassGraphError, compile_graph
from deferred.core.passes import FullscreenPass, ObjectPass, Phase, RenderPass
from deferred.errors import InputError, RenderError
from deferred.gbuffer.layout import LINEAR_DEPTH
from deferred.gl.target_spec import TargetSpec
from deferred.gl.targets import COMPOSITE, FINAL
from deferred.interfaces.material import Material
from deferred.interfaces.techniques import PhasePasses
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SCENE = {
    "size": [48, 32],
    "camera": {"position": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0]},
    "object": [{"mesh": "builtin:sphere"}],
    "light": [{"type": "directional", "direction": [0.0, 0.0, -1.0]}],
}
SPEC = TargetSpec(4, "f2", "scratch", clear=(0.25, 0.5, 0.75, 1.0))


class NoGL:
    """Stands in for a GL context: any use of it fails the test."""

    def __getattr__(self, name):
        raise AssertionError(f"GL work ({name}) before the pass graph was checked")


class Marker(RenderPass):
    def __init__(self, name, reads=(), writes=(), creates=None):
        self.name = name
        self.phase = Phase.SCREEN
        self.reads = tuple(reads)
        self.writes = tuple(writes)
        self.creates = dict(creates or {})

    def execute(self, frame):
        pass


def test_graph_accepts_a_consistent_list_and_lists_its_targets():
    graph = compile_graph([Marker("a", creates={"t": SPEC}), Marker("b", reads=["t"]),
                           Marker("c", writes=["t"])])
    assert graph.targets == {"t": SPEC}
    assert graph.creators == {"t": "a"}


@pytest.mark.parametrize("passes, message", [
    ([Marker("a", reads=["nowhere"])], "pass a: reads unknown target 'nowhere'"),
    ([Marker("a", writes=["nowhere"])], "pass a: writes unknown target 'nowhere'"),
    ([Marker("a", reads=["t"]), Marker("b", creates={"t": SPEC})],
     "pass a: reads target 't' before any pass produces it (pass b creates it later)"),
    ([Marker("a", creates={"t": SPEC}), Marker("b", creates={"t": SPEC})],
     "pass b: creates target 't', which pass a already creates"),
    ([Marker("a"), Marker("a")], "two passes are named 'a'"),
    ([Marker("a", creates={"t": SPEC}),
      FullscreenPass("b", Phase.POST, "post/copy.frag", {"u_source": "t"}, ("t",))],
     "pass b: samples target 't' while writing it (snapshot it first with copy_pass)"),
])
def test_graph_errors_name_the_pass_and_the_target(passes, message):
    with pytest.raises(PassGraphError, match=message.replace("(", r"\(").replace(")", r"\)")):
        compile_graph(passes)


class ReadsUnknown(Material):
    """A material whose pass reads a target no pass creates."""

    name = "test_reads_unknown"
    surface_shader = "materials/standard/surface.glsl"
    techniques = (*Material.techniques, PhasePasses(Phase.MATERIAL, lambda material, obj: [
        ObjectPass(f"{obj.label}.broken", Phase.MATERIAL, obj, fragment="post/copy.frag",
                   colors=(COMPOSITE,), extra_reads=("velocity",))]))


class ReadsTooEarly(Material):
    """A geometry-phase pass reading the light accumulation, made only later."""

    name = "test_reads_early"
    surface_shader = "materials/standard/surface.glsl"
    techniques = (*Material.techniques, PhasePasses(Phase.GEOMETRY, lambda material, obj: [
        ObjectPass(f"{obj.label}.early", Phase.GEOMETRY, obj, fragment="post/copy.frag",
                   colors=(COMPOSITE,), extra_reads=("light_accumulation",))]))


@pytest.mark.parametrize("material, message", [
    (ReadsUnknown, "pass sphere0.broken: reads unknown target 'velocity'"),
    (ReadsTooEarly, "pass sphere0.early: reads target 'light_accumulation' before any pass "
                    "produces it"),
])
def test_material_pass_errors_come_before_any_gl_work(material, message):
    scene = scene_from_dict(SCENE)
    scene.objects[0].material = material()
    with pytest.raises(PassGraphError, match=message):
        Renderer(scene, gl=NoGL())


def test_created_targets_are_cleared_to_their_declared_value(render):
    scene = scene_from_dict(SCENE)
    _, renderer = render(scene)
    created = FullscreenPass("test.scratch", Phase.POST, "post/copy.frag",
                             {"u_source": FINAL}, ("scratch",), creates={"scratch": SPEC},
                             blend="add")
    renderer.insert_pass(created, after="post.tonemap")
    renderer.render()
    scratch = renderer.targets.read("scratch")
    final = renderer.targets.read(FINAL)
    # blend "add" over the clear value: scratch = clear + final
    assert np.allclose(scratch, np.asarray(SPEC.clear) + final, atol=2e-3)
    assert "scratch" in renderer.graph.targets


def test_insert_pass_is_checked_and_placed(render):
    scene = scene_from_dict(SCENE)
    _, renderer = render(scene)
    probe = FullscreenPass("test.depth_probe", Phase.LIGHTING, "post/copy.frag",
                           {"u_source": LINEAR_DEPTH}, ("probe",),
                           creates={"probe": TargetSpec(1, "f4", "probe", clear=(0.0,))})
    renderer.insert_pass(probe, before="lighting.cull_tiles")
    names = [p.name for p in renderer.passes]
    assert names.index("test.depth_probe") == names.index("lighting.cull_tiles") - 1
    renderer.render()
    assert np.array_equal(renderer.targets.read("probe"), renderer.targets.read(LINEAR_DEPTH))
    late = FullscreenPass("test.too_early", Phase.GEOMETRY, "post/copy.frag",
                          {"u_source": "probe"}, ("late",),
                          creates={"late": TargetSpec(1, "f4", "late", clear=(0.0,))})
    with pytest.raises(PassGraphError, match="pass test.too_early: reads target 'probe' before"):
        renderer.insert_pass(late, before="gbuffer.clear")
    assert "test.too_early" not in [p.name for p in renderer.passes]  # left as it was
    with pytest.raises(PassGraphError, match="no pass is named 'nope'"):
        renderer.insert_pass(late, after="nope")


def test_an_exception_inside_a_pass_names_the_pass(render):
    scene = scene_from_dict(SCENE)
    _, renderer = render(scene)

    class Explodes(Marker):
        def execute(self, frame):
            raise ZeroDivisionError("boom")

    renderer.insert_pass(Explodes("test.explodes"), after="gbuffer.clear")
    with pytest.raises(RenderError, match=r"pass test\.explodes: ZeroDivisionError: boom"):
        renderer.render()


def test_a_target_the_pass_did_not_declare_is_an_error_naming_the_pass(render):
    scene = scene_from_dict(SCENE)
    _, renderer = render(scene)

    class Sneaky(Marker):
        def execute(self, frame):
            frame.target(LINEAR_DEPTH)

    renderer.insert_pass(Sneaky("test.sneaky"), after="gbuffer.clear")
    with pytest.raises(RenderError, match="pass test.sneaky: target 'linear_depth' is used but "
                                          "not declared"):
        renderer.render()


def test_a_misspelt_uniform_is_an_error_in_strict_mode_only(gl):
    def misspelt(frame):
        return {"u_exposur": 1.0}

    def pass_():
        return FullscreenPass("test.misspelt", Phase.POST, "post/tonemap.frag",
                              {"u_source": COMPOSITE}, ("copy",), uniforms=misspelt,
                              creates={"copy": TargetSpec(4, "f1", "copy")})

    for strict in (True, False):
        renderer = Renderer(scene_from_dict(SCENE), gl=gl, strict=strict)
        try:
            renderer.insert_pass(pass_(), after="post.tonemap")
            if strict:
                with pytest.raises(RenderError, match="pass test.misspelt: program "
                                                      "post/fullscreen.vert \\+ post/tonemap.frag "
                                                      "declares no uniform 'u_exposur'"):
                    renderer.render()
            else:
                renderer.render()
        finally:
            renderer.release()


def test_a_material_uniform_no_program_declares_is_an_error_in_strict_mode(gl):
    scene = scene_from_dict(SCENE)
    material = scene.objects[0].material

    class Misspelt(type(material)):
        def uniforms(self, frame):
            return {**super().uniforms(frame), "u_specular_intensty": 0.5}

    scene.objects[0].material = Misspelt(material.params)
    renderer = Renderer(scene, gl=gl, strict=True)
    try:
        with pytest.raises(RenderError, match="material standard: no program of it declares "
                                              "uniform 'u_specular_intensty'"):
            renderer.render()
    finally:
        renderer.release()


def test_a_half_size_target_is_created_at_half_size_and_drawn_whole(render):
    scene = scene_from_dict(SCENE)
    _, renderer = render(scene)
    half = TargetSpec(4, "f2", "half", clear=(0.0,) * 4, scale=0.5)
    renderer.insert_pass(FullscreenPass("test.half", Phase.POST, "post/copy.frag",
                                        {"u_source": COMPOSITE}, ("half",),
                                        creates={"half": half}), after="post.tonemap")
    renderer.render()
    assert renderer.targets["half"].size == (24, 16)
    # the viewport follows the target: every pixel written (the frame's lower-left quarter)
    np.testing.assert_array_equal(renderer.targets.read("half"),
                                  renderer.targets.read(COMPOSITE)[:16, :24])


def test_a_bad_layout_is_refused_before_any_gl_work():
    from deferred.gbuffer.layout import GBufferData

    class DeclaresFoo(Material):
        name = "test_declares_foo"
        surface_shader = "materials/standard/surface.glsl"
        gbuffer_data = (GBufferData("foo", "R8", ("x",)),)

    class DeclaresFooAgain(DeclaresFoo):
        name = "test_declares_foo_again"
        gbuffer_data = (GBufferData("foo", "RG8", ("x", "y")),)

    scene = scene_from_dict({**SCENE, "object": [{"mesh": "builtin:sphere"}] * 2})
    scene.objects[0].material = DeclaresFoo()
    scene.objects[1].material = DeclaresFooAgain()
    for pipeline in ("deferred", "forward"):
        with pytest.raises(InputError, match="G-buffer data 'foo' is declared as RG8"):
            Renderer(scene, pipeline, gl=NoGL())


def test_a_parameter_may_not_shadow_a_framework_uniform(render):
    from pydantic import Field

    from deferred.interfaces.material import MaterialParams

    class ShadowingParams(MaterialParams):
        resolution: float = Field(2.0)

    class Shadowing(Material):
        name = "test_shadowing"
        Params = ShadowingParams
        surface_shader = "materials/standard/surface.glsl"

    scene = scene_from_dict(SCENE)
    scene.objects[0].material = Shadowing()
    with pytest.raises(RenderError, match="parameters would set the framework's uniform "
                                          "u_resolution"):
        render(scene)


def test_a_gbuffer_pass_writing_surfaces_without_depth_is_refused(render):
    """The lighting runs where the G-buffer's depth is nearer than the far plane: a pass that
    wrote surfaces without depth would leave them unlit, so it is refused before it runs."""
    from deferred.interfaces.techniques import GBufferPass

    scene = scene_from_dict(SCENE)
    _, renderer = render(scene)
    obj = scene.objects[0]
    without = GBufferPass("test.no_depth", Phase.GEOMETRY, obj, depth=None)
    with pytest.raises(PassGraphError, match="pass test.no_depth: writes G-buffer surfaces "
                                             r"\('normal_exponent_id'\) with no 'depth'"):
        renderer.insert_pass(without, after="gbuffer.clear")
    # the same pass writing depth, or testing against it to draw over surfaces already there
    renderer.insert_pass(GBufferPass("test.with_depth", Phase.GEOMETRY, obj),
                         after="gbuffer.clear")
    renderer.insert_pass(GBufferPass("test.over_depth", Phase.GEOMETRY, obj, depth_write=False,
                                     depth_func="lequal"), after="test.with_depth")
    assert {"test.with_depth", "test.over_depth"} <= {p.name for p in renderer.passes}
