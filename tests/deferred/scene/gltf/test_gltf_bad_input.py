"""Bad glTF files: one line naming the file and the JSON path, exit status 2, nothing written,
in bounded time."""

from __future__ import annotations

import json
import math
import time

import numpy as np
import pytest
from gltf_files import GltfBuilder, sphere

from deferred.cli import main


def render(capsys, path, tmp_path):
    out = tmp_path / "out.png"
    code = main(["render", str(path), "-o", str(out), "--size", "32x32"])
    err = capsys.readouterr().err
    return code, err, out


def ball(tmp_path, name="ball.gltf", edit=None, texture: str | None = None):
    """A one-sphere .gltf (and its .bin); ``edit(document)`` changes the JSON first."""
    gltf = GltfBuilder()
    positions, normals, uvs, faces = sphere(1.0, 8, 4)
    extra = {}
    if texture is not None:
        gltf.doc["images"] = [{"uri": texture}]
        gltf.doc["textures"] = [{"source": 0}]
        extra["pbr"] = {"baseColorTexture": {"index": 0}}
    gltf.node(root=True, mesh=gltf.mesh(gltf.primitive(positions, normals, faces,
                                                       gltf.material(**extra), uvs=uvs)))
    path = gltf.save_gltf(tmp_path / name)
    if edit is not None:
        document = json.loads(path.read_text())
        edit(document)
        path.write_text(json.dumps(document))
    return path


def refused(capsys, tmp_path, path, pattern):
    code, err, out = render(capsys, path, tmp_path)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert pattern in lines[0], lines[0]
    assert not out.exists()
    return lines[0]


def test_a_truncated_glb(capsys, tmp_path):
    gltf = GltfBuilder()
    positions, normals, uvs, faces = sphere(1.0, 8, 4)
    gltf.node(root=True, mesh=gltf.mesh(gltf.primitive(positions, normals, faces)))
    path = gltf.save_glb(tmp_path / "cut.glb")
    data = path.read_bytes()
    path.write_bytes(data[:-100])
    refused(capsys, tmp_path, path, f"cut.glb: truncated GLB: its header says {len(data):,} "
                                    f"bytes, the file has {len(data) - 100:,}")
    path.write_bytes(data[:7])
    refused(capsys, tmp_path, path, "cut.glb: truncated GLB: 7 bytes")


def test_a_buffer_outside_the_files_folder(capsys, tmp_path):
    folder = tmp_path / "model"
    folder.mkdir()
    path = ball(folder)
    (tmp_path / "secret.bin").write_bytes(path.with_suffix(".bin").read_bytes())

    def outside(document):
        document["buffers"][0]["uri"] = "../secret.bin"

    path = ball(folder, edit=outside)
    refused(capsys, tmp_path, path, "ball.gltf: buffers[0].uri: the buffer file "
                                    "'../secret.bin' is outside the glTF file's folder")

    def absolute(document):
        document["buffers"][0]["uri"] = str(tmp_path / "secret.bin")

    refused(capsys, tmp_path, ball(folder, edit=absolute),
            "ball.gltf: buffers[0].uri: the buffer file")


def test_a_missing_texture(capsys, tmp_path):
    refused(capsys, tmp_path, ball(tmp_path, texture="albedo.png"),
            "ball.gltf: images[0].uri: texture file not found")


def test_data_uris(capsys, tmp_path):
    def bad_base64(document):
        document["buffers"][0]["uri"] = "data:application/octet-stream;base64,AAA!!"

    refused(capsys, tmp_path, ball(tmp_path, edit=bad_base64),
            "ball.gltf: buffers[0].uri: malformed base64 in its data URI")

    def not_base64(document):
        document["buffers"][0]["uri"] = "data:text/plain,hello"

    refused(capsys, tmp_path, ball(tmp_path, edit=not_base64),
            "ball.gltf: buffers[0].uri: a data URI the framework does not read")


def test_a_good_data_uri_is_read(capsys, tmp_path):
    import base64

    path = ball(tmp_path)
    payload = base64.b64encode(path.with_suffix(".bin").read_bytes()).decode()

    def inline(document):
        document["buffers"][0]["uri"] = f"data:application/octet-stream;base64,{payload}"

    path = ball(tmp_path, edit=inline)
    path.with_suffix(".bin").unlink()
    code, err, out = render(capsys, path, tmp_path)
    assert code == 0, err
    assert out.exists()


def test_accessor_bounds_out_of_range(capsys, tmp_path):
    def longer(document):
        document["accessors"][0]["count"] += 10

    refused(capsys, tmp_path, ball(tmp_path, edit=longer),
            "ball.gltf: accessors[0]: 55 elements of 12 bytes (stride 12) from byte 0 end at "
            "byte 660, past the end of bufferViews[0] (540 bytes)")

    def past_buffer(document):
        document["bufferViews"][1]["byteOffset"] = 10**6

    refused(capsys, tmp_path, ball(tmp_path, edit=past_buffer),
            "ball.gltf: bufferViews[1]: bytes 1,000,000..")

    def bad_index(document):
        document["meshes"][0]["primitives"][0]["indices"] = 99

    refused(capsys, tmp_path, ball(tmp_path, edit=bad_index),
            "ball.gltf: meshes[0].primitives[0].indices: refers to accessors[99], but the file "
            "has 4 accessors")


