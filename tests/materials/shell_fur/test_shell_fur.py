"""shell_fur (Silva et al., "Curling and Clumping Fur Represented by Texture Layers"): the
paper's algorithms and equations against independent numpy references, the GLSL through
transform feedback, and the behaviour of the rendered fur."""

from __future__ import annotations

from pathlib import Path

import moderngl
import numpy as np
import pytest
from locations import FIXTURES, ROOT

from deferred.gl.shaderlib import ShaderLibrary
from deferred.io.images import write_image
from deferred.materials.shell_fur import ShellFurMaterial
from deferred.materials.shell_fur.passes import layer_layout
from deferred.materials.shell_fur.state import ShellFurState, fur_state
from deferred.materials.techniques.strands import StrandForces, StrandSimulation, triangle_strands
from deferred.materials.techniques.wetness import (
    DRY_CENTRE,
    Droplet,
    blend_droplet,
    dry_mask,
    dry_out,
    load_wetness_mask,
    mask_image,
)
from deferred.scene.builtin_meshes import builtin_plane, builtin_sphere
from deferred.scene.loader import scene_from_dict
from deferred.scene.timeline import SceneEvaluator

HARNESS = FIXTURES / "shell_fur_harness"


# -- Algorithm 1 ------------------------------------------------------------------------------

def algorithm1_reference(mask: np.ndarray, c_drop, r_drop: float, rho_drop: float) -> np.ndarray:
    """Algorithm 1 as printed, texel by texel, over the texels within r_drop of c_drop."""
    out = mask.astype(np.float64).copy()
    size = mask.shape[0]
    c_drop = np.asarray(c_drop, np.float64)
    for i in range(size):
        for j in range(size):
            texel = np.array([(j + 0.5) / size, (i + 0.5) / size])
            if np.linalg.norm(texel - c_drop) > r_drop:
                continue
            c_mask, r_mask, rho_mask = out[i, j, :2].copy(), out[i, j, 2], out[i, j, 3]
            if np.linalg.norm(c_mask - c_drop) <= r_drop:
                if rho_mask != 0.0:
                    rho_total = min(max(rho_mask + rho_drop, 0.0), 1.0)
                    if rho_total != 0.0:
                        alpha = rho_drop / rho_total
                        c_mask = (1.0 - alpha) * c_mask + alpha * c_drop
                        r_mask = (1.0 - alpha) * r_mask + alpha * r_drop
                    rho_mask = rho_total
            else:
                c_mask, rho_mask, r_mask = c_drop.copy(), rho_drop, r_drop
            out[i, j] = (*c_mask, r_mask, rho_mask)
    return out


def assert_masks_match(mask: np.ndarray, reference: np.ndarray) -> None:
    """Same wetness everywhere; same clump (centre, radius) wherever the fur is wet (a texel of
    wetness 0 holds no clump, whatever centre it was given)."""
    np.testing.assert_allclose(mask[..., 3], reference[..., 3], atol=1e-6)
    wet = reference[..., 3] > 0.0
    np.testing.assert_allclose(mask[wet][:, :3], reference[wet][:, :3], atol=1e-6)


@pytest.mark.parametrize("case", ["no_overlap", "overlap_merges", "overlap_new_clump",
                                  "zero_wetness", "saturates"])
def test_algorithm1_against_the_printed_algorithm(case):
    size = 32
    droplets = {
        "no_overlap": [Droplet((0.25, 0.25), 0.1, 0.6), Droplet((0.75, 0.7), 0.12, 0.3)],
        # the second centre lies within its radius of the first's: one clump, moved
        "overlap_merges": [Droplet((0.4, 0.5), 0.2, 0.6), Droplet((0.5, 0.5), 0.15, 0.3)],
        # centres farther apart than the radius: the overlap becomes the second's clump
        "overlap_new_clump": [Droplet((0.3, 0.5), 0.2, 0.5), Droplet((0.6, 0.5), 0.2, 0.4)],
        "zero_wetness": [Droplet((0.5, 0.5), 0.2, 0.0), Droplet((0.3, 0.3), 0.15, 0.7),
                         Droplet((0.32, 0.3), 0.15, 0.0)],
        "saturates": [Droplet((0.5, 0.5), 0.2, 0.8), Droplet((0.52, 0.5), 0.2, 0.8)],
    }[case]
    mask = dry_mask(size)
    reference = dry_mask(size).astype(np.float64)
    for droplet in droplets:
        blend_droplet(mask, droplet)
        reference = algorithm1_reference(reference, droplet.centre, droplet.radius,
                                         droplet.wetness)
    assert_masks_match(mask, reference)
    wet = mask[..., 3] > 0
    if case == "zero_wetness":
        # a droplet of wetness 0 wets nothing and leaves a wet clump as it was
        only_second = dry_mask(size)
        blend_droplet(only_second, droplets[1])
        np.testing.assert_array_equal(mask, only_second)
    if case == "overlap_merges":
        # by hand: alpha = 0.3 / 0.9 of the way to the second centre, wetness 0.9
        both = wet & (np.abs(mask[..., 3] - 0.9) < 1e-6)
        assert both.sum() > 50
        np.testing.assert_allclose(mask[both][:, 0], 0.4 + (0.1 / 3.0), atol=1e-6)
        np.testing.assert_allclose(mask[both][:, 2], 0.2 + (0.15 - 0.2) / 3.0, atol=1e-6)
    if case == "overlap_new_clump":
        centres = {(round(float(c[0]), 5), round(float(c[1]), 5)) for c in mask[wet][:, :2]}
        assert centres == {(0.3, 0.5), (0.6, 0.5)}
    if case == "saturates":
        assert mask[..., 3].max() == pytest.approx(1.0)
    assert (mask[~wet][:, :2] == DRY_CENTRE).all()


