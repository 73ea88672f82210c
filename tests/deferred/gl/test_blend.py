"""Blend state per output: the named modes are shorthands for Blend values; a tuple gives each
output its own factors and equations (min and max, separate alpha), which GL applies per draw
buffer; the pass graph reads only the outputs a pass blends over."""

import moderngl
import numpy as np
import pytest

from deferred.core.passes import FullscreenPass, Phase, drawn_targets
from deferred.gl.blend import BLEND_MODES, Blend, blend_outputs, blended_outputs, shared_blend
from deferred.gl.device import Device

FRAGMENT = """
#version 330 core
layout(location = 0) out vec4 out_0;
layout(location = 1) out vec4 out_1;
layout(location = 2) out vec4 out_2;
uniform vec4 u_value;
void main() { out_0 = u_value; out_1 = u_value; out_2 = u_value; }
"""
VERTEX = """
#version 330 core
void main() {
    vec2 corner = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
"""


def test_named_modes_are_blend_shorthands_and_tuples_give_each_output_its_own():
    assert blend_outputs("add", 3) == (BLEND_MODES["add"],) * 3
    assert BLEND_MODES["add"] == Blend("one", "one")
    multiply = Blend("zero", "one_minus_src_color")
    assert blend_outputs(("add", None, multiply), 3) == (BLEND_MODES["add"], None, multiply)
    assert shared_blend(blend_outputs("alpha", 2)) == (True, BLEND_MODES["alpha"])
    assert shared_blend(blend_outputs(("add", "min"), 2))[0] is False
    assert Blend("one", "one", "add", "zero", "one_minus_src_alpha").factors == (
        moderngl.ONE, moderngl.ONE, moderngl.ZERO, moderngl.ONE_MINUS_SRC_ALPHA)
    with pytest.raises(ValueError, match="2 blend states for 3 outputs"):
        blend_outputs(("add", "add"), 3)
    with pytest.raises(ValueError, match="unknown blend mode 'ad'"):
        blend_outputs("ad", 1)
    with pytest.raises(ValueError, match="not a factor"):
        Blend("one", "two")
    with pytest.raises(ValueError, match="not an equation"):
        Blend(equation="average")


def test_a_pass_reads_only_the_outputs_it_blends_over():
    assert blended_outputs(("add", None), ("a", "b")) == ("a",)
    reads, writes = drawn_targets((), ("a", "b"), (None, "add"), None, False, False)
    assert reads == ("b",) and writes == ("a", "b")
    reads, _ = drawn_targets((), ("a", "b"), "add", None, False, False)
    assert reads == ("a", "b")
    with pytest.raises(ValueError, match="pass p: blend: 1 blend states for 2 outputs"):
        FullscreenPass("p", Phase.POST, "x.frag", {}, ("a", "b"), blend=("add",))


def draw(ctx, device, textures, blend, value):
    fbo = ctx.framebuffer(textures)
    fbo.use()
    device.set_state(blend=blend)
    program = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
    program["u_value"].value = value
    ctx.vertex_array(program, []).render(moderngl.TRIANGLES, vertices=3)
    return fbo


def read(texture):
    return np.frombuffer(texture.read(), np.float32).reshape(-1, 4)[0]


def test_each_output_blends_by_its_own_state(gl):
    ctx = gl.ctx
    gl.make_current()
    textures = [ctx.texture((4, 4), 4, dtype="f4") for _ in range(3)]
    start = (0.5, 0.25, 0.75, 0.5)
    for texture in textures:
        texture.write(np.tile(np.float32(start), 16).tobytes())
    device = Device(ctx, None, None)
    states = ("add", Blend("one", "one", "max", "zero", "one_minus_src_alpha", "add"), None)
    source = (0.25, 0.5, 0.25, 0.5)
    draw(ctx, device, textures, states, source)
    np.testing.assert_allclose(read(textures[0]), np.add(start, source))
    # colour: max; alpha: zero x source + (1 - source alpha) x destination
    np.testing.assert_allclose(read(textures[1]), (0.5, 0.5, 0.75, 0.25))
    np.testing.assert_allclose(read(textures[2]), source)  # written, not blended
    # a shared state after a per-output one applies to every buffer again
    for texture in textures:
        texture.write(np.tile(np.float32(start), 16).tobytes())
    draw(ctx, device, textures, "min", source)
    for texture in textures:
        np.testing.assert_allclose(read(texture), np.minimum(start, source))
    device.set_state()
    for texture in textures:
        texture.release()
