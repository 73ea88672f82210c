"""A glTF file's own parts named in its errors: a .gltf without its .bin says the buffer file is
missing (not the bare name trimesh gives), and a Draco-compressed GLB is decoded, or refused
naming the decoder, never "mesh is degenerate"."""

from __future__ import annotations

import sys

import numpy as np
from gltf_files import GltfBuilder, sphere

from deferred.cli import main
from deferred.io.images import read_image


def render(capsys, path, tmp_path):
    out = tmp_path / "out.png"
    code = main(["render", str(path), "-o", str(out), "--size", "32x32"])
    return code, capsys.readouterr().err, out


def draco_ball(path):
    """A GLB of one sphere whose primitive is Draco-compressed (KHR_draco_mesh_compression)."""
    import DracoPy

    positions, _, _, faces = sphere(1.0, 12, 6)
    gltf = GltfBuilder()
    data = DracoPy.encode(positions.astype(np.float32), faces.astype(np.uint32))
    view = gltf.view(data)
    gltf.doc["accessors"] += [
        {"componentType": 5126, "count": len(positions), "type": "VEC3",
         "min": positions.min(axis=0).tolist(), "max": positions.max(axis=0).tolist()},
        {"componentType": 5125, "count": faces.size, "type": "SCALAR"}]
    primitive = {"attributes": {"POSITION": 0}, "indices": 1, "material": gltf.material(),
                 "extensions": {"KHR_draco_mesh_compression": {
                     "bufferView": view, "attributes": {"POSITION": 0}}}}
    gltf.doc["extensionsUsed"] = gltf.doc["extensionsRequired"] = [
        "KHR_draco_mesh_compression"]
    gltf.node(root=True, mesh=gltf.mesh(primitive))
    return gltf.save_glb(path)


def test_a_gltf_without_its_bin_says_the_buffer_file_is_missing(capsys, tmp_path):
    gltf = GltfBuilder()
    positions, normals, uvs, faces = sphere(1.0, 8, 4)
    gltf.node(root=True, mesh=gltf.mesh(gltf.primitive(positions, normals, faces,
                                                       gltf.material(), uvs=uvs)))
    path = gltf.save_gltf(tmp_path / "helmet.gltf")
    path.with_suffix(".bin").unlink()
    code, err, out = render(capsys, path, tmp_path)
    assert code == 2 and not out.exists()
    assert err.startswith("error: helmet.gltf: buffers[0].uri: buffer file not found: "), err
    assert err.rstrip().endswith("helmet.bin") and len(err.splitlines()) == 1, err


def test_a_draco_glb_renders(capsys, tmp_path):
    code, err, out = render(capsys, draco_ball(tmp_path / "draco.glb"), tmp_path)
    assert code == 0, err
    assert "degenerate" not in err and out.exists()
    image = read_image(out)[..., :3].astype(float)
    # the decoded ball fills the middle of the frame the file's bounds give: not the corners
    assert np.abs(image[16, 16] - image[0, 0]).max() > 0.1, (image[16, 16], image[0, 0])


def test_a_draco_glb_without_the_decoder_names_it(capsys, tmp_path, monkeypatch):
    path = draco_ball(tmp_path / "draco.glb")
    monkeypatch.setitem(sys.modules, "DracoPy", None)  # import DracoPy raises ImportError
    code, err, out = render(capsys, path, tmp_path)
    assert code == 2 and not out.exists()
    assert err.startswith("error: draco.glb: meshes[0].primitives[0].extensions."
                          "KHR_draco_mesh_compression: a Draco-compressed mesh needs the Draco "
                          "decoder, DracoPy"), err
    assert "degenerate" not in err and len(err.splitlines()) == 1, err
