"""What the framework says of a glTF file: ``deferred info`` lists its parts and what is not
drawn; morph targets, unknown extensions and oversized textures are warned about by name."""

from __future__ import annotations

import numpy as np
import pytest
from gltf_files import GltfBuilder, quad, sphere

from deferred.cli import main
from deferred.scene.gltf import GltfWarning
from deferred.scene.loader import load_scene


@pytest.fixture(autouse=True)
def cache(tmp_path, monkeypatch):
    """Extracted and downscaled textures go to the test's folder."""
    monkeypatch.setenv("DEFERRED_CACHE", str(tmp_path / "cache"))


def texture_path(scene) -> str:
    """The base colour texture's file of the scene's first object: pbr's table, or the
    standard stand-in's path."""
    params = scene.objects[0].material.params
    texture = getattr(params, "base_color_texture", None) or params.texture
    return getattr(texture, "path", texture)


def morphing_file(tmp_path):
    gltf = GltfBuilder()
    positions, normals, uvs, faces = sphere(1.0, 16, 8)
    primitive = gltf.primitive(positions, normals, faces, gltf.material((0.5, 0.5, 0.5, 1)))
    primitive["targets"] = [{"POSITION": gltf.accessor(np.zeros_like(positions))}]
    ball = gltf.node(root=True, name="ball", mesh=gltf.mesh(primitive, name="blob"))
    gltf.animation([(ball, "weights", [0.0, 1.0], [[0.0], [1.0]], "LINEAR"),
                    (ball, "translation", [0.0, 1.0], [[0, 0, 0], [1, 0, 0]], "STEP")],
                   name="pulse")
    gltf.doc["cameras"] = [{"type": "orthographic", "name": "plan",
                            "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}]
    gltf.node(root=True, name="above", camera=0, translation=(0, 0, 5))
    return gltf.save_glb(tmp_path / "morph.glb")


def test_info_lists_the_files_parts_and_what_is_not_drawn(tmp_path, capsys):
    code = main(["info", str(morphing_file(tmp_path))])
    out, err = capsys.readouterr()
    assert code == 0, err
    lines = out.splitlines()
    for expected in ("glTF: morph.glb (glTF 2.0, generator deferred)", "nodes: 2",
                     "  nodes[0] ball (mesh 0)", "meshes: 1",
                     "  meshes[0]: 1 primitive(s), 153 vertices, 256 triangles",
                     "materials: 1", "animations: 1",
                     "  [0] pulse: 1 channel(s) on 1 node(s), 1 s, STEP",
                     "cameras: 1", "lights: 0", "skins: 0", "not supported: 3",
                     "  morph targets of meshes[0] (drawn in their base shape)",
                     "  cameras[0] plan is orthographic (drawn as perspective)",
                     "  morph weight channels of pulse"):
        assert expected in lines, (expected, out)
    assert "gbuffer:" in out
    assert "morph targets" in err  # warned as it is read too


def test_morph_targets_and_weights_are_warned_about_by_name(tmp_path):
    with pytest.warns(GltfWarning) as caught:
        load_scene(morphing_file(tmp_path))
    said = " ".join(str(w.message) for w in caught)
    assert "meshes[0] (blob) has morph targets" in said
    assert "moves morph target weights of ball" in said
    assert "orthographic" in said


def test_a_texture_over_the_gl_limit_is_downscaled_with_a_warning(tmp_path):
    from PIL import Image

    from deferred.io.images import check_image

    wide = tmp_path / "wide.png"
    Image.fromarray(np.full((4, 20000, 3), 200, np.uint8)).save(wide)
    gltf = GltfBuilder()
    positions, normals, uvs, faces = quad()
    gltf.doc["images"] = [{"uri": "wide.png"}]
    gltf.doc["textures"] = [{"source": 0}]
    material = gltf.material(pbr={"baseColorTexture": {"index": 0}})
    gltf.node(root=True, mesh=gltf.mesh(gltf.primitive(positions, normals, faces, material,
                                                       uvs=uvs)))
    path = gltf.save_gltf(tmp_path / "wide.gltf")
    with pytest.warns(GltfWarning, match=r"wide.gltf: images\[0\] is 20000x4, larger than a "
                                         r"texture may be .*: downscaled to 10000x2"):
        scene = load_scene(path)
    assert check_image(texture_path(scene))[:2] == (10000, 2)


def test_embedded_images_are_cached_by_their_content(tmp_path):
    from deferred.scene.gltf.images import cache_folder

    gltf = GltfBuilder()
    positions, normals, uvs, faces = quad()
    from io import BytesIO

    from PIL import Image

    png = BytesIO()
    Image.fromarray(np.zeros((4, 4, 3), np.uint8)).save(png, format="PNG")
    gltf.doc["images"] = [{"bufferView": gltf.view(png.getvalue()), "mimeType": "image/png"}]
    gltf.doc["textures"] = [{"source": 0}]
    material = gltf.material(pbr={"baseColorTexture": {"index": 0}})
    gltf.node(root=True, mesh=gltf.mesh(gltf.primitive(positions, normals, faces, material,
                                                       uvs=uvs)))
    path = gltf.save_glb(tmp_path / "logo.glb")
    first = load_scene(path)
    second = load_scene(path)
    files = list(cache_folder().iterdir())
    assert len(files) == 1 and files[0].suffix == ".png"
    for scene in (first, second):
        assert texture_path(scene) == str(files[0])
