"""Issue #22: the files a mesh file names (an OBJ's material library and its textures, a glTF's
buffers and images) are inputs too: one that is a pipe or a device is refused before trimesh
opens it (it blocked the load for good, Ctrl-C swallowed), and an output never replaces one."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from deferred.errors import InputError
from deferred.io.images import read_image, write_image
from deferred.scene.meshes import load_mesh

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


def test_the_files_trimesh_read_are_the_meshs_sources(tmp_path):
    mesh = obj_with_texture(tmp_path, "my materials.mtl", "skin map.png")
    loaded = load_mesh(str(mesh))
    assert loaded.sources == (mesh, tmp_path / "my materials.mtl", tmp_path / "skin map.png")
    (tmp_path / "skin map.png").unlink()  # a missing texture: trimesh goes without it
    assert load_mesh(str(mesh)).sources == (mesh, tmp_path / "my materials.mtl")


def expire(signum, frame):
    raise TimeoutError("the load blocked")


@pytest.mark.parametrize("fifo", ["tet.mtl", "tex.png"])
def test_a_named_file_that_is_a_pipe_is_refused_before_it_blocks(tmp_path, fifo):
    os.mkfifo(tmp_path / fifo)
    mesh = obj_with_texture(tmp_path)
    if fifo == "tex.png":  # the library names it
        assert (tmp_path / "tet.mtl").read_text().endswith("map_Kd tex.png\n")
    signal.signal(signal.SIGALRM, expire)
    signal.alarm(20)  # a regression blocks in the open: fail, do not hang the suite
    try:
        with pytest.raises(InputError, match=rf"file {fifo} named by tet.obj is not a regular "
                                             r"file \(a device or pipe\)"):
            load_mesh(str(mesh), where="scene.toml: object[0].mesh")
    finally:
        signal.alarm(0)


@pytest.mark.slow
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
    assert len(lines) == 1 and "file tet.mtl named by tet.obj is not a regular file" in lines[0]
    assert not (tmp_path / "out.png").exists()


def test_an_output_never_replaces_a_texture_an_obj_names(tmp_path, capsys):
    from deferred.cli import main

    obj_with_texture(tmp_path)
    (tmp_path / "s.toml").write_text(SCENE)
    before = read_image(tmp_path / "tex.png")
    code = main(["render", str(tmp_path / "s.toml"), "-o", str(tmp_path / "tex.png")])
    err = capsys.readouterr().err
    assert code == 2 and f"would overwrite {tmp_path / 'tex.png'}, a file the scene reads" \
        in err, err
    np.testing.assert_array_equal(read_image(tmp_path / "tex.png"), before)