def test_droplets_wrap_round_a_cylindrical_unwrap():
    from deferred.materials.techniques.wetness import uv_wrap

    assert uv_wrap(builtin_sphere(16, 8)) == (True, False)
    assert uv_wrap(builtin_plane(4)) == (False, False)
    # a droplet on the seam (u = 0.97) is the droplet at u = 0.47 turned half way round
    size = 32
    on_seam, inside = dry_mask(size), dry_mask(size)
    blend_droplet(on_seam, Droplet((0.97, 0.5), 0.1, 0.6), wrap=(True, False))
    blend_droplet(inside, Droplet((0.47, 0.5), 0.1, 0.6), wrap=(True, False))
    turned = np.roll(inside, size // 2, axis=1)
    wet = turned[..., 3] > 0
    assert (on_seam[..., 3] > 0).sum() == wet.sum() > 25
    np.testing.assert_allclose(on_seam[..., 3], turned[..., 3])
    np.testing.assert_allclose(on_seam[wet][:, 0], 0.97, atol=1e-6)
    # a second droplet across the seam joins the first's clump, its centre moving the short way
    blend_droplet(on_seam, Droplet((0.03, 0.5), 0.1, 0.6), wrap=(True, False))
    merged = np.abs(on_seam[..., 3] - 1.0) < 1e-6
    centres = on_seam[merged][:, 0]
    assert merged.sum() > 10 and np.all((centres > 0.99) | (centres < 0.01))
    # without wrapping the droplet stops at the border
    clipped = dry_mask(size)
    blend_droplet(clipped, Droplet((0.97, 0.5), 0.1, 0.6))
    assert (clipped[..., 3] > 0).sum() < wet.sum()


def test_a_zero_wetness_stamp_holds_no_clump():
    """The one departure from Algorithm 1 as printed: texels a droplet of wetness 0 covered stay
    dry (no clump), so a later droplet near that spot wets them; as printed they would keep the
    dry droplet's centre and refuse it (rho_mask = 0)."""
    mask = dry_mask(32)
    blend_droplet(mask, Droplet((0.5, 0.5), 0.2, 0.0))
    blend_droplet(mask, Droplet((0.55, 0.5), 0.2, 0.7))
    printed = np.zeros((32, 32, 4))
    printed = algorithm1_reference(printed, (0.5, 0.5), 0.2, 0.0)
    printed = algorithm1_reference(printed, (0.55, 0.5), 0.2, 0.7)
    covered = (mask[..., 3] > 0).sum()
    assert covered > 3 * (printed[..., 3] > 0).sum()
    fresh = dry_mask(32)
    blend_droplet(fresh, Droplet((0.55, 0.5), 0.2, 0.7))
    np.testing.assert_array_equal(mask, fresh)


def test_drying_resets_texels_to_dry_and_rewets():
    mask = dry_mask(16)
    blend_droplet(mask, Droplet((0.5, 0.5), 0.3, 0.5))
    dry_out(mask, 0.2)
    assert mask[..., 3].max() == pytest.approx(0.3)
    dry_out(mask, 0.5)
    np.testing.assert_array_equal(mask, dry_mask(16))
    # dried fur takes a new droplet at the same place (its old clump is gone)
    blend_droplet(mask, Droplet((0.5, 0.5), 0.3, 0.5))
    assert mask[..., 3].max() == pytest.approx(0.5)


@pytest.mark.parametrize("suffix", ["exr", "png"])
def test_wetness_mask_image_round_trip(tmp_path, suffix):
    mask = dry_mask(32)
    # wetness below the centre's coordinates: a PNG reader must not premultiply them
    blend_droplet(mask, Droplet((0.25, 0.75), 0.15, 0.5))
    path = tmp_path / f"mask.{suffix}"
    image = mask_image(mask)
    # the channels are data, not colour premultiplied by alpha
    write_image(path, image, attributes={"oiio:UnassociatedAlpha": 1})
    loaded = load_wetness_mask(path, 32)
    wet = mask[..., 3] > 0
    step = 1.0 / 255.0 if suffix == "png" else 1e-3  # 8-bit PNG
    np.testing.assert_allclose(loaded[..., 3], mask[..., 3], atol=step)
    np.testing.assert_allclose(loaded[wet][:, :3], mask[wet][:, :3], atol=step)
    # the clump stays in the top-left quarter of the image (v = 1 is the top row)
    image = mask_image(mask)
    rows, cols = np.nonzero(image[..., 3] > 0)
    assert rows.mean() < 16 and cols.mean() < 16


# -- strands: Eq. 2 and 3 ----------------------------------------------------------------------

def one_strand(normal=(0.0, 1.0, 0.0), length=0.2) -> StrandSimulation:
    return StrandSimulation(np.zeros((1, 3)), np.array([normal], float), np.array([length]))


def settle(sim: StrandSimulation, forces: StrandForces, seconds=20.0, dt=1.0 / 240.0):
    for _ in range(int(seconds / dt)):
        sim.step(dt, forces)


def test_strand_under_gravity_settles_where_the_spring_balances_the_weight():
    k, m, g = 3.0, 0.02, 9.81
    sim = one_strand()
    settle(sim, StrandForces(k, m, 0.2, np.array([0.0, -g, 0.0]), np.zeros(3)))
    # inside the region: the spring alone holds the weight, k (p - p0) = m g
    np.testing.assert_allclose(sim.tips[0], [0.0, 0.2 - m * g / k, 0.0], atol=1e-6)
    np.testing.assert_allclose(sim.velocities[0], 0.0, atol=1e-6)


def test_strand_pulled_sideways_rests_on_the_length_constraint_balanced():
    k, m = 3.0, 0.02
    gravity = np.array([9.81, 0.0, 0.0])  # along the surface
    sim = one_strand()
    settle(sim, StrandForces(k, m, 0.2, gravity, np.zeros(3)))
    r = sim.tips[0] - sim.roots[0]
    assert np.linalg.norm(r) == pytest.approx(0.2, abs=1e-9)  # on the sphere of Eq. 3
    force = -k * (sim.tips[0] - sim.rest[0]) + m * gravity
    radial = r / np.linalg.norm(r)
    tangential = force - (force @ radial) * radial
    assert np.linalg.norm(tangential) < 1e-6 * np.linalg.norm(force)  # no force along it
    assert force @ radial > 0.0  # it pushes outward: the constraint holds it
    assert sim.tips[0, 0] > 0.0


def test_strands_never_leave_the_region_of_eq3_in_strong_wind():
    mesh = builtin_sphere(24, 12)
    sim = StrandSimulation(*triangle_strands(mesh, np.eye(4), 0.15))
    rng = np.random.default_rng(3)
    dt = 1.0 / 240.0
    for _ in range(600):
        wind = rng.normal(0.0, 50.0, (len(sim.roots), 3))  # violent, different per strand
        sim.step(dt, StrandForces(2.0, 0.01, 0.0, np.array([0.0, -9.81, 0.0]), wind))
        offset = sim.tips - sim.roots
        assert (np.linalg.norm(offset, axis=1) <= sim.lengths * (1 + 1e-9) + 1e-12).all()
        assert (np.einsum("ij,ij->i", offset, sim.normals) >= -1e-12).all()
    # the wind did move them
    assert np.linalg.norm(sim.tips - sim.rest, axis=1).mean() > 0.05


def test_strands_are_stable_for_any_stiffness_and_damping():
    sim = one_strand()
    forces = StrandForces(1e5, 0.01, 1e3, np.array([0.0, -9.81, 0.0]), np.zeros(3))
    settle(sim, forces, seconds=1.0)
    assert np.isfinite(sim.tips).all()
    np.testing.assert_allclose(sim.tips[0], [0.0, 0.2 - 0.01 * 9.81 / 1e5, 0.0], atol=1e-6)
    # heavy damping slows the strand, it does not shake it
    sim = one_strand()
    path = []
    for _ in range(240):
        sim.step(1.0 / 240.0, StrandForces(2.0, 0.01, 5.0, np.zeros(3), np.array([0.3, 0, 0])))
        path.append(sim.tips[0, 0])
    assert (np.diff(path) >= -1e-12).all()


def test_triangle_strands_point_outward_and_scale_to_world():
    mesh = builtin_sphere(16, 8)
    model = np.diag([2.0, 2.0, 2.0, 1.0])
    roots, normals, lengths = triangle_strands(mesh, model, 0.1)
    live = lengths > 0
    assert (np.einsum("ij,ij->i", roots[live], normals[live]) > 0).all()
    np.testing.assert_allclose(lengths[live], 0.2, rtol=1e-6)


def test_curl_frames_are_orthonormal_and_shared_across_seams():
    from deferred.materials.techniques.strands import curl_frames
    from deferred.materials.techniques.topology import weld

    mesh = builtin_sphere(16, 8)  # its u seam splits a column of vertices
    welded = weld(mesh.positions)
    u, v = curl_frames(mesh, welded)
    n = mesh.normals.astype(np.float64)
    np.testing.assert_allclose(np.linalg.norm(u, axis=1), 1.0, atol=1e-9)
    np.testing.assert_allclose(np.einsum("ij,ij->i", u, v), 0.0, atol=1e-9)
    np.testing.assert_allclose(np.abs(np.einsum("ij,ij->i", u, n)), 0.0, atol=1e-6)
    split = [np.flatnonzero(welded == g) for g in np.unique(welded)]
    seams = [group for group in split if len(group) > 1]
    assert seams
    for group in seams:
        assert np.abs(u[group] - u[group[0]]).max() < 1e-9
        assert np.abs(v[group] - v[group[0]]).max() < 1e-9


def test_droplet_k_is_the_same_whatever_the_batch():
    from deferred.materials.techniques.wetness import random_droplets

    mesh = builtin_sphere(16, 8)
    one_go = random_droplets(mesh, np.eye(4), 12, 0.1, 0.5, seed=3)
    batched = (random_droplets(mesh, np.eye(4), 5, 0.1, 0.5, seed=3)
               + random_droplets(mesh, np.eye(4), 7, 0.1, 0.5, seed=3, start=5))
    assert one_go == batched
    assert random_droplets(mesh, np.eye(4), 12, 0.1, 0.5, seed=4) != one_go


# -- GLSL through transform feedback -------------------------------------------------------------

@pytest.fixture
def shaders(gl):
    lib = ShaderLibrary(gl.ctx, 330)
    lib.add_root(HARNESS)
    yield lib
    lib.release()


def float_texture(ctx, array: np.ndarray, repeat=True) -> moderngl.Texture:
    height, width = array.shape[:2]
    texture = ctx.texture((width, height), 4, np.ascontiguousarray(array, np.float32).tobytes(),
                          dtype="f4")
    texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
    texture.repeat_x = texture.repeat_y = repeat
    return texture


def transform(gl, program, buffers, count: int, floats: int) -> np.ndarray:
    """Run ``program``'s vertex shader over ``count`` vertices; its varyings, interleaved."""
    ctx = gl.ctx
    gl.park()  # a draw needs a framebuffer bound, even with rasterization off
    out = ctx.buffer(reserve=count * floats * 4)
    vao = ctx.vertex_array(program, buffers)
    vao.transform(out, moderngl.POINTS, vertices=count)
    result = np.frombuffer(out.read(), np.float32).reshape(count, floats).astype(np.float64)
    vao.release()
    out.release()
    return result


def eq5_reference(h, mask, pixel, w, layers, strength):
    """Eq. 5 with k = ln N (the clump.glsl note) and h within the layers' [1/N, 1]."""
    h = np.clip(h, 1.0 / layers, 1.0)
    profile = (1.0 - w) * h + w * (1.0 + np.log(h) / np.log(layers))
    return profile, (profile * mask[:, 3] * strength)[:, None] * (pixel - mask[:, :2])


def test_eq5_and_algorithm2_in_glsl_against_numpy(gl, shaders):
    ctx = gl.ctx
    source = shaders.assemble("clump.vert").text
    program = ctx.program(vertex_shader=source,
                          varyings=["out_profile", "out_d", "out_fur_d", "out_kept"])
    rng = np.random.default_rng(5)
    n = 64
    h = np.concatenate([[0.0, 1.0 / 16.0, 0.5, 1.0], rng.uniform(0.0, 1.0, n - 4)])
    mask = np.column_stack([rng.uniform(0.3, 0.7, (n, 2)), rng.uniform(0.05, 0.2, n),
                            rng.uniform(0.0, 1.0, n)])
    mask[:8, 3] = 0.0  # dry texels
    pixel = mask[:, :2] + rng.uniform(-0.2, 0.2, (n, 2))
    # hand-made Algorithm 2 cases against the texture below, at the tip (profile 1):
    # 60: inside the clump near its centre (kept); 61: on the texel row of another clump whose
    # stored centre is farther than its radius (ignored: a different clump); 62: near the rim,
    # displaced onto dry fur (ignored); 63: dry fur (kept, not displaced)
    h[60:] = 1.0
    pixel[60:] = [(0.52, 0.5), (0.5, 8.5 / 64.0), (0.5, 0.5 + 0.2), (0.05, 0.95)]

    # a wetness mask with one clump: centre (0.5, 0.5), radius 0.25, wetness 0.8
    size = 64
    image = dry_mask(size)
    blend_droplet(image, Droplet((0.5, 0.5), 0.25, 0.8))
    # and a texel row whose stored centre lies farther than its radius (another clump's)
    image[8, :, :] = (0.5, 0.9, 0.05, 0.5)
    texture = float_texture(ctx, image)
    texture.use(0)
    w, layers, strength = 0.7, 16.0, 1.5
    for name, value in (("u_clump_shape", w), ("u_layers", layers),
                        ("u_clump_strength", strength), ("u_wetness_mask", 0)):
        program[name].value = value
    data = np.column_stack([h, mask, pixel]).astype(np.float32)
    vbo = ctx.buffer(data.tobytes())
    out = transform(gl, program, [(vbo, "1f 4f 2f", "in_h", "in_mask", "in_pixel")], n, 6)

    profile, d = eq5_reference(h, mask, pixel, w, layers, strength)
    np.testing.assert_allclose(out[:, 0], profile, atol=1e-5)
    np.testing.assert_allclose(out[:, 1:3], d, atol=1e-5)
    # the profile runs from (1 - w)/N at the first layer to 1 at the tip, for any w
    assert out[1, 0] == pytest.approx((1.0 - w) / layers, abs=1e-6)
    assert out[3, 0] == pytest.approx(1.0, abs=1e-6)
    np.testing.assert_allclose(out[:8, 1:3], 0.0)  # dry: no displacement

    # Algorithm 2 against the mask texture, by hand
    def texel(uv):
        j = int(np.floor(uv[0] % 1.0 * size))
        i = int(np.floor(uv[1] % 1.0 * size))
        return image[i, j]

    kept = out[:, 5] > 0.5
    # by hand: at the tip d = rho s (c_pixel - c) = 0.8 * 1.5 * (0.02, 0)
    np.testing.assert_allclose(out[60, 3:5], (0.024, 0.0), atol=1e-6)
    assert kept[60] and not kept[61] and not kept[62] and kept[63]
    np.testing.assert_allclose(out[63, 3:5], 0.0)
    def wetness(uv):  # the mask's alpha filtered bilinearly, wrapping (wet.glsl)
        x, y = uv[0] * size - 0.5, uv[1] * size - 0.5
        j, i = int(np.floor(x)), int(np.floor(y))
        fx, fy = x - j, y - i
        a = image[:, :, 3]
        i0, i1, j0, j1 = i % size, (i + 1) % size, j % size, (j + 1) % size
        return ((1 - fx) * (1 - fy) * a[i0, j0] + fx * (1 - fy) * a[i0, j1]
                + (1 - fx) * fy * a[i1, j0] + fx * fy * a[i1, j1])

    def wetness_near(uv):  # wet.glsl: the mean of five, four of them 4 texels away diagonally
        step = 4.0 / size
        return np.mean([wetness(uv + offset) for offset in
                        ((0.0, 0.0), (step, step), (-step, -step), (step, -step), (-step, step))])

    for k in range(n):
        m = texel(pixel[k])
        if m[3] == 0.0:
            # dry fur stays where it is, its top cut down beside wet fur (a sloping border)
            assert np.allclose(out[k, 3:5], 0.0), k
            assert kept[k] == (h[k] <= 1.0 - 0.6 * wetness_near(pixel[k]) + 1e-6), k
            continue
        want_d = eq5_reference(h[k:k + 1], m[None], pixel[k:k + 1], w, layers, strength)[1][0]
        np.testing.assert_allclose(out[k, 3:5], want_d, atol=1e-5)
        there = texel(pixel[k] + want_d)
        expect = (np.linalg.norm(pixel[k] - m[:2]) <= m[2] and there[3] != 0.0
                  and np.linalg.norm(there[:2] - m[:2]) <= 0.5 * m[2])
        assert kept[k] == expect, k
    vbo.release()
    texture.release()
    program.release()


def fur_vertex_program(ctx, shaders):
    source = shaders.assemble("materials/shell_fur/fur.vert").text
    return ctx.program(vertex_shader=source, varyings=["v_position", "v_strand_tangent"])


def tangent_frames(mesh):
    """An orthonormal (u, v) per vertex in its tangent plane (numpy, for the strand texture)."""
    n = mesh.normals.astype(np.float64)
    t = mesh.tangents.astype(np.float64)
    u = t - np.einsum("ij,ij->i", t, n)[:, None] * n
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return u, np.cross(n, u)


def layer_positions(gl, shaders, mesh, h, wetness, curl_radius, curl_frequency, fur_length,
                    deflection=None, frames=None):
    """fur.vert's layer positions and strand tangents (object space: identity transforms)."""
    from deferred.gl.meshes import GpuMesh

    ctx = gl.ctx
    program = fur_vertex_program(ctx, shaders)
    for name in ("u_view", "u_model"):  # identity transforms
        program[name].write(np.eye(4, dtype=np.float32).tobytes())
    for name, value in (("u_shell_depth", h), ("u_fur_length", fur_length),
                        ("u_curl_radius", curl_radius), ("u_curl_frequency", curl_frequency)):
        program[name].value = value
    mask = float_texture(ctx, np.full((4, 4, 4), (0.5, 0.5, 0.5, wetness), np.float32))
    count = mesh.vertex_count
    strand = np.zeros((1, 1024 * (3 * count // 1024 + 1), 4), np.float32)
    u, v = frames if frames is not None else tangent_frames(mesh)
    if deflection is not None:
        strand[0, 0:3 * count:3, :3] = deflection
    strand[0, 1:3 * count:3, :3] = u
    strand[0, 2:3 * count:3, :3] = v
    strand = strand.reshape(-1, 1024, 4)
    strand_texture = float_texture(ctx, strand, repeat=False)
    mask.use(0)
    strand_texture.use(1)
    program["u_wetness_mask"].value = 0
    program["u_strand_tips"].value = 1
    gpu = GpuMesh(ctx, mesh)
    out = transform(gl, program, [gpu.vertex_buffer(program)], count, 6)
    gpu.release()
    mask.release()
    strand_texture.release()
    program.release()
    return out[:, :3], out[:, 3:]


@pytest.mark.parametrize("wetness", [0.0, 0.4, 1.0])
@pytest.mark.parametrize("h", [0.0, 0.3, 1.0])
def test_curl_offsets_of_layer_h_match_eq4(gl, shaders, h, wetness):
    mesh = builtin_sphere(12, 6)
    K, w, L = 0.05, 9.0, 0.2
    positions, tangents = layer_positions(gl, shaders, mesh, h, wetness, K, w, L)
    n = mesh.normals.astype(np.float64)
    u, v = tangent_frames(mesh)
    alpha = (1.0 - wetness) * K * h
    curl = alpha * (np.cos(w * h) * u + np.sin(w * h) * v)  # Eq. 4
    straight = h * L * n  # beta(h) of an unbent strand: the layers evenly along the normal
    np.testing.assert_allclose(positions - mesh.positions, straight + curl, atol=2e-5)
    if wetness == 1.0:  # wet fur loses its curl
        np.testing.assert_allclose(positions - mesh.positions, straight, atol=2e-5)
    # the strand tangent is d(v_offset)/dh
    k = (1.0 - wetness) * K
    derivative = L * n + k * ((np.cos(w * h) - w * h * np.sin(w * h)) * u
                              + (np.sin(w * h) + w * h * np.cos(w * h)) * v)
    derivative /= np.linalg.norm(derivative, axis=1, keepdims=True)
    np.testing.assert_allclose(tangents, derivative, atol=1e-4)


@pytest.mark.parametrize("deflection", [(0.12, -0.05, 0.0),   # inside Eq. 3's region
                                        (0.5, 0.2, 0.1),      # too long: pulled back to L
                                        (0.1, -0.6, 0.0)])    # below the surface: lifted
def test_layers_follow_the_bezier_of_the_simulated_strand(gl, shaders, deflection):
    mesh = builtin_plane(2, 2.0)
    L = 0.3
    deflection = np.tile(deflection, (mesh.vertex_count, 1))
    root = mesh.positions.astype(np.float64)
    n = mesh.normals.astype(np.float64)
    rest = root + L * n
    # Eq. 3: above the surface, within L of the root
    offset = rest + deflection - root
    offset -= np.minimum(np.einsum("ij,ij->i", offset, n), 0.0)[:, None] * n
    tip = root + offset * np.minimum(1.0, L / np.linalg.norm(offset, axis=1))[:, None]
    assert (np.linalg.norm(tip - root, axis=1) <= L + 1e-9).all()
    control = (root + rest) / 2.0  # the rest strand's midpoint (strand.glsl)
    for h in (0.0, 0.25, 0.6, 1.0):
        positions, tangents = layer_positions(gl, shaders, mesh, h, 0.0, 0.0, 0.0, L,
                                              deflection)
        bezier = (1 - h) ** 2 * root + 2 * (1 - h) * h * control + h * h * tip
        np.testing.assert_allclose(positions, bezier, atol=2e-5)
        derivative = 2 * (1 - h) * (control - root) + 2 * h * (tip - control)
        derivative /= np.linalg.norm(derivative, axis=1, keepdims=True)
        np.testing.assert_allclose(tangents, derivative, atol=1e-4)
    # unbent, the layers sit evenly along the normal
    positions, _ = layer_positions(gl, shaders, mesh, 0.4, 0.0, 0.0, 0.0, L)
    np.testing.assert_allclose(positions, root + 0.4 * L * n, atol=2e-5)


# -- the layers ------------------------------------------------------------------------------

def test_layer_layout_is_silvas_spacing():
    layout = layer_layout(4.0)
    assert layout == [(0.0, 1.0), (0.25, 1.0), (0.5, 1.0), (0.75, 1.0), (1.0, 1.0)]
    # a fractional count: h = (1 + n) / N, the last layer kept at the tip and faded
    layout = layer_layout(3.5)
    assert [h for h, _ in layout] == pytest.approx([0.0, 1 / 3.5, 2 / 3.5, 3 / 3.5, 1.0])
    assert layout[-1][1] == pytest.approx(0.5)
    assert layer_layout(4.0, debug="wetness")[1:] == [None] * 4


# -- rendered behaviour -------------------------------------------------------------------------

def clump_scene(params: dict, size=(128, 128)) -> dict:
    """A plane seen from straight above (almost orthographic), unlit: only what a debug view
    draws shows."""
    return {
        "size": list(size), "background": [0.0, 0.0, 0.0], "tonemap": "none",
        "camera": {"position": [0.0, 20.0, 0.0], "target": [0.0, 0.0, 0.0],
                   "up": [0.0, 0.0, -1.0], "fov": 5.8},
        "object": [{"mesh": "builtin:plane", "material": "shell_fur",
                    "params": {"fur_length": 0.2, "shells": 16, "lod_error": 0.01,
                               "fins": False, "gravity": [0.0, 0.0, 0.0], "density": 100,
                               "pattern": "coarse", **params}}],
    }


@pytest.mark.slow
@pytest.mark.parametrize("mapping", ["triplanar", "uv"])
def test_wet_clump_gathers_fur_into_its_centre_and_leaves_dry_fur_alone(render, tmp_path,
                                                                         mapping):
    mask = dry_mask(128)
    blend_droplet(mask, Droplet((0.5, 0.5), 0.2, 1.0))
    path = tmp_path / "clump.exr"
    write_image(path, mask_image(mask))
    top = {"debug": "single_shell", "shell_range": [0.6, 0.7],  # a layer at h 0.625, opaque
           "fur_mapping": mapping}
    wet, _ = render(scene_from_dict(clump_scene({**top, "wetness_mask": str(path)}), "wet"))
    dry, _ = render(scene_from_dict(clump_scene(top), "dry"))
    covered_wet = wet.image[..., 0] > 128
    covered_dry = dry.image[..., 0] > 128
    # the plane (2 units) fills the 128-pixel frame: the clump is centred, 0.2 * 128 px
    ys, xs = np.mgrid[0:128, 0:128] + 0.5
    radius = np.hypot(xs - 64, ys - 64) / (0.2 * 128)
    inner, ring = radius < 0.5, (radius > 0.55) & (radius < 0.95)
    assert covered_dry[inner].mean() > 0.2  # the dry tips cover some of the plane
    assert covered_wet[inner].mean() > 2.0 * covered_wet[ring].mean()
    assert covered_wet[ring].mean() < 0.5 * covered_dry[ring].mean()
    # outside the clump nothing changed
    outside = radius > 1.05
    assert (covered_wet[outside] == covered_dry[outside]).mean() > 0.999


@pytest.mark.slow
def test_uv_mapping_keeps_the_world_density_on_an_even_unwrap(render):
    """On a plane (UV scale the same everywhere) strands over the UVs cover the layer as much as
    triplanar strands in world units: the density converts through the mean UV scale."""
    covered = {}
    for mapping in ("triplanar", "uv"):
        scene = clump_scene({"debug": "single_shell", "shell_range": [0.3, 0.4],
                             "fur_mapping": mapping, "density": 400}, size=(192, 192))
        result, _ = render(scene_from_dict(scene, mapping))
        covered[mapping] = (result.image[..., 0] > 128).mean()
    assert 0.1 < covered["triplanar"] < 0.9
    assert covered["uv"] == pytest.approx(covered["triplanar"], rel=0.15)


@pytest.mark.slow
def test_forward_and_deferred_agree_on_straight_fur(render):
    scene = {
        "size": [160, 120], "background": [0.02, 0.02, 0.03],
        "camera": {"position": [0.0, 1.2, 2.6], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"mesh": "builtin:sphere", "material": "shell_fur",
                    "params": {"fur_length": 0.12, "shells": 12, "fins": False}}],
        "light": [{"type": "directional", "direction": [-0.4, -1.0, -0.5], "intensity": 1.5},
                  {"type": "ambient", "color": [0.3, 0.3, 0.35], "intensity": 0.5}],
    }
    from conftest import psnr

    deferred, _ = render(scene_from_dict(scene, "s"), "deferred")
    forward, _ = render(scene_from_dict(scene, "s"), "forward")
    a = deferred.image[..., :3] / 255.0
    b = forward.image[..., :3] / 255.0
    assert psnr(a, b) > 25.0  # measured 27.8 dB: one tangent per strand in deferred
    covered = (a.sum(-1) > 0.1)
    assert covered.mean() > 0.3


def evaluated(scene, time: float = 0.0):
    """The scene's first object as a frame at ``time`` has it (its state: what a material
    reads of it)."""
    return SceneEvaluator(scene).evaluate(time).objects[0]


def state_at(gl, scene_dict, times):
    scene = scene_from_dict(scene_dict, "anim")
    state = ShellFurState(gl.ctx, evaluated(scene))
    out = []
    for t in times:
        state.advance(t)
        out.append((state.mask.copy(), state.strands.deflections().copy()))
    state.release()
    return out


def anim_scene(params: dict, events=()):
    return {"size": [64, 64],
            "object": [{"name": "fur", "mesh": "builtin:plane", "material": "shell_fur",
                        "params": {"fur_length": 0.2, "mask_size": 64, "seed": 4, **params}}],
            "event": [{"time": t, "object": "fur", "params": p} for t, p in events]}


def test_droplets_fall_on_the_timeline_and_dry_at_dry_rate(gl):
    scene = anim_scene({"droplet_wetness": 0.8, "dry_rate": 0.5, "droplet_radius": 0.3},
                       [(1.0, {"droplets": 10})])
    states = state_at(gl, scene, [0.5, 1.0, 1.5, 2.0, 3.1])
    wetness = [mask[..., 3] for mask, _ in states]
    assert wetness[0].max() == 0.0  # before the rain
    assert wetness[1].max() > 0.5
    assert wetness[2].max() == pytest.approx(wetness[1].max() - 0.25, abs=1e-5)
    assert wetness[3].max() < wetness[2].max()
    assert wetness[4].max() == 0.0  # dried: at most 1 (overlaps), gone after 2 s at 0.5 / s


@pytest.mark.slow
def test_wind_from_a_time_bends_the_strands_and_time_is_deterministic(gl):
    scene = anim_scene({"gravity": [0.0, 0.0, 0.0], "damping": 0.2},
                       [(1.0, {"wind": [0.05, 0.0, 0.0]})])
    before, after, later = state_at(gl, scene, [0.9, 2.0, 3.0])
    assert np.abs(before[1][:, 0]).max() < 1e-9  # no force yet: strands at rest
    shift = after[1][:, 0] - before[1][:, 0]
    assert shift.min() > 0.005  # every strand leans with the wind (+x)
    # the same time again, after a later one, gives the same state
    again = state_at(gl, scene, [3.0, 2.0])[1]
    np.testing.assert_array_equal(again[1], after[1])
    np.testing.assert_array_equal(again[0], after[0])


@pytest.mark.slow
def test_the_state_at_a_time_does_not_depend_on_the_frames_before(gl):
    scene = anim_scene({"wind": [0.04, 0.0, 0.0], "gust": 0.8, "droplets": 5,
                        "dry_rate": 0.3, "droplet_radius": 0.3},
                       [(0.37, {"droplets": 12}), (0.61, {"wind": [0.0, 0.0, -0.04]})])
    frames = state_at(gl, scene, [k / 25.0 for k in range(26)])[-1]  # 25 fps up to 1 s
    direct = state_at(gl, scene, [1.0])[0]
    np.testing.assert_allclose(frames[1], direct[1], atol=1e-12)
    np.testing.assert_allclose(frames[0], direct[0], atol=1e-6)
    # frames closer than a step still move the strands (a step is taken when one is due)
    fine = state_at(gl, scene, [k / 1000.0 for k in range(0, 1001, 1)])[-1]
    np.testing.assert_allclose(fine[1], direct[1], atol=1e-12)


def test_a_timeline_may_not_change_what_the_simulation_reads_once(tmp_path, capsys):
    scene = write_scene(tmp_path / "s.toml", "fur_length = 0.1")
    scene.write_text(scene.read_text().replace("[[object]]", "[[object]]\nname = \"fur\"")
                     + '\n[[event]]\ntime = 1.0\nobject = "fur"\nparams = { fur_length = 0.2 }\n')
    code, output = cli(capsys, "render", str(scene), "-o", str(tmp_path / "out.png"))
    assert code == 2
    assert "event[0].params.fur_length: shell_fur reads fur_length once, at t = 0" in output


def test_deflections_come_back_to_object_space(gl):
    """A plane turned on its side (object +y = world +z) under world gravity: the strands sag
    along world -y, which is object +z... rotated back by the inverse transform."""
    scene = {"size": [32, 32],
             "object": [{"name": "fur", "mesh": "builtin:plane?divisions=4",
                         "material": "shell_fur", "rotation": [90.0, 0.0, 0.0], "scale": 2.0,
                         "params": {"fur_length": 0.2, "damping": 0.5}}]}
    loaded = scene_from_dict(scene, "s")
    obj = loaded.objects[0]
    state = ShellFurState(gl.ctx, evaluated(loaded))
    state.advance(0.0)  # settled under gravity
    deflection = state.vertex_deflections()
    linear = obj.model[:3, :3]
    world = deflection @ linear.T
    down = world / np.linalg.norm(world, axis=1, keepdims=True)
    # in the world the tips hang down (and a little toward the surface, held at length L)
    assert (down[:, 1] < -0.9).all()
    # object units: half the world length (scale 2)
    sag = np.linalg.norm(world, axis=1)
    np.testing.assert_allclose(np.linalg.norm(deflection, axis=1), sag / 2.0, rtol=1e-6)
    state.release()


@pytest.mark.slow
def test_render_at_the_same_time_twice_is_identical(render):
    scene = anim_scene({"droplets": 8, "wind": [0.03, 0.0, 0.0], "gust": 0.5, "shells": 6,
                        "dry_rate": 0.1})
    scene["camera"] = {"position": [0.0, 1.5, 1.5], "target": [0.0, 0.0, 0.0]}
    scene["light"] = [{"type": "ambient", "intensity": 1.0}]
    first, _ = render(scene_from_dict(scene, "s"), time=1.3)
    second, renderer = render(scene_from_dict(scene, "s"), time=2.0)
    repeat = renderer.render(time=1.3)
    np.testing.assert_array_equal(first.image, repeat.image)
    assert not np.array_equal(first.image, second.image)


def shared_material_scene(event: dict | None = None):
    """Two spheres drawn with one shell_fur Material instance, ``a`` on the left and ``b``
    turned on its side on the right; ``event``: params ``a`` takes from t = 0.25 s."""
    scene = scene_from_dict({
        "size": [96, 48],
        "camera": {"position": [0.0, 0.6, 3.0], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "light": [{"type": "directional", "direction": [-0.4, -1.0, -0.5]},
                  {"type": "ambient", "intensity": 0.4}]}, "shared")
    material = ShellFurMaterial.from_dict({"fur_length": 0.25, "shells": 6, "damping": 0.2,
                                           "settle": 0.2, "mask_size": 64})
    a = scene.add("builtin:sphere", material, position=(-0.9, 0.0, 0.0), scale=0.5, label="a")
    b = scene.add("builtin:sphere", material, position=(0.9, 0.0, 0.0), scale=0.5,
                  rotation=(90.0, 0.0, 0.0), label="b")
    assert a.material is b.material
    if event is not None:
        scene.add_event(a, 0.25, event)
    return scene, a, b


@pytest.mark.slow
@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_an_event_on_one_object_leaves_another_sharing_its_material_alone(render, pipeline):
    """Each object's simulation is its own (keyed by the object, not by its material): wind
    and rain on ``a`` change ``a`` alone, and ``b``, at another transform, has strands of its
    own."""
    plain, plain_a, plain_b = shared_material_scene()
    windy, windy_a, windy_b = shared_material_scene({"wind": [0.3, 0.0, 0.0], "droplets": 40,
                                                     "droplet_radius": 0.2})
    before, plain_renderer = render(plain, pipeline, time=0.5)
    after, windy_renderer = render(windy, pipeline, time=0.5)
    # a changed, b's half of the image did not
    assert not np.array_equal(before.hdr[:, :48], after.hdr[:, :48])
    np.testing.assert_array_equal(before.hdr[:, 48:], after.hdr[:, 48:])

    def states(renderer, a, b):
        return (fur_state(renderer.last_frame, a), fur_state(renderer.last_frame, b))

    (plain_a, plain_b), (windy_a, windy_b) = states(plain_renderer, plain_a, plain_b), \
        states(windy_renderer, windy_a, windy_b)
    assert windy_a.mask[..., 3].max() > 0.0 and windy_b.mask[..., 3].max() == 0.0
    np.testing.assert_array_equal(windy_b.strands.tips, plain_b.strands.tips)
    np.testing.assert_array_equal(windy_b.mask, plain_b.mask)
    assert np.abs(windy_a.strands.tips - plain_a.strands.tips).max() > 1e-3
    # the same mesh at two transforms: two sets of strands, sagging apart in object space
    assert plain_a is not plain_b
    assert np.abs(plain_a.strands.roots - plain_b.strands.roots).max() > 0.5
    assert np.abs(plain_a.vertex_deflections() - plain_b.vertex_deflections()).max() > 1e-3


@pytest.mark.slow
def test_an_event_changing_a_uniform_leaves_another_object_sharing_the_material_alone(render):
    plain, _, _ = shared_material_scene()
    tinted, _, _ = shared_material_scene({"color": [0.1, 0.6, 0.1]})
    before, _ = render(plain, time=0.5)
    after, _ = render(tinted, time=0.5)
    np.testing.assert_array_equal(before.hdr[:, 48:], after.hdr[:, 48:])


def test_the_strands_step_before_any_pass_draws_and_go_with_the_renderer(render):
    scene, a, b = shared_material_scene({"wind": [0.3, 0.0, 0.0]})
    steps = []

    def before_pass(render_pass, frame):
        if not steps:  # the first pass of the frame: every pass is prepared by now
            steps.extend(fur_state(frame, obj).step for obj in (a, b))

    _, renderer = render(scene, time=0.5, before_pass=before_pass)
    assert steps == [120, 120]  # 0.5 s of 1/240 s steps
    states = [fur_state(renderer.last_frame, obj) for obj in (a, b)]
    textures = [t for state in states for t in (state.mask_texture, state.tips_texture)]
    renderer.release()
    assert all(type(t.mglo).__name__ == "InvalidObject" for t in textures)


# -- bad input ---------------------------------------------------------------------------------

def cli(capsys, *args) -> tuple[int, str]:
    from deferred.cli import main

    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out + captured.err


def write_scene(path: Path, params: str) -> Path:
    path.write_text(f"""size = [32, 32]
[[object]]
mesh = "builtin:plane"
material = "shell_fur"
[object.params]
{params}
""")
    return path


@pytest.mark.parametrize("params, message", [
    ('wetness_mask = "missing.png"',
     "object[0].params.wetness_mask: wetness mask image not found"),
    ('color_texture = "nope.png"', "object[0].params.color_texture: color texture image not found"),
    ('wetness_mask = ""', "object[0].params.wetness_mask: is empty; name the wetness mask image"),
    ('wetness_mask = "."', "object[0].params.wetness_mask: wetness mask image is a folder"),
    ('color_texture = "/dev/zero"',
     "object[0].params.color_texture: color texture image is not a regular file (a device or "
     "pipe)"),
    ('color_pattern = "tartan"', "object[0].params.color_pattern"),
    ("curl_radius = -1.0", "object[0].params.curl_radius"),
    ("droplets = 1.5", "object[0].params.droplets"),
    ("clump_shape = 2.0", "object[0].params.clump_shape"),
])
def test_bad_parameters_are_one_line_errors(tmp_path, capsys, params, message):
    scene = write_scene(tmp_path / "s.toml", params)
    out = tmp_path / "out.png"
    code, output = cli(capsys, "render", str(scene), "-o", str(out))
    assert code == 2, output
    assert message in output
    assert len(output.strip().splitlines()) == 1 and "Traceback" not in output
    assert not out.exists()


def test_a_wetness_mask_needs_four_channels(tmp_path, capsys):
    write_image(tmp_path / "rgb.png", np.zeros((8, 8, 3), np.float32))
    scene = write_scene(tmp_path / "s.toml", 'wetness_mask = "rgb.png"')
    code, output = cli(capsys, "render", str(scene), "-o", str(tmp_path / "out.png"))
    assert code == 2
    assert "wetness_mask: wetness mask rgb.png needs 4 channels" in output


# -- the fur's light per pixel (techniques/fur_light.py) -----------------------------------------

AROUND = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, 1), (1, -1), (-1, -1)]  # (x, y)


def fur_light_reference(irradiance, depth, holds):
    """Per pixel: (its irradiance, 1) where it holds the fur, else (the first neighbour's
    holding it, in base_irradiance's order, -1), else zeros; and the least and greatest depth of
    the fur over the 3x3 pixels (zeros where none holds it)."""
    height, width = holds.shape
    light = np.zeros((height, width, 4))
    depths = np.zeros((height, width, 2))
    light[holds, :3] = irradiance[holds]
    light[holds, 3] = 1.0
    for y in range(height):
        for x in range(width):
            seen = [depth[y + dy, x + dx] for dx, dy in [(0, 0), *AROUND]
                    if 0 <= x + dx < width and 0 <= y + dy < height and holds[y + dy, x + dx]]
            if seen:
                depths[y, x] = min(seen), max(seen)
            if holds[y, x]:
                continue
            for dx, dy in AROUND:
                qx, qy = x + dx, y + dy
                if 0 <= qx < width and 0 <= qy < height and holds[qy, qx]:
                    light[y, x, :3] = irradiance[qy, qx]
                    light[y, x, 3] = -1.0
                    break
    return light, depths


@pytest.mark.slow
def test_the_fur_light_is_each_pixels_own_or_its_first_neighbours(render):
    """The once-per-frame gather the layers read instead of searching the G-buffer themselves,
    against numpy on the frame's own G-buffer, with another surface in front of the fur; and the
    layers beyond the skin's silhouette, lit only through a neighbour, are drawn."""
    scene = scene_from_dict({
        "size": [72, 56], "background": [0.0, 0.0, 0.0],
        "camera": {"position": [0.0, 0.0, 3.2], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"name": "fur", "mesh": "builtin:sphere", "material": "shell_fur",
                    "params": {"fur_length": 0.15, "shells": 8, "fins": False}},
                   {"name": "ball", "mesh": "builtin:sphere", "material": "standard",
                    "position": [0.55, -0.3, 1.0], "scale": 0.3}],
        "light": [{"type": "directional", "direction": [-0.4, -1.0, -0.5], "intensity": 1.5},
                  {"type": "ambient", "color": [0.3, 0.3, 0.35]}]}, "fur_light")
    result, renderer = render(scene)
    read = renderer.targets.read
    surface = scene.objects[0].material.surface_id()
    holds = np.abs(read("normal_exponent_id")[..., 3] - surface) < 0.5
    albedo = np.maximum(read("albedo_specular")[..., :3], 1.0 / 255.0)
    irradiance = read("light_accumulation")[..., :3] / albedo
    light, depths = fur_light_reference(irradiance, read("linear_depth")[..., 0], holds)
    got = read("shell_fur_light")
    assert 0.1 < holds.mean() < 0.7
    other = (read("linear_depth")[..., 0] > 0.0) & ~holds
    assert other.sum() > 20  # the ball in front
    ring = got[..., 3] < 0.0
    assert ring.sum() > 50
    np.testing.assert_allclose(got, light, rtol=1e-4, atol=1e-5)
    spread = depths[..., 1] - depths[..., 0]
    assert (spread > 0.05).sum() > 20  # the silhouettes, and the fur's edge behind the ball
    np.testing.assert_allclose(read("shell_fur_light_depths"), depths, rtol=1e-6)
    # the fur past the skin: lit pixels where the G-buffer holds nothing
    image = result.image[::-1]  # top row first; the targets are bottom row first
    beyond = (read("linear_depth")[..., 0] == 0.0) & (image[..., :3].max(-1) > 8)
    assert beyond.sum() > 40


@pytest.mark.slow
def test_without_a_colour_map_the_fur_is_the_tint_as_over_a_white_texture(render, tmp_path):
    """No texture and no pattern: the layers skip the colour lookup (FUR_COLOR_MAP undefined)
    and draw what a white texture gives; a pattern still shows."""
    write_image(tmp_path / "white.png", np.ones((16, 16, 3), np.float32))
    base = {"size": [96, 72], "background": [0.0, 0.0, 0.0],
            "camera": {"position": [0.0, 0.6, 2.8], "target": [0.0, 0.0, 0.0], "fov": 40.0},
            "light": [{"type": "directional", "direction": [-0.4, -1.0, -0.5]},
                      {"type": "ambient", "color": [0.3, 0.3, 0.35]}]}
    from conftest import psnr

    def image(**params):
        scene = {**base, "object": [{"mesh": "builtin:sphere", "material": "shell_fur",
                                     "params": {"fur_length": 0.12, "shells": 8,
                                                "color": [0.6, 0.4, 0.2], **params}}]}
        for pipeline in ("deferred", "forward"):
            result, _ = render(scene_from_dict(scene, "colour"), pipeline)
            yield result.image[..., :3] / 255.0

    plain = scene_from_dict({**base, "object": [{"mesh": "builtin:sphere",
                                                 "material": "shell_fur"}]}, "plain")
    material = plain.objects[0].material
    assert "FUR_COLOR_MAP" not in material.defines(plain.objects[0])
    striped_scene = scene_from_dict({**base, "object": [{
        "mesh": "builtin:sphere", "material": "shell_fur",
        "params": {"color_pattern": "stripes"}}]}, "striped")
    assert "FUR_COLOR_MAP" in striped_scene.objects[0].material.defines(striped_scene.objects[0])
    tint = list(image())
    white = list(image(color_texture=str(tmp_path / "white.png")))
    striped = list(image(color_pattern="stripes", pattern_color=[0.1, 0.1, 0.1]))
    for a, b, c in zip(tint, white, striped, strict=True):
        assert a.sum(-1).astype(bool).mean() > 0.3
        assert psnr(a, b) > 45.0
        assert psnr(a, c) < 30.0


@pytest.mark.slow
def test_short_fur_keeps_its_silhouette_in_the_deferred_pipeline(render):
    """Fur beyond the skin's silhouette, lit from the skin by the gather, is drawn as much as
    the forward pipeline (which lights each layer fragment itself) draws it: where the surface's
    depth changes fast from pixel to pixel the first pixel holding the fur is at another depth,
    and the light must still be found."""
    scene = scene_from_dict({
        "size": [160, 120], "background": [0.0, 0.0, 0.0],
        "camera": {"position": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"mesh": "builtin:sphere", "material": "shell_fur", "scale": 0.6,
                    # strands of one stiffness: the gather's reach is tested, not the droop
                    # (with strand_variation 0.35 the deferred image draws 652 of 689)
                    "params": {"fur_length": 0.12, "shells": 12, "fins": False,
                               "strand_variation": 0.0}}],
        "light": [{"type": "directional", "direction": [0.0, 0.0, -1.0], "intensity": 1.5},
                  {"type": "ambient", "color": [0.3, 0.3, 0.35]}]}, "short")
    deferred, renderer = render(scene)
    forward, _ = render(scene, "forward")
    beyond = renderer.targets.read("linear_depth")[::-1, :, 0] == 0.0  # top row first
    drawn_deferred = (deferred.image[..., :3].max(-1) > 24) & beyond
    drawn_forward = (forward.image[..., :3].max(-1) > 24) & beyond
    assert drawn_forward.sum() > 150
    assert drawn_deferred.sum() >= 0.95 * drawn_forward.sum()


