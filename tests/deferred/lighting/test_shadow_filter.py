"""The shadow filters of lighting/shadows.glsl against a numpy reference: the pcf filter is the
3x3 grid of bilinear comparisons a texel apart (a tent over 4x4 texels) whatever number of
lookups the shader spends on it, and the soft filter the mean of its Poisson taps."""

import moderngl
import numpy as np
from glsl_harness import draw_values
from locations import FIXTURES

from deferred.gbuffer.layout import GBufferLayout
from deferred.gl.shaderlib import ShaderLibrary
from deferred.interfaces import registry
from deferred.materials.standard import StandardMaterial
from deferred.render.generated import generated_glsl

HARNESS = FIXTURES / "shadow_filter_harness"
SIZE = 64  # the depth map's texels a side
POISSON = np.array([
    (-0.9420, -0.3991), (0.9456, -0.7689), (-0.0942, -0.9294), (0.3450, 0.2939),
    (-0.9159, 0.4577), (-0.8154, -0.8791), (-0.3828, 0.2768), (0.9748, 0.7565),
    (0.4432, -0.9751), (0.5374, -0.4737), (-0.2650, -0.4189), (0.7920, 0.1909),
    (-0.2419, 0.9971), (-0.8141, 0.9144), (0.1998, 0.7864), (0.1438, -0.1410)])


def bilinear_comparison(depths, u, v, reference):
    """GL's bilinear comparison (LEQUAL) at (u, v): each of the four texels around compared
    with ``reference`` first, the results weighed bilinearly."""
    s, t = u * SIZE - 0.5, v * SIZE - 0.5
    i, j = int(np.floor(s)), int(np.floor(t))
    fs, ft = s - i, t - j
    lit = 0.0
    for dj, wy in ((0, 1.0 - ft), (1, ft)):
        for di, wx in ((0, 1.0 - fs), (1, fs)):
            texel = depths[np.clip(j + dj, 0, SIZE - 1), np.clip(i + di, 0, SIZE - 1)]
            lit += wx * wy * float(reference <= texel)
    return lit


def reference_filter(depths, point, soft):
    u, v, z = point
    if soft:
        taps = POISSON * 2.0 / SIZE  # two texels wide (the harness's header)
    else:
        taps = np.array([(x, y) for y in (-1, 0, 1) for x in (-1, 0, 1)], float) / SIZE
    return np.mean([bilinear_comparison(depths, u + du, v + dv, z) for du, dv in taps])


def glsl_filter(gl, depths, points):
    ctx = gl.ctx
    gl.make_current()
    gl.park()
    lib = ShaderLibrary(ctx, 330)
    lib.add_root(HARNESS)
    models = registry.shading_models.builtins()  # the files common/lighting.glsl includes
    layout = GBufferLayout({d.name: d for m in models for d in m.gbuffer_data})
    for name, text in generated_glsl(registry.lights.builtins(), models, layout,
                                     [StandardMaterial()]).items():
        lib.set_virtual_file(name, text)
    program = lib.program("shadow_filter_harness.vert", "shadow_filter_harness.frag")
    atlas = ctx.depth_texture((SIZE, SIZE), depths.astype(np.float32).tobytes())
    atlas.compare_func = "<="
    atlas.filter = (moderngl.LINEAR, moderngl.LINEAR)
    inputs = ctx.texture((len(points), 1), 4, np.asarray(points, np.float32).tobytes(),
                         dtype="f4")
    inputs.filter = (moderngl.NEAREST, moderngl.NEAREST)
    atlas.use(0)
    inputs.use(1)
    program["u_shadow_atlas"] = 0
    program["u_points"] = 1
    program["u_shadow_atlas_texel"] = 1.0 / SIZE
    values = draw_values(gl, program, (len(points), 1), 1).ravel()
    for thing in (inputs, atlas):
        thing.release()
    lib.release()
    return values


def test_filters_match_the_numpy_reference(gl):
    rng = np.random.default_rng(7)
    # blocks of random depth, so that each filter's footprint holds several edges
    depths = np.kron(rng.uniform(0.2, 0.8, (SIZE // 2, SIZE // 2)), np.ones((2, 2)))
    points = []
    for _ in range(200):  # kept a few texels from the map's edge: no clamping
        u, v = rng.uniform(4.0 / SIZE, 1.0 - 4.0 / SIZE, 2)
        points.append((u, v, rng.uniform(0.2, 0.8), float(rng.integers(0, 2))))
    got = glsl_filter(gl, depths, points)
    want = np.array([reference_filter(depths, p[:3], p[3] > 0.5) for p in points])
    # GPUs weigh a bilinear comparison with 8 bits of a texel's fraction (llvmpipe in float)
    np.testing.assert_allclose(got, want, atol=5e-3)
    pcf = np.array([p[3] < 0.5 for p in points])
    # a single bilinear comparison (too narrow a filter) would not pass
    single = np.array([bilinear_comparison(depths, *p[:3]) for p in points])
    assert np.abs(single - want)[pcf].max() > 0.1
    assert 0.0 < want[pcf].mean() < 1.0  # partly shadowed footprints
