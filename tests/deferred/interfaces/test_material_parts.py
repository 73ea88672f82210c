"""A material composed of parts (deferred.interfaces.material): pass inputs given to a plain pass
type, techniques adding passes, a simulation brought to each frame's time once, and the old
hooks of the base class refused when a class defines one, saying what to write instead."""

import pytest

from deferred.api import (
    GBufferPass,
    InputError,
    Material,
    Motion,
    PassInput,
    Phase,
    PhasePasses,
    ReachMotion,
    ShadowCaster,
    Simulation,
    SurfacePasses,
    Technique,
)
from deferred.materials.standard import StandardMaterial
from deferred.render.budget import held_memory
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SCENE = {
    "size": [48, 36],
    "camera": {"position": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0]},
    "object": [{"mesh": "builtin:sphere", "params": {"color": [0.8, 0.1, 0.1]}}],
    "light": [{"type": "ambient", "intensity": 1.0}],
}


class Tint(PassInput):
    """Gives the pass its own ``u_color``, over the material's."""

    def __init__(self, color):
        self.color = color

    def uniforms(self, frame, obj):
        return {"u_color": self.color}


class TintedSurface(StandardMaterial):
    techniques = (SurfacePasses(inputs=(Tint((0.1, 0.8, 0.1)),)),)


def scene_with(material_cls, **params):
    scene = scene_from_dict(SCENE)
    base = scene.objects[0].material.params.model_dump()
    scene.objects[0].material = material_cls(material_cls.Params(**{**base, **params}))
    return scene


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_an_input_given_to_a_plain_pass_reaches_its_program(gl, pipeline):
    with Renderer(scene_with(TintedSurface), pipeline, gl=gl) as renderer:
        red, green, _ = renderer.render(hdr=True).hdr[18, 24, :3]
    assert green > 4.0 * red  # the input's colour, not the params' red


def test_a_pass_with_inputs_is_not_drawn_as_a_plain_one():
    scene = scene_from_dict(SCENE)
    obj = scene.objects[0]
    plain = GBufferPass("a", Phase.GEOMETRY, obj)
    given = GBufferPass("b", Phase.GEOMETRY, obj, inputs=(Tint((0.0, 1.0, 0.0)),))
    assert plain._plain and not given._plain


def test_an_input_reading_a_target_orders_its_pass_after_the_maker():
    class Reads(PassInput):
        reads = ("light_accumulation",)

    obj = scene_from_dict(SCENE).objects[0]
    made = GBufferPass("a", Phase.MATERIAL, obj, inputs=(Reads(),), extra_reads=("composite",))
    assert made.samples == ("composite", "light_accumulation")
    assert set(made.samples) <= set(made.reads)


def test_a_material_s_passes_are_its_techniques_in_their_order():
    class Extra(Technique):
        def passes(self, material, phase, obj):
            return [GBufferPass(f"{obj.label}.extra_{phase.value}", phase, obj)] \
                if phase == Phase.GEOMETRY else []

        def scene_passes(self, objects, phase):
            return [GBufferPass(f"scene.{len(objects)}", phase, objects[0])] \
                if phase == Phase.GEOMETRY else []

    class Composed(StandardMaterial):
        techniques = (*Material.techniques, Extra(),
                      PhasePasses(Phase.GEOMETRY, lambda material, obj: [
                          GBufferPass(f"{obj.label}.last", Phase.GEOMETRY, obj)]))

    obj = scene_with(Composed).objects[0]
    names = [p.name for p in obj.material.passes(Phase.GEOMETRY, obj)]
    assert names == ["sphere0.gbuffer", "sphere0.extra_geometry", "sphere0.last"]
    assert [p.name for p in obj.material.passes(Phase.FORWARD, obj)] == ["sphere0.forward"]
    assert [p.name for p in Composed.scene_passes([obj, obj], Phase.GEOMETRY)] == ["scene.2"]
    assert Composed.scene_passes([obj], Phase.FORWARD) == []