@pytest.mark.slow
def test_fur_over_the_screen_border_is_lit_as_inside(render):
    """Fur whose root lies just off the screen takes the light of the pixels inside, as the
    search did: the deferred image does not differ from the forward one more along the border
    than inside (``fig12_word``: a furry square filling the frame)."""
    from deferred.scene.loader import load_scene

    scene = load_scene(ROOT / "examples" / "shell_fur" / "fig12_word.toml")
    deferred, _ = render(scene, size=(320, 240))  # roots 1 pixel off the screen
    forward, _ = render(scene, "forward", size=(320, 240))
    error = ((deferred.image[..., :3] / 255.0 - forward.image[..., :3] / 255.0) ** 2).sum(-1)
    border = np.zeros(error.shape, bool)
    border[:2], border[-2:], border[:, :2], border[:, -2:] = True, True, True, True
    assert error[~border].mean() < 1e-3  # the pipelines agree on this short fur
    assert error[border].mean() < 3.0 * error[~border].mean() + 1e-5


def test_a_droplet_blends_in_bands_of_rows_as_it_does_at_once(monkeypatch):
    """Blending a band of rows at a time (bounded memory for a droplet covering a large mask)
    gives the texels blending all of them at once gives, wrapped or not."""
    from deferred.materials.techniques import wetness

    droplets = [Droplet((0.3, 0.4), 0.35, 0.5), Droplet((0.95, 0.5), 0.3, 0.7),
                Droplet((0.5, 0.02), 0.6, 0.4)]
    for wrap in ((False, False), (True, False), (True, True)):
        masks = []
        for band_texels in (1 << 30, 64, 1):  # all at once, a few rows, one row a band
            monkeypatch.setattr(wetness, "BLEND_BAND_TEXELS", band_texels)
            mask = dry_mask(48)
            for droplet in droplets:
                blend_droplet(mask, droplet, wrap)
            masks.append(mask)
        assert (masks[0][..., 3] > 0).mean() > 0.5  # the droplets wet most of it
        np.testing.assert_array_equal(masks[0], masks[1])
        np.testing.assert_array_equal(masks[0], masks[2])



