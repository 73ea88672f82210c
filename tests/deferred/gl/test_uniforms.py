"""Uniforms written only when they change (deferred.gl.uniforms) and the frame's GL state memo: what
the program and the context end up holding is what the last caller asked for."""

import numpy as np
import pytest

from deferred.gl.uniforms import ProgramUniforms, gl_value

VERTEX = """#version 330
uniform mat4 u_view;
uniform vec3 u_color;
uniform float u_x;
void main() { gl_Position = u_view * vec4(u_color * u_x, 1.0); }
"""
FRAGMENT = """#version 330
out vec4 colour;
void main() { colour = vec4(1.0); }
"""


@pytest.fixture
def program(gl):
    made = gl.ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
    yield made
    made.release()


class CountingWriters(dict):
    """A program's uniform writers, each counting the writes it makes (into ``log``)."""

    def __init__(self, log):
        super().__init__()
        self.log = log

    def __setitem__(self, name, writer):
        def counted(value, name=name, writer=writer):
            self.log.append(name)
            writer(value)
        super().__setitem__(name, counted)


class CountingUniforms(ProgramUniforms):
    """Counts the writes that reach GL."""

    __slots__ = ("writes",)

    def __init__(self, program):
        super().__init__(program)
        self.writes = []
        self._writers = CountingWriters(self.writes)


def test_a_value_the_program_holds_is_not_written_again(program):
    uniforms = CountingUniforms(program)
    view = np.arange(16, dtype=np.float64).reshape(4, 4)
    uniforms.set({"u_view": view, "u_color": (1.0, 2.0, 3.0), "u_x": 0.5, "u_unknown": 1.0})
    assert sorted(uniforms.writes) == ["u_color", "u_view", "u_x"]  # unknown names skipped
    uniforms.set({"u_view": view.copy(), "u_color": (1.0, 2.0, 3.0), "u_x": 0.5})
    assert len(uniforms.writes) == 3
    uniforms.set({"u_view": view, "u_color": (1.0, 2.0, 3.0), "u_x": 0.25})
    assert uniforms.writes[3:] == ["u_x"]
    assert program["u_x"].value == pytest.approx(0.25)
    # matrices reach GL column-major (GLSL's order), as gl_value converts them
    stored = np.array(program["u_view"].value, dtype=np.float32)
    np.testing.assert_array_equal(stored, view.T.reshape(-1))
    assert gl_value(view) == np.ascontiguousarray(view.T, np.float32).tobytes()


def test_a_shared_dict_is_set_again_after_a_pass_overwrote_one_of_its_values(program):
    uniforms = CountingUniforms(program)
    camera = {"u_x": 1.0, "u_color": (0.0, 1.0, 0.0)}
    uniforms.set_shared("camera", camera)
    uniforms.set_shared("camera", camera)
    assert len(uniforms.writes) == 2  # the second time: skipped whole
    uniforms.set({"u_x": 3.0})  # a pass's own value for a camera name
    assert program["u_x"].value == pytest.approx(3.0)
    uniforms.set_shared("camera", camera)
    assert program["u_x"].value == pytest.approx(1.0)
    assert uniforms.writes[2:] == ["u_x", "u_x"]  # only the overwritten value, twice


def test_stable_values_are_planned_once_and_their_replacement_reaches_gl(program):
    """set_stable works out once per StableValues which names the program has and their GL
    values; values replacing them are planned again, the values hold their plans, and a
    plain dict (which its owner may change in place) is set as by set."""
    from deferred.gl.uniforms import StableValues

    uniforms = CountingUniforms(program)
    view = np.arange(16, dtype=np.float64).reshape(4, 4)
    first = StableValues(u_view=view, u_x=0.5, u_unknown=1.0)
    uniforms.set_stable(first)
    uniforms.set_stable(first)
    assert sorted(uniforms.writes) == ["u_view", "u_x"]  # once; the unknown name skipped
    np.testing.assert_array_equal(np.array(program["u_view"].value, np.float32),
                                  view.T.reshape(-1))
    uniforms.set_stable(StableValues(u_view=view, u_x=0.75))
    assert uniforms.writes[2:] == ["u_x"]
    assert program["u_x"].value == pytest.approx(0.75)
    uniforms.set_stable(first)  # the first values again: their value is written back
    assert program["u_x"].value == pytest.approx(0.5)
    # a shared dict's value overwritten by stable values is set again with the dict
    camera = {"u_x": 1.0}
    uniforms.set_shared("camera", camera)
    uniforms.set_stable(first)
    uniforms.set_shared("camera", camera)
    assert program["u_x"].value == pytest.approx(1.0)
    # a plain dict changed in place reaches GL each time
    changing = {"u_x": 2.0}
    uniforms.set_stable(changing)
    changing["u_x"] = 3.0
    uniforms.set_stable(changing)
    assert program["u_x"].value == pytest.approx(3.0)
    # values replaced many times: each set right, each plan held by its values
    for index in range(10):
        values = StableValues(u_x=float(index))
        uniforms.set_stable(values)
        assert program["u_x"].value == pytest.approx(float(index))
        uniforms.set_stable(values)  # planned the second time
        assert values.plans == {uniforms: (("u_x", float(index)),)}


