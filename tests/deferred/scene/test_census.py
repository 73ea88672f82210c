"""A scene's meshes counted before any is built (deferred.scene.census): built-in shapes from
their arguments, files from their headers or face lines, the memory of building them checked
first; and the loader's ``before_meshes``, called with every object before a mesh loads."""

from __future__ import annotations

import struct

import pytest

from deferred.errors import InputError
from deferred.scene import loader
from deferred.scene.census import BUILD_BYTES_PER_TRIANGLE, check_mesh_memory, mesh_triangles
from deferred.scene.meshes import load_mesh


@pytest.mark.parametrize("spec", ["builtin:sphere?segments=12&rings=7", "builtin:torus",
                                  "builtin:plane?divisions=5", "builtin:cube",
                                  "builtin:head?segments=10&rings=6"])
def test_a_builtin_is_counted_exactly_without_being_built(spec):
    assert mesh_triangles(spec) == len(load_mesh(spec).indices)


def test_a_bad_builtin_or_a_missing_file_counts_nothing(tmp_path):
    assert mesh_triangles("builtin:sphere?segments=-1") == 0
    assert mesh_triangles("nowhere.obj", tmp_path) == 0
    assert mesh_triangles("notes.gltf", tmp_path) == 0


def test_files_are_counted_from_their_headers_or_face_lines(tmp_path):
    quads = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n" \
            "f 1 2 3 4\n# f 9 9 9\nvn 0 0 1\nf 2 3 5\n"
    (tmp_path / "quads.obj").write_text(quads)
    (tmp_path / "tri.ply").write_text("ply\nformat ascii 1.0\nelement vertex 3\n"
                                      "property float x\nproperty float y\nproperty float z\n"
                                      "element face 1\nproperty list uchar int vertex_indices\n"
                                      "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    (tmp_path / "tri.off").write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    facet = struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0)
    (tmp_path / "two.stl").write_bytes(b"\0" * 80 + struct.pack("<I", 2) + facet * 2)
    assert mesh_triangles("quads.obj", tmp_path) == 2  # a face each: a lower bound
    assert len(load_mesh("quads.obj", tmp_path).indices) == 3
    for name, count in (("tri.ply", 1), ("tri.off", 1), ("two.stl", 2)):
        assert mesh_triangles(name, tmp_path) == count
        assert len(load_mesh(name, tmp_path).indices) == count


def test_building_meshes_past_the_memory_budget_is_refused_naming_the_largest(monkeypatch):
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", str(1_000_000 * BUILD_BYTES_PER_TRIANGLE))
    check_mesh_memory({"a": 900_000, "b": 10}, {"a": "s.toml: object[0].mesh", "b": "x"})
    with pytest.raises(InputError, match=r"building 2 meshes of 2,000,000 triangles .*"
                                         r"DEFERRED_TARGET_MEMORY") as refused:
        check_mesh_memory({"a": 1_500_000, "b": 500_000},
                          {"a": "s.toml: object[0].mesh", "b": "s.toml: object[1].mesh"})
    assert refused.value.where == "s.toml: object[0].mesh"


SCENE = """size = [64, 48]
[[object]]
name = "ball"
mesh = "builtin:sphere?segments=16&rings=8"
[[object]]
mesh = "builtin:torus"
material = "revie_fur"
[[light]]
type = "directional"
"""


def test_before_meshes_sees_every_object_before_a_mesh_loads(monkeypatch):
    loaded = []
    real = loader.load_mesh
    monkeypatch.setattr(loader, "load_mesh", lambda *a, **k: loaded.append(a[0]) or real(*a, **k))
    seen = []

    def before(scene, objects):
        assert not loaded and not scene.objects and len(scene.lights) == 1
        seen.extend((obj.label, obj.triangles, obj.where, obj.material.name) for obj in objects)

    scene = loader.scene_from_toml(SCENE, "s.toml", before_meshes=before)
    assert seen == [("ball", 256, "s.toml: object[0]", "standard"),
                    ("builtin:torus", 4096, "s.toml: object[1]", "revie_fur")]
    assert len(scene.objects) == 2 and len(loaded) == 2


def test_a_refusal_before_the_meshes_loads_none(monkeypatch):
    monkeypatch.setattr(loader, "load_mesh", lambda *a, **k: pytest.fail("a mesh was loaded"))

    def refuse(scene, objects):
        raise InputError("too much", "--samples")

    with pytest.raises(InputError, match="too much"):
        loader.scene_from_toml(SCENE, "s.toml", before_meshes=refuse)


def test_a_file_with_problems_is_not_weighed():
    def weigh(scene, objects):
        pytest.fail("weighed a file refused anyway")

    with pytest.raises(InputError, match="shells"):
        loader.scene_from_toml(SCENE + "[object.params]\nshells = -1\n", "s.toml",
                               before_meshes=weigh)