def test_droplets_may_rise_on_a_timeline_but_not_fall(tmp_path, capsys):
    """Fallen droplets stay (the simulation only ever blends more in): an event lowering
    ``droplets`` would be ignored, so it is refused, naming the event."""
    scene = write_scene(tmp_path / "s.toml", "droplets = 10")
    scene.write_text(scene.read_text() + """
[[event]]
time = 0.5
object = "plane0"
params = { droplets = 20 }
[[event]]
time = 1.0
object = "plane0"
params = { droplets = 15 }
""")
    code, out = cli(capsys, "render", str(scene), "-o", str(tmp_path / "out.png"))
    assert code == 2, out
    assert out.strip().splitlines() == [
        "error: s.toml: event[1].params.droplets: droplets may rise on a timeline, not fall "
        "(from 20 to 15 at 1 s): what it counts has happened"]
    assert not (tmp_path / "out.png").exists()
    raised = scene.read_text().replace("droplets = 15", "droplets = 25")
    scene.write_text(raised)
    code, out = cli(capsys, "render", str(scene), "-o", str(tmp_path / "out.png"))
    assert code == 0, out


def test_the_simulation_budget_grows_with_the_strands(render, monkeypatch):
    """Refused before a frame: the steps to reach a time times the object's strands (one a
    triangle) past MAX_STRAND_STEPS; the same time on a coarser mesh renders."""
    import deferred.materials.shell_fur.state as shell_fur_state

    monkeypatch.setattr(shell_fur_state, "MAX_STRAND_STEPS", 20_000)

    def scene(divisions: int):
        return scene_from_dict({"size": [32, 24], "object": [
            {"name": "fur", "mesh": f"builtin:plane?divisions={divisions}",
             "material": "shell_fur", "params": {"time_step": 0.01, "settle": 0.5}}],
            "light": [{"type": "directional"}]}, "s.toml")

    from deferred.errors import InputError

    with pytest.raises(InputError, match=r"^time: t = 1 s needs 150 simulation steps of 200 "
                                         r"strands \(fur: one a triangle\), 30,000 strand "
                                         r"steps; the most is 20,000"):
        render(scene(10), time=1.0)  # 200 triangles x 150 steps
    result, _ = render(scene(4), time=1.0)  # 32 triangles x 150 steps
    assert result.image is not None


