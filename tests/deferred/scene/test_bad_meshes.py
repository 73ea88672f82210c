"""Bad mesh files are one-line errors (exit 2) naming the file and the scene key, before GL
starts, with no traceback, no library chatter and no output file; sound meshes far out or in
Latin-1 still load."""

import numpy as np
import pytest
from command_line import assert_one_line_error, render_scene

import deferred.scene.geometry
import deferred.scene.meshes
from deferred.scene.meshes import load_mesh

TETRAHEDRON = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


def sphere_obj(extra: str = "") -> str:
    """A small UV-less lat-long sphere as OBJ text (median edge about 0.2)."""
    lines = []
    rings, segments = 8, 16
    for i in range(rings + 1):
        theta = np.pi * i / rings
        for j in range(segments):
            phi = 2 * np.pi * j / segments
            lines.append(f"v {np.sin(theta) * np.cos(phi):.6f} {np.cos(theta):.6f} "
                         f"{np.sin(theta) * np.sin(phi):.6f}")
    for i in range(rings):
        for j in range(segments):
            a = i * segments + j + 1
            b = i * segments + (j + 1) % segments + 1
            lines += [f"f {a} {a + segments} {b}", f"f {b} {a + segments} {b + segments}"]
    return "\n".join(lines) + "\n" + extra


def ply(vertices: str, faces: str, count_v: int, count_f: int) -> str:
    return ("ply\nformat ascii 1.0\n"
            f"element vertex {count_v}\nproperty float x\nproperty float y\nproperty float z\n"
            f"element face {count_f}\nproperty list uchar int vertex_indices\nend_header\n"
            f"{vertices}{faces}")


# name -> (file contents, what the message must say)
BAD_MESHES = {
    "nan.obj": ("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "non-finite vertex positions"),
    "inf.obj": ("v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n", "non-finite vertex positions"),
    "stray.obj": ("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1e20 1 0\nf 1 2 3\nf 2 4 3\n",
                  "coordinate of 1e+20"),
    "far_vertex.obj": (sphere_obj("v 900000 0 0\nf 1 2 145\n"), "median edge"),
    "no_faces.obj": ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no triangles"),
    "index.ply": (ply("0 0 0\n1 0 0\n0 1 0\n", "3 0 1 7\n", 3, 1), "outside its vertex list"),
    "index.obj": ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "cannot read mesh index.obj"),
    "flat.obj": ("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\nf 1 1 2\n",
                 "degenerate"),
    "empty.obj": ("", "no triangles"),
    # a triangle 1e-12 high: an area to the mesh checks, none to xatlas (its UVs came back NaN)
    "thin.obj": ("v 0 0 0\nv 0 0 1e-12\nv 0 1 0\nf 2 3 1\n", "the UV unwrap found no triangle"),
}


# -- meshes -------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", list(BAD_MESHES))
def test_bad_mesh_is_a_one_line_error(tmp_path, capfd, name):
    text, fragment = BAD_MESHES[name]
    (tmp_path / name).write_text(text)
    code, err, out = render_scene(tmp_path, capfd, {"mesh": name, "material": "standard"})
    assert_one_line_error(code, err, "scene.toml: object[0].mesh", name, fragment)
    assert not out.exists()


@pytest.mark.parametrize("limit, value", [("MAX_TRIANGLES", 3), ("MAX_VERTICES", 3),
                                          ("MAX_MESH_FILE_BYTES", 16)])
def test_mesh_size_limits(tmp_path, capfd, monkeypatch, limit, value):
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    module = deferred.scene.meshes if limit == "MAX_MESH_FILE_BYTES" else deferred.scene.geometry
    monkeypatch.setattr(module, limit, value)
    code, err, out = render_scene(tmp_path, capfd, {"mesh": "tet.obj", "material": "standard"})
    assert_one_line_error(code, err, "object[0].mesh", "tet.obj", "more than the")
    assert not out.exists()


def test_latin1_obj_loads(tmp_path):
    """trimesh decodes text with charset_normalizer: a dependency, or this fails to import."""
    (tmp_path / "café.obj").write_bytes("# modèle exporté\n".encode("latin-1")
                                        + TETRAHEDRON.encode())
    mesh = load_mesh("café.obj", tmp_path)
    assert mesh.generated_uvs and len(mesh.indices) == 4


def test_far_but_sound_mesh_still_loads():
    """The span criterion is relative: a vertex 1e5 out on a mesh of 0.2 edges is accepted."""
    from deferred.scene.geometry import build_mesh

    positions = np.array([[0, 0, 0], [0.2, 0, 0], [0, 0.2, 0], [1e5, 0.2, 0]], float)
    mesh = build_mesh("far", positions, np.array([[0, 1, 2], [1, 3, 2]]))
    assert mesh.generated_uvs and np.isfinite(mesh.uvs).all()
