"""Issue #22: the files a mesh file names (an OBJ's material library and its textures, a glTF's
buffers and images) are inputs too: one that is a pipe or a device is refused before trimesh
opens it (it blocked the load for good, Ctrl-C swallowed), and an output never replaces one."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from deferred.errors import InputError
from deferred.io.images import read_image, write_image
from deferred.scene.meshes import load_mesh, mesh_references

TETRAHEDRON = """mtllib {library}
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
vt 0 0
vt 1 0
vt 0 1
vt 1 1
usemtl skin
f 1/1 3/3 2/2
f 1/1 2/2 4/4
f 1/1 4/4 3/3
f 2/2 3/3 4/4
"""
LIBRARY = "newmtl skin\nKd 0.8 0.8 0.8\nmap_Kd {texture}\n"
SCENE = """size = [32, 24]
[[object]]
mesh = "tet.obj"
[[light]]
type = "directional"
"""


def obj_with_texture(folder: Path, library: str = "tet.mtl", texture: str = "tex.png") -> Path:
    (folder / "tet.obj").write_text(TETRAHEDRON.format(library=library))
    if not (folder / library).exists():
        (folder / library).write_text(LIBRARY.format(texture=texture))
    if not (folder / texture).exists():
        write_image(folder / texture, np.full((4, 4, 3), 0.25, np.float32))
    return folder / "tet.obj"


def test_references_are_found_as_trimesh_finds_them(tmp_path):
    mesh = obj_with_texture(tmp_path, "my materials.mtl", "skin map.png")
    assert mesh_references(mesh) == [tmp_path / "my materials.mtl", tmp_path / "skin map.png"]
    loaded = load_mesh(str(mesh))
    assert loaded.sources == (mesh, tmp_path / "my materials.mtl", tmp_path / "skin map.png")
    gltf = tmp_path / "thing.gltf"
    gltf.write_text(json.dumps({"buffers": [{"uri": "data.bin"}, {"uri": "data:,abc"}],
                                "images": [{"uri": "skin%20map.png"}, {"bufferView": 0}]}))
    assert mesh_references(gltf) == [tmp_path / "data.bin", tmp_path / "skin map.png"]


@pytest.mark.parametrize("fifo", ["tet.mtl", "tex.png"])
def test_a_named_file_that_is_a_pipe_is_refused_before_it_blocks(tmp_path, fifo):
    os.mkfifo(tmp_path / fifo)
    mesh = obj_with_texture(tmp_path)
    if fifo == "tex.png":  # the library names it
        assert (tmp_path / "tet.mtl").read_text().endswith("map_Kd tex.png\n")
    start = time.monotonic()
    with pytest.raises(InputError, match=rf"{fifo}, named by mesh file tet.obj, is not a "
                                         r"regular file \(a device or pipe\)"):
        load_mesh(str(mesh), where="scene.toml: object[0].mesh")
    assert time.monotonic() - start < 5.0


def test_the_cli_refuses_a_pipe_named_by_an_obj_and_writes_nothing(tmp_path):
    os.mkfifo(tmp_path / "tet.mtl")
    obj_with_texture(tmp_path)
    (tmp_path / "s.toml").write_text(SCENE)
    result = subprocess.run([sys.executable, "-m", "deferred.cli", "render",
                             str(tmp_path / "s.toml"), "-o", str(tmp_path / "out.png")],
                            capture_output=True, text=True, timeout=60,
                            env={**os.environ, "PYTHONPATH": os.getcwd()})
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "tet.mtl, named by mesh file tet.obj" in lines[0]
    assert not (tmp_path / "out.png").exists()


def test_an_output_never_replaces_a_texture_an_obj_names(tmp_path, capsys):
    from deferred.cli import main

    obj_with_texture(tmp_path)
    (tmp_path / "s.toml").write_text(SCENE)
    before = read_image(tmp_path / "tex.png")
    for output in ("tex.png", "tet.mtl"):
        if output.endswith(".mtl"):
            continue  # not an image name: refused by its suffix already
        code = main(["render", str(tmp_path / "s.toml"), "-o", str(tmp_path / output)])
        err = capsys.readouterr().err
        assert code == 2 and f"would overwrite {tmp_path / output}, a file the scene reads" \
            in err, err
    np.testing.assert_array_equal(read_image(tmp_path / "tex.png"), before)