def test_a_mask_with_too_few_channels_is_refused_by_its_header(tmp_path, monkeypatch):
    """Refused before a pixel is decoded (a one-channel 16384^2 mask was decoded whole, 2.1 GB,
    to count its channels)."""
    from deferred.errors import InputError
    from deferred.io.images import write_image
    from deferred.materials.techniques import wetness

    write_image(tmp_path / "grey.exr", np.zeros((16, 16, 1), np.float32), channels=("Y",))

    def decoded(*args, **kwargs):
        raise AssertionError("decoded")

    monkeypatch.setattr(wetness, "read_image", decoded)
    with pytest.raises(InputError, match=r"grey.exr needs 4 channels .* it has 1$"):
        wetness.read_mask_image(tmp_path / "grey.exr")


def test_a_droplets_work_is_the_texels_under_it():
    """footprint_texels counts what blend_droplet visits: about (2 r size)^2 a droplet, the
    texel centres inside its circle among them, and no more than its square of texels."""
    from deferred.materials.techniques.wetness import footprint_texels

    size = 256
    for radius in (0.02, 0.05, 0.1, 0.2):
        droplet = Droplet((0.43, 0.57), radius, 0.5)
        texels = footprint_texels([droplet], size)
        side = 2.0 * radius * size
        assert side ** 2 <= texels <= (side + 2) ** 2
        mask = dry_mask(size)
        blend_droplet(mask, droplet)
        assert np.count_nonzero(mask[..., 3]) <= texels
    # the sum over droplets; a droplet wrapping round covers the mask once at most
    droplets = [Droplet((0.1 * k, 0.5), 0.05, 0.5) for k in range(10)]
    assert footprint_texels(droplets, size) == sum(footprint_texels([d], size) for d in droplets)
    assert footprint_texels([Droplet((0.5, 0.5), 3.0, 0.5)], size, (True, True)) == size * size
    assert footprint_texels([Droplet((0.5, 0.5), 3.0, 0.5)], size) == size * size