class Ticks:
    """A simulation's state: the times it was brought to, and whether it was released."""

    def __init__(self):
        self.times = []
        self.released = False

    def release(self):
        self.released = True


class Clock(Simulation):
    key = "test_clock"
    started = []

    def start(self, ctx, obj):
        self.started.append(obj.label)
        return Ticks()

    def advance(self, state, frame, obj):
        state.times.append(frame.time)

    def check_time(self, obj, time, where):
        if time > obj.material.params.specular_exponent:
            raise InputError(f"t = {time:g} s is past the clock's end", where)

    def held_memory(self, obj):
        return {f"clock of {obj.label}": 1000}


class Clocked(StandardMaterial):
    simulation = Clock()
    motion = ReachMotion("specular_intensity")


def test_a_simulation_is_brought_to_each_frame_s_time_once_and_goes_with_the_renderer(gl):
    Clock.started.clear()
    scene = scene_with(Clocked, specular_exponent=10.0, specular_intensity=0.25)
    obj = scene.objects[0]
    seen = []

    def before_pass(render_pass, frame):
        state = Clocked.simulation.state(frame, frame.scene.object_state(obj))
        seen.append((frame.time, state))

    with Renderer(scene, "deferred", gl=gl) as renderer:
        renderer.render(time=0.5, before_pass=before_pass)
        renderer.render(time=0.25, before_pass=before_pass)
        state = seen[0][1]
        assert Clock.started == ["sphere0"]  # one state for the renderer's life
        assert state.times == [0.5, 0.25]  # once a frame, before any pass
        assert all(s is state for _, s in seen)
        assert held_memory(renderer.state)["clock of sphere0"] == 1000
        assert obj.material.motion.extent(renderer.state.object_state(obj)) == 0.25
        with pytest.raises(InputError, match=r"^time: t = 11 s is past the clock's end"):
            renderer.render(time=11.0)
    assert state.released


def test_a_material_without_parts_has_the_defaults():
    assert StandardMaterial.simulation is None
    assert type(StandardMaterial.motion) is Motion
    assert type(StandardMaterial.shadow) is ShadowCaster
    assert [type(t) for t in StandardMaterial.techniques] == [SurfacePasses]


@pytest.mark.parametrize("hook, instead", [
    ("material_passes", "techniques = (*Material.techniques, PhasePasses(Phase.MATERIAL, "
                        "build))"),
    ("geometry_passes", "give SurfacePasses(vertex=..., inputs=..., gbuffer=MyPass) in place "
                        "of the default SurfacePasses() (docs/"),
    ("stipple_passes", "PhasePasses(Phase.STIPPLE, build)"),
    ("draw_shadow", "shadow = MyCaster()`, a ShadowCaster subclass defining draw(frame, obj, "
                    "view)"),
    ("draw_opacity", "draw_opacity(frame, obj, view, stage)"),
    ("opacity_shadows", "opacity_shadows(obj)"),
    ("motion_extent", "motion = ReachMotion(\"<parameter>\")"),
    ("check_time_for", "simulation = MySimulation()`, a Simulation subclass defining "
                       "check_time(obj, time, where)"),
])
def test_a_hook_that_became_a_part_is_refused_saying_what_to_write(hook, instead):
    with pytest.raises(TypeError) as raised:
        type("OldSpelling", (Material,), {hook: lambda self, *args: [], "name": "old"})
    message = str(raised.value)
    assert f"OldSpelling defines {hook}, which the framework no longer asks" in message
    assert instead in message
    assert message.endswith("(docs/writing-a-material.md)")


def test_a_subclass_of_a_built_in_keeps_its_parts():
    from deferred.materials.shell_fur import ShellFurMaterial

    class Longer(ShellFurMaterial):
        pass

    assert Longer.simulation is ShellFurMaterial.simulation
    assert Longer.techniques == ShellFurMaterial.techniques
    assert isinstance(Longer.motion, ReachMotion) and Longer.motion.parameter == "fur_length"