def test_an_index_past_the_vertices(capsys, tmp_path):
    gltf = GltfBuilder()
    positions, normals, uvs, faces = sphere(1.0, 8, 4)
    faces = faces.copy()
    faces[3, 1] = 4000
    gltf.node(root=True, mesh=gltf.mesh(gltf.primitive(positions, normals, faces)))
    refused(capsys, tmp_path, gltf.save_glb(tmp_path / "far.glb"),
            "far.glb: meshes[0].primitives[0].indices: an index is 4,000, past the 45 "
            "vertices of its primitive")


def test_nan_in_an_accessor(capsys, tmp_path):
    gltf = GltfBuilder()
    positions, normals, uvs, faces = sphere(1.0, 8, 4)
    positions = positions.copy()
    positions[7, 2] = math.nan
    gltf.node(root=True, mesh=gltf.mesh(gltf.primitive(positions, normals, faces)))
    refused(capsys, tmp_path, gltf.save_glb(tmp_path / "nan.glb"),
            "nan.glb: accessors[0]: holds 1 NaN or infinite values (the first in element 7)")


def test_a_million_nodes_are_refused_quickly(capsys, tmp_path):
    path = tmp_path / "many.gltf"
    path.write_text(json.dumps({"asset": {"version": "2.0"},
                                "nodes": [{} for _ in range(10**6)]}))
    start = time.perf_counter()
    refused(capsys, tmp_path, path, "many.gltf: nodes: 1,000,000 nodes, more than the 50,000 "
                                    "the framework reads")
    assert time.perf_counter() - start < 30.0


def test_a_cyclic_node_graph(capsys, tmp_path):
    def cycle(document):
        document["nodes"] += [{"children": [2]}, {"children": [3]}, {"children": [1]}]

    refused(capsys, tmp_path, ball(tmp_path, edit=cycle),
            "ball.gltf: nodes[1].children: the node graph has a cycle (3 nodes:")

    def two_parents(document):
        document["nodes"] += [{"children": [0]}]

    line = refused(capsys, tmp_path, ball(tmp_path, edit=two_parents), "ball.gltf: ")
    assert "nodes[0] is a child of" in line or "a scene lists root nodes" in line


def test_a_required_extension_the_framework_lacks(capsys, tmp_path):
    def required(document):
        document["extensionsUsed"] = document["extensionsRequired"] = ["EXT_meshopt_compression"]

    refused(capsys, tmp_path, ball(tmp_path, edit=required),
            "ball.gltf: extensionsRequired[0]: requires the extension 'EXT_meshopt_compression'")


def test_an_extension_used_is_warned_about_once_by_name(capsys, tmp_path):
    def used(document):
        document["extensionsUsed"] = ["KHR_materials_sheen"]
        document["materials"][0]["extensions"] = {"KHR_materials_sheen": {}}

    code, err, out = render(capsys, ball(tmp_path, edit=used), tmp_path)
    assert code == 0, err
    assert err.count("KHR_materials_sheen") == 1, err
    assert out.exists()


def test_more_than_four_influences_are_a_clear_error(capsys, tmp_path):
    gltf = GltfBuilder()
    positions, normals, uvs, faces = sphere(1.0, 8, 4)
    count = len(positions)
    joints = np.zeros((count, 4))
    weights = np.tile([0.5, 0.2, 0.1, 0.1], (count, 1))
    primitive = gltf.primitive(positions, normals, faces, JOINTS_0=joints, WEIGHTS_0=weights,
                               JOINTS_1=joints, WEIGHTS_1=np.tile([0.1, 0, 0, 0], (count, 1)))
    joint = gltf.node(name="bone")
    gltf.doc["skins"] = [{"joints": [joint]}]
    gltf.node(root=True, mesh=gltf.mesh(primitive), skin=0, children=[joint])
    refused(capsys, tmp_path, gltf.save_glb(tmp_path / "many.glb"),
            "many.glb: meshes[0].primitives[0].attributes.WEIGHTS_1: vertices follow more "
            "than 4 joints")


@pytest.mark.parametrize("text, pattern", [
    ("{", "malformed glTF JSON"),
    ('{"asset": {"version": "1.0"}}', "asset.version: glTF 1.0; the framework reads glTF 2.0"),
    ('{"asset": {"version": "2.0"}, "nodes": [{"mesh": "x"}]}', "malformed glTF JSON"),
])
def test_malformed_documents(capsys, tmp_path, text, pattern):
    path = tmp_path / "bad.gltf"
    path.write_text(text)
    refused(capsys, tmp_path, path, f"bad.gltf: {pattern}")