@pytest.mark.slow
def test_droplet_work_past_the_budget_is_refused_before_a_frame(tmp_path, capsys, monkeypatch):
    """radius^2 x droplets past MAX_DROPLET_TEXELS is refused naming the params or the event
    that asked for the droplets (10,000 droplets of radius 1 on a 4096^2 mask would take hours);
    fewer droplets render, and nothing is written for the refused ones."""
    import deferred.materials.shell_fur.state as shell_fur_state

    monkeypatch.setattr(shell_fur_state, "MAX_DROPLET_TEXELS", 20_000)
    out = tmp_path / "out.png"
    scene = write_scene(tmp_path / "s.toml", "droplets = 40\ndroplet_radius = 1.0\nmask_size = 64")
    code, text = cli(capsys, "render", str(scene), "-o", str(out))
    assert code == 2, text
    assert text.strip().splitlines() == [text.strip()]
    assert text.startswith("error: s.toml: object[0].params.droplets: 40 droplets by t = 0 s "
                           "blend "), text
    assert "the most is 20,000: fewer or smaller droplets, or a smaller mask_size" in text
    assert not out.exists()
    few = write_scene(tmp_path / "s.toml", "droplets = 2\ndroplet_radius = 1.0\nmask_size = 64")
    code, text = cli(capsys, "render", str(few), "-o", str(out))
    assert code == 0, text
    # droplets an event adds: the event is named, and only at a time that reaches it
    few.write_text(few.read_text() + """
[[event]]
time = 1.0
object = "plane0"
params = { droplets = 40 }
""")
    out.unlink()
    code, text = cli(capsys, "render", str(few), "-o", str(out))
    assert code == 0, text
    code, text = cli(capsys, "render", str(few), "-o", str(tmp_path / "late.png"), "--time", "1")
    assert code == 2, text
    assert text.startswith("error: s.toml: event[0].params.droplets: 40 droplets by t = 1 s"), \
        text
    assert not (tmp_path / "late.png").exists()


