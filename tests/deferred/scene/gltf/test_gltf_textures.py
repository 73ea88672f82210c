"""glTF textures through the pbr material: a quad showing a 2x2 image of four colours, moved by
KHR_texture_transform's offset, scale and rotation (in glTF's texture space, v down from the
image's top), each corner of the quad showing the texel the extension's matrix picks, forward and
deferred alike."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import psnr
from gltf_files import GltfBuilder, quad

from deferred.errors import InputError
from deferred.interfaces import registry
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene

# the image's texels, top row first: red, green / blue, white
TEXELS = np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 255]]], np.uint8)
NAMES = {(0, 0): "red", (0, 1): "green", (1, 0): "blue", (1, 1): "white"}


@pytest.fixture(autouse=True)
def pbr_registered(tmp_path, monkeypatch):
    monkeypatch.setenv("DEFERRED_CACHE", str(tmp_path / "cache"))
    try:
        registry.materials.get("pbr")
    except InputError:
        pytest.skip("no pbr material registered")


def textured_quad(tmp_path, transform: dict | None) -> object:
    from PIL import Image

    Image.fromarray(TEXELS).save(tmp_path / "four.png")
    gltf = GltfBuilder()
    positions, normals, uvs, faces = quad(2.0, 2.0)
    gltf.doc["images"] = [{"uri": "four.png"}]
    gltf.doc["samplers"] = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071,
                             "wrapT": 33071}]
    gltf.doc["textures"] = [{"source": 0, "sampler": 0}]
    info = {"index": 0}
    if transform is not None:
        info["extensions"] = {"KHR_texture_transform": transform}
        gltf.doc["extensionsUsed"] = ["KHR_texture_transform"]
    material = gltf.material(pbr={"baseColorTexture": info})
    gltf.node(root=True, mesh=gltf.mesh(gltf.primitive(positions, normals, faces, material,
                                                       uvs=uvs)))
    camera = gltf.camera(2 * math.atan(1.1 / 4.0), 0.5, 20.0, aspect=1.0)
    gltf.node(root=True, camera=camera, translation=(0, 0, 4))
    sun = gltf.light(type="directional", intensity=3.0)
    gltf.node(root=True, extensions={"KHR_lights_punctual": {"light": sun}})
    return gltf.save_gltf(tmp_path / "quad.gltf")


def colour_name(pixel: np.ndarray) -> str:
    on = pixel > 0.5 * pixel.max()
    return {(True, False, False): "red", (False, True, False): "green",
            (False, False, True): "blue", (True, True, True): "white"}.get(tuple(on), "?")


def corners(image: np.ndarray) -> dict[str, str]:
    """The colour near each corner of the quad (which fills most of the view)."""
    height, width = image.shape[:2]
    near, far = int(0.12 * width), int(0.88 * width)
    return {"top left": colour_name(image[near, near]), "top right": colour_name(image[near, far]),
            "bottom left": colour_name(image[far, near]),
            "bottom right": colour_name(image[far, far])}


def expected(transform: dict | None) -> dict[str, str]:
    """The texel each corner shows: the corner's glTF UV through the extension's matrix."""
    offset, rotation, scale = (0.0, 0.0), 0.0, (1.0, 1.0)
    if transform is not None:
        offset = transform.get("offset", offset)
        rotation = transform.get("rotation", rotation)
        scale = transform.get("scale", scale)
    c, s = math.cos(rotation), math.sin(rotation)
    out = {}
    for name, (u, v) in {"top left": (0.06, 0.06), "top right": (0.94, 0.06),
                         "bottom left": (0.06, 0.94), "bottom right": (0.94, 0.94)}.items():
        su, sv = u * scale[0], v * scale[1]
        tu, tv = c * su + s * sv + offset[0], -s * su + c * sv + offset[1]
        row, column = min(max(int(tv * 2), 0), 1), min(max(int(tu * 2), 0), 1)
        out[name] = NAMES[(row, column)]
    return out


@pytest.mark.parametrize("transform", [
    None,
    {"offset": [0.5, 0.0], "scale": [0.5, 0.5]},
    {"offset": [0.0, 1.0], "rotation": math.pi / 2},
    {"offset": [1.0, 0.0], "scale": [-1.0, 1.0]},
])
def test_khr_texture_transform_picks_the_texels_it_says(gl, tmp_path, transform):
    path = textured_quad(tmp_path, transform)
    images = []
    for pipeline in ("deferred", "forward"):
        scene = load_scene(path)
        scene.size = (64, 64)
        with Renderer(scene, pipeline, gl=gl) as renderer:
            images.append(renderer.render(hdr=True).hdr[..., :3])
    assert corners(images[0]) == expected(transform)
    assert psnr(np.clip(images[0], 0, 1), np.clip(images[1], 0, 1)) >= 40.0
