"""Tangents for normal maps where a mesh gives none (deferred.gl.tangents), and the extra
attributes' stand-ins (deferred.gl.meshes.MeshData.extra_attributes)."""

import numpy as np

from deferred.gl.meshes import MeshData
from deferred.gl.tangents import mikktspace_tangents
from deferred.scene.builtin_meshes import builtin_sphere


def grid(uv_of):
    """A 6 x 6 grid in the XZ plane facing +Y, its UVs from (x, z)."""
    t = np.linspace(-1.0, 1.0, 7)
    zz, xx = np.meshgrid(t, t, indexing="ij")
    positions = np.stack([xx, np.zeros_like(xx), zz], -1).reshape(-1, 3)
    normals = np.tile([0.0, 1.0, 0.0], (len(positions), 1))
    uvs = np.array([uv_of(x, z) for x, _, z in positions])
    quads = [(r * 7 + c, (r + 1) * 7 + c, (r + 1) * 7 + c + 1, r * 7 + c + 1)
             for r in range(6) for c in range(6)]
    indices = np.array([(a, b, c) for a, b, c, _ in quads] +
                       [(a, c, d) for a, _, c, d in quads])
    return positions, normals, uvs, indices


def test_tangent_runs_along_u_for_any_uv_rotation():
    for angle in (0.0, 0.7, 2.5):
        c, s = np.cos(angle), np.sin(angle)
        # u along the world direction (c, 0, -s), v along (s, 0, c) rotated into +V = -Z
        positions, normals, uvs, indices = grid(lambda x, z, c=c, s=s: (c * x - s * z,
                                                                        -s * x - c * z))
        tangents = mikktspace_tangents(positions, normals, uvs, indices)
        np.testing.assert_allclose(tangents[:, :3], np.tile([c, 0.0, -s], (49, 1)), atol=1e-6)
        bitangent = np.cross(normals, tangents[:, :3]) * tangents[:, 3:]
        np.testing.assert_allclose(bitangent, np.tile([-s, 0.0, -c], (49, 1)), atol=1e-6)


def test_mirrored_uvs_flip_the_handedness():
    positions, normals, uvs, indices = grid(lambda x, z: (x, -z))
    mirrored = grid(lambda x, z: (-x, -z))[2]
    assert np.all(mikktspace_tangents(positions, normals, uvs, indices)[:, 3] == 1.0)
    flipped = mikktspace_tangents(positions, normals, mirrored, indices)
    assert np.all(flipped[:, 3] == -1.0)
    np.testing.assert_allclose(flipped[:, :3], np.tile([-1.0, 0.0, 0.0], (49, 1)), atol=1e-6)


def test_sphere_tangents_follow_the_longitude():
    mesh = builtin_sphere(64, 32)
    tangents = mikktspace_tangents(mesh.positions, mesh.normals, mesh.uvs, mesh.indices)
    phi = mesh.uvs[:, 0] * 2.0 * np.pi
    along = np.stack([np.cos(phi), np.zeros_like(phi), -np.sin(phi)], -1)  # d/dphi, unit
    away_from_poles = np.abs(mesh.normals[:, 1]) < 0.95
    seam = (mesh.uvs[:, 0] > 0.0) & (mesh.uvs[:, 0] < 1.0)
    keep = away_from_poles & seam
    np.testing.assert_allclose(tangents[keep, :3], along[keep], atol=0.02)
    np.testing.assert_allclose(np.linalg.norm(tangents[:, :3], axis=1), 1.0, atol=1e-5)
    assert np.all(np.abs(np.sum(tangents[:, :3] * mesh.normals, axis=1)) < 1e-5)


def test_extra_attributes_are_the_meshs_own_or_their_stand_ins():
    mesh = builtin_sphere(8, 4)
    count = mesh.vertex_count
    extras = mesh.extra_attributes()
    assert extras.shape == (count, 10) and extras.dtype == np.float32
    np.testing.assert_array_equal(extras[:, :2], mesh.uvs)  # the first set stands in
    np.testing.assert_array_equal(extras[:, 2:6], 1.0)  # white
    np.testing.assert_allclose(extras[:, 6:], mikktspace_tangents(
        mesh.positions, mesh.normals, mesh.uvs, mesh.indices))
    rng = np.random.default_rng(3)
    fields = {name: getattr(mesh, name) for name in MeshData.__dataclass_fields__}
    given = MeshData(**{**fields,
                        "uv1": rng.random((count, 2)).astype(np.float32),
                        "colors": rng.random((count, 4)).astype(np.float32),
                        "file_tangents": rng.random((count, 4)).astype(np.float32)})
    np.testing.assert_array_equal(given.extra_attributes(),
                                  np.hstack([given.uv1, given.colors, given.file_tangents]))