@pytest.mark.slow
def test_a_moving_object_carries_its_strands_along(gl):
    """Issue #25: the strands follow the object's transform at each step (model_at), so a
    sphere turned upside down by its track still has its fur hanging down the world's -y,
    and its roots sit on the turned mesh (they stayed at the first transform)."""
    from deferred.render.renderer import Renderer
    from deferred.scene.loader import scene_from_dict

    scene = scene_from_dict({
        "size": [32, 24],
        "object": [{"name": "ball", "mesh": "builtin:sphere", "material": "shell_fur",
                    "params": {"shells": 2, "fins": False, "settle": 0.5}}],
        "track": [{"target": "object:ball", "interpolation": "linear",
                   "keys": [{"time": 0.0, "position": [0.0, 0.0, 0.0], "rotation": [0, 0, 0]},
                            {"time": 1.0, "position": [0.5, 0.0, 0.0],
                             "rotation": [180.0, 0.0, 0.0]}]}],
        "light": [{"type": "ambient"}]})
    obj = scene.objects[0]
    with Renderer(scene, gl=gl) as renderer:
        renderer.render(time=2.0, readback=False)
        state = renderer.resources.cached(("shell_fur_state", obj), lambda ctx: None)
        assert isinstance(state, ShellFurState)
        model = scene.world_at(obj, 2.0)
        assert np.allclose(state.model, model)
        world = state.vertex_deflections() @ model[:3, :3].T
        assert world[:, 1].mean() < -1e-3  # hanging down the world, not the object
        centre = state.strands.roots.mean(axis=0)
        assert np.allclose(centre, model[:3, 3], atol=0.02)  # roots on the moved mesh
