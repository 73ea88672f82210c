import numpy as np
import pytest
import trimesh

from deferred.errors import InputError
from deferred.scene.builtin_meshes import BUILTIN_MESHES
from deferred.scene.geometry import comb_to_tangent_space
from deferred.scene.meshes import load_mesh


def listing_2_7_reference(color, normal, tangent, binormal):
    """Revie Listing 2.7, transcribed literally for one vertex."""
    tangent_space = np.eye(4)
    tangent_space[:3, 0] = tangent
    tangent_space[:3, 1] = binormal
    tangent_space[:3, 2] = normal
    tangent_space = tangent_space.T
    direction = np.array(color[:3]) * 2.0 - 1.0
    direction = direction - np.dot(direction, normal) * normal
    direction = direction / np.linalg.norm(direction)
    direction = (tangent_space @ np.append(direction, 0.0))[:3]
    return np.append((direction + 1.0) * 0.5, color[3])


def test_comb_conversion_matches_listing_2_7():
    rng = np.random.default_rng(7)
    n = 200
    normals = rng.normal(size=(n, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    helper = rng.normal(size=(n, 3))
    tangents = helper - np.sum(helper * normals, axis=1, keepdims=True) * normals
    tangents /= np.linalg.norm(tangents, axis=1, keepdims=True)
    binormals = np.cross(normals, tangents)
    colors = rng.uniform(size=(n, 4))
    got = comb_to_tangent_space(colors, normals, tangents, binormals)
    want = np.array([listing_2_7_reference(c, nn, t, b)
                     for c, nn, t, b in zip(colors, normals, tangents, binormals, strict=True)])
    np.testing.assert_allclose(got, want, atol=1e-6)
    # tangential after conversion: no component along the normal (z = 0 -> packed 0.5)
    np.testing.assert_allclose(got[:, 2], 0.5, atol=1e-6)


@pytest.mark.parametrize("name", BUILTIN_MESHES)
def test_builtin_meshes_have_orthonormal_frames_and_outward_winding(name):
    mesh = load_mesh(f"builtin:{name}")
    n, t, b = mesh.normals, mesh.tangents, mesh.binormals
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)
    assert np.abs(np.sum(n * t, axis=1)).max() < 1e-4
    assert np.abs(np.sum(n * b, axis=1)).max() < 1e-4
    p, i = mesh.positions, mesh.indices
    face = np.cross(p[i[:, 1]] - p[i[:, 0]], p[i[:, 2]] - p[i[:, 0]])
    area = np.linalg.norm(face, axis=1)
    facing = np.sum(face * n[i].mean(axis=1), axis=1)
    assert np.all(facing[area > 1e-9] > 0.0)


def test_obj_with_positions_only_gets_normals_uvs_and_tangents(tmp_path):
    sphere = trimesh.creation.icosphere(subdivisions=2)
    path = tmp_path / "scan.obj"
    lines = [f"v {x} {y} {z}" for x, y, z in sphere.vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in sphere.faces]
    path.write_text("\n".join(lines) + "\n")
    mesh = load_mesh(path.name, tmp_path)
    assert mesh.generated_uvs and not mesh.has_comb
    assert np.isfinite(mesh.uvs).all() and mesh.uvs.min() >= 0.0 and mesh.uvs.max() <= 1.0
    # computed normals point outward on a sphere centred at the origin
    assert np.all(np.sum(mesh.normals * mesh.positions, axis=1) > 0.0)
    assert np.abs(np.sum(mesh.normals * mesh.tangents, axis=1)).max() < 1e-4


def test_ply_vertex_colours_become_tangent_space_comb(tmp_path):
    sphere = trimesh.creation.icosphere(subdivisions=2)
    down = np.tile([0.5, 0.0, 0.5, 0.6], (len(sphere.vertices), 1))  # object-space -Y, length .6
    sphere.visual.vertex_colors = (down * 255).round().astype(np.uint8)
    path = tmp_path / "combed.ply"
    sphere.export(path)
    mesh = load_mesh(str(path))
    assert mesh.has_comb
    np.testing.assert_allclose(mesh.comb[:, 3], 153 / 255, atol=1e-6)
    # back to object space: the comb must be the tangential part of -Y
    d = mesh.comb[:, :3] * 2.0 - 1.0
    obj = d[:, :1] * mesh.tangents + d[:, 1:2] * mesh.binormals + d[:, 2:3] * mesh.normals
    want = np.array([0.0, -1.0, 0.0]) - mesh.normals[:, 1:2] * -1.0 * mesh.normals
    lengths = np.linalg.norm(want, axis=1)
    ok = lengths > 0.2  # away from the poles, where -Y has no tangential part
    want = want[ok] / lengths[ok, None]
    np.testing.assert_allclose(obj[ok], want, atol=0.02)


@pytest.mark.parametrize("suffix", [".stl", ".off", ".glb"])
def test_other_formats_load(tmp_path, suffix):
    box = trimesh.creation.box()
    path = tmp_path / f"box{suffix}"
    box.export(path)
    mesh = load_mesh(str(path))
    assert len(mesh.indices) >= 12


@pytest.mark.parametrize("suffix, magic", [(".ply", "ply"), (".glb", "glTF")])
def test_a_file_without_its_formats_first_bytes_is_refused_before_it_is_parsed(
        tmp_path, monkeypatch, suffix, magic):
    """A 1 GiB file of NUL bytes named .ply took 8 GB to be called "not a ply file"."""
    path = tmp_path / f"zeros{suffix}"
    path.write_bytes(b"\0" * 4096)

    def parsed(*args, **kwargs):
        raise AssertionError("trimesh was asked")

    monkeypatch.setattr(trimesh, "load", parsed)
    with pytest.raises(InputError, match=rf"^s.toml: object\[0\].mesh: zeros{suffix} is not a "
                                         rf"{suffix[1:].upper()} file \(it does not begin with "
                                         rf"'{magic}'\)$"):
        load_mesh(str(path), where="s.toml: object[0].mesh")


def test_a_gltf_whose_data_uri_is_not_base64_is_named_with_its_json_path(tmp_path):
    """A glTF whose data URI is not base64 stopped trimesh with a bare AssertionError, which
    was the whole message; deferred.scene.gltf reads glTF now and names the key."""
    import json

    gltf = tmp_path / "bad.gltf"
    gltf.write_text(json.dumps({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "data:application/octet-stream;base64,AAAA!!", "byteLength": 36}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "max": [1, 1, 0], "min": [0, 0, 0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0}))
    with pytest.raises(InputError, match=r"^s.toml: object\[0\].mesh: bad.gltf: "
                                         r"buffers\[0\].uri: malformed base64 in its data "
                                         r"URI"):
        load_mesh(str(gltf), where="s.toml: object[0].mesh")


def test_bad_meshes_are_input_errors(tmp_path):
    with pytest.raises(InputError, match="not found"):
        load_mesh("missing.obj", tmp_path, where="scene.toml: object[0].mesh")
    broken = tmp_path / "broken.obj"
    broken.write_text("v 0 0 0\nv 1 0 0\nf 1 2 9\n")
    with pytest.raises(InputError) as info:
        load_mesh(str(broken), where="scene.toml: object[0].mesh")
    assert str(info.value).startswith("scene.toml: object[0].mesh:")
    empty = tmp_path / "empty.obj"
    empty.write_text("# nothing\n")
    with pytest.raises(InputError):
        load_mesh(str(empty))
    with pytest.raises(InputError, match="unknown built-in"):
        load_mesh("builtin:teapot")
    with pytest.raises(InputError, match="unsupported"):
        (tmp_path / "x.fbx").write_text("")
        load_mesh(str(tmp_path / "x.fbx"))


def test_obj_with_uvs_keeps_its_vertex_colour_comb(tmp_path):
    """The paper's asset format: UVs plus painted RGBA comb colours."""
    lines = ["v 0 0 0 1 0.5 0.5", "v 1 0 0 1 0.5 0.5", "v 0 0 -1 1 0.5 0.5",
             "vt 0 0", "vt 1 0", "vt 0 1", "vn 0 1 0", "f 1/1/1 2/2/1 3/3/1"]
    (tmp_path / "painted.obj").write_text("\n".join(lines) + "\n")
    mesh = load_mesh(str(tmp_path / "painted.obj"))
    assert mesh.has_comb and not mesh.generated_uvs
    # object +X is the tangent (+U) here: tangent-space (1, 0, 0) packed
    np.testing.assert_allclose(mesh.comb[:, :3], [[1.0, 0.5, 0.5]] * 3, atol=1e-5)


def test_builtin_parameters():
    torus = load_mesh("builtin:torus?segments=78&sides=60")
    assert torus.name == "builtin:torus"  # labels derived from it stay identifiers (torus0)
    assert len(torus.indices) == 9360  # 2 * 78 * 60
    assert torus.vertex_count == 79 * 61
    assert len(load_mesh("builtin:torus").indices) == 2 * 64 * 32  # no parameters: unchanged
    thin = load_mesh("builtin:torus?major=1.0&minor=0.1")
    radii = np.linalg.norm(thin.positions[:, [0, 2]], axis=1)
    np.testing.assert_allclose([radii.min(), radii.max()], [0.9, 1.1], atol=1e-5)
    sphere = load_mesh("builtin:sphere?segments=8&rings=4&radius=0.5")
    assert len(sphere.indices) == 2 * 8 * 4
    np.testing.assert_allclose(np.linalg.norm(sphere.positions, axis=1), 0.5, atol=1e-6)
    assert len(load_mesh("builtin:plane?divisions=3&size=4").indices) == 2 * 3 * 3
    np.testing.assert_allclose(load_mesh("builtin:cube?size=3").bounds()[1], [1.5] * 3)


@pytest.mark.parametrize("spec, fragment", [
    ("builtin:torus?twist=3", "builtin:torus has no parameter 'twist' (parameters: segments, "
                              "sides, major, minor)"),
    ("builtin:torus?segments=2", "'segments' must be 3..4096, got 2"),
    ("builtin:sphere?rings=5000", "'rings' must be 3..4096, got 5000"),
    ("builtin:plane?divisions=4.5", "'divisions' must be an integer, got '4.5'"),
    ("builtin:torus?major=big", "'major' must be a number, got 'big'"),
    ("builtin:cube?size=0", "'size' must be greater than 0 and at most 10000, got 0"),
    ("builtin:sphere?radius=inf", "'radius' must be greater than 0 and at most 10000, got inf"),
    ("builtin:sphere?radius=nan", "'radius' must be greater than 0 and at most 10000, got nan"),
    ("builtin:torus?sides", "'sides' has no value"),
    ("builtin:torus?sides=8&sides=9", "'sides' is given twice"),
    ("builtin:teapot?size=1", "unknown built-in mesh 'builtin:teapot'"),
])
def test_builtin_parameter_errors_name_the_mesh_key(spec, fragment):
    with pytest.raises(InputError) as info:
        load_mesh(spec, where="scene.toml: object[0].mesh")
    message = str(info.value)
    assert message.startswith("scene.toml: object[0].mesh: ") and fragment in message, message
    assert "\n" not in message