def test_forgotten_values_are_written_again(program):
    # between frames code may write a program directly; the frame forgets what it wrote
    uniforms = ProgramUniforms(program)
    uniforms.set({"u_x": 1.0})
    program["u_x"].value = 7.0
    uniforms.forget()
    uniforms.set({"u_x": 1.0})
    assert program["u_x"].value == pytest.approx(1.0)


def test_the_state_memo_sets_what_a_pass_states(render):
    # A pass stating the last pass's state sets nothing; one changing only the depth offset
    # between draws (the root shell) must not leave the next pass with its offset.
    from deferred.scene.loader import load_scene

    _, renderer = render(load_scene("builtin:demo"), size=(32, 18))
    frame = renderer.last_frame
    ctx = frame.ctx
    frame.set_state(depth_test=True, cull="back", depth_offset=(1.0, 2.0))
    assert ctx.polygon_offset == (1.0, 2.0)
    frame.set_depth_offset((0.0, 0.0))
    assert ctx.polygon_offset == (0.0, 0.0)
    frame.set_state(depth_test=True, cull="back", depth_offset=(1.0, 2.0))
    assert ctx.polygon_offset == (1.0, 2.0)
    frame.set_state(blend="add")
    assert ctx.polygon_offset == (0.0, 0.0)


def test_gl_call_times_are_measured_only_when_asked(render):
    from deferred.scene.loader import load_scene

    result, renderer = render(load_scene("builtin:overdraw"), size=(64, 36))
    assert result.gl_call_seconds == 0.0
    timed = renderer.render(time_gl_calls=True)
    assert timed.gl_call_seconds > 0.0
    np.testing.assert_array_equal(timed.hdr, result.hdr)
    assert timed.draws_by_pass == result.draws_by_pass
    assert sum(result.draws_by_pass.values()) == result.draw_calls



WRITER_VERTEX = """#version 330
uniform float u_float;
uniform int u_int;
uniform bool u_bool;
uniform vec2 u_vec2;
uniform vec3 u_vec3;
uniform vec4 u_vec4;
uniform ivec3 u_ivec3;
uniform mat3 u_mat3;
uniform mat4 u_mat4;
uniform float u_array[3];
uniform sampler2D u_sampler;
void main() {
    vec4 t = texture(u_sampler, u_vec2);
    float b = u_bool ? 1.0 : 0.0;
    gl_Position = u_mat4 * vec4(u_mat3 * u_vec3 * u_float + vec3(u_ivec3) * float(u_int), b)
                  + u_vec4 + t + vec4(u_array[0] + u_array[1] + u_array[2]);
}
"""
WRITER_VALUES = {
    "u_float": 0.375, "u_int": -7, "u_bool": True, "u_vec2": (0.25, -1.5),
    "u_vec3": (1.0, 2.0, 3.0), "u_vec4": (4.0, 5.0, 6.0, 7.0), "u_ivec3": (1, -2, 3),
    "u_mat3": np.arange(9, dtype=np.float64).reshape(3, 3),
    "u_mat4": np.arange(16, dtype=np.float64).reshape(4, 4) * 0.5,
    "u_array": [0.5, 1.5, 2.5], "u_sampler": 3,
}


def test_the_uniform_writer_leaves_what_moderngls_own_setter_does(gl):
    """uniform_writer packs and writes past moderngl's Python layers: every type of uniform
    (arrays through the handle) holds the value moderngl's own setter gives it."""
    from deferred.gl.uniforms import uniform_writer

    ours = gl.ctx.program(vertex_shader=WRITER_VERTEX, fragment_shader=FRAGMENT)
    theirs = gl.ctx.program(vertex_shader=WRITER_VERTEX, fragment_shader=FRAGMENT)
    try:
        for name, value in WRITER_VALUES.items():
            converted = gl_value(value)
            uniform_writer(ours[name])(converted)
            if isinstance(converted, bytes):
                theirs[name].write(converted)
            else:
                theirs[name].value = converted
        for name in WRITER_VALUES:
            assert ours[name].read() == theirs[name].read(), name
        assert ours["u_int"].value == -7 and ours["u_vec2"].value == (0.25, -1.5)
        assert ours["u_array"].value == pytest.approx([0.5, 1.5, 2.5])
    finally:
        ours.release()
        theirs.release()


def test_the_private_moderngl_writer_is_pinned(gl):
    """uniform_writer writes past moderngl's Python layers through the private
    ``Context._write_uniform`` (moderngl 5.12 and later); where moderngl drops or renames it
    the writer falls back to the handle's own setter, correct but slower. This pins it: a
    moderngl without it fails here, by name, instead of slowing every draw unseen (the
    equivalence test above catches a changed signature)."""
    import moderngl

    from deferred.gl.uniforms import uniform_writer

    program = gl.ctx.program(vertex_shader=WRITER_VERTEX, fragment_shader=FRAGMENT)
    try:
        handle = program["u_vec3"]
        assert callable(getattr(handle.ctx, "_write_uniform", None)), (
            f"moderngl {moderngl.__version__} has no Context._write_uniform: "
            "deferred.gl.uniforms.uniform_writer needs a look")
        assert uniform_writer(handle).__name__ == "write"  # the direct path, not the fallback
        assert uniform_writer(program["u_array"]).__name__ == "write_by_handle"
    finally:
        program.release()
