"""deferred info SCENE says where a frame's time and memory go: each mesh's vertices and
triangles and the file's materials dropped, the textures (size, memory), the lights, the shadow
maps (and the lights left unshadowed) and the memory budget used."""

from __future__ import annotations

import re

import numpy as np

from deferred.cli import main
from deferred.io.images import write_image

OBJ = """mtllib none.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
usemtl brick
f 1 2 3
usemtl glass
f 1 3 4
"""


def test_info_lists_meshes_textures_lights_shadows_and_memory(tmp_path, capsys):
    (tmp_path / "quad.obj").write_text(OBJ)
    write_image(tmp_path / "wood.png", np.full((32, 64, 3), 128, np.uint8))
    lights = "".join('[[light]]\ntype = "spot"\nposition = [0, 3, 0]\ndirection = [0, -1, 0]\n'
                     'shadows = true\nshadow_resolution = 256\n' for _ in range(3))
    (tmp_path / "scene.toml").write_text(
        'size = [64, 48]\n[shadows]\nmax_shadowed_lights = 2\n'
        '[[object]]\nname = "quad"\nmesh = "quad.obj"\n[object.params]\ntexture = "wood.png"\n'
        '[[object]]\nname = "ball"\nmesh = "builtin:sphere?segments=8&rings=4"\n' + lights)
    code = main(["info", str(tmp_path / "scene.toml")])
    out, err = capsys.readouterr()
    assert code == 0, err
    lines = out.splitlines()
    assert "scene: scene.toml, 64x48" in lines
    quad = next(line for line in lines if line.strip().startswith("quad "))
    assert re.search(r"quad\.obj: \d+ vertices, 2 triangles, material standard", quad), quad
    assert "the file's materials brick, glass dropped (the object's standard draws the whole " \
           "mesh)" in quad
    ball = next(line for line in lines if line.strip().startswith("ball "))
    assert "builtin:sphere: 45 vertices, 64 triangles" in ball, ball
    texture = next(line for line in lines if "wood.png" in line)
    assert re.search(r"wood\.png: 64x32, [\d.]+ KiB$", texture), texture
    assert "scene lights: 3" in lines
    assert any(re.fullmatch(r"objects: 2, \d+ vertices, 66 triangles", line) for line in lines)
    assert "shadow maps: 2 of 3 shadowed lights in an atlas of 4096x4096 " \
           "(max_shadowed_lights = 2)" in lines
    assert "  light[0] spot: 1 tile of 256x256" in lines
    assert "  unshadowed: light[2] (max_shadowed_lights = 2)" in lines
    memory = next(line for line in lines if line.startswith("memory (deferred, 64x48): "))
    assert re.search(r"of the budget of [\d.]+ GiB \([\d.]+%, DEFERRED_TARGET_MEMORY\): \d+ "
                     r"render targets [\d.]+ KiB, held [\d.]+ MiB$", memory), memory
