"""Issue #11, the input side: bad meshes and images are one-line errors (exit 2) naming the file
and the scene key, before GL starts, with no traceback, no library chatter and no output file;
the UV unwrap is bounded in time and stops on Ctrl-C."""

import multiprocessing
import os
import signal
import threading
import time

import numpy as np
import OpenImageIO as oiio
import pytest

import deferred.io.images
import deferred.scene.geometry
import deferred.scene.meshes
import deferred.scene.unwrap
from deferred.cli import main
from deferred.errors import InputError
from deferred.io.images import check_image, read_channels, read_image, write_image
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


def write_png(path, width, height, channels=1):
    """A real PNG of any size, cheap however wide (zeros compress to nothing)."""
    image = oiio.ImageOutput.create(str(path))
    assert image.open(str(path), oiio.ImageSpec(width, height, channels, oiio.UINT8))
    assert image.write_image(np.zeros((height, width, channels), np.uint8))
    image.close()


@pytest.fixture(scope="module")
def images(tmp_path_factory):
    """Good and bad image files, by name."""
    folder = tmp_path_factory.mktemp("images")
    rng = np.random.default_rng(11)
    pixels = rng.uniform(size=(48, 48, 4)).astype(np.float32)
    write_image(folder / "good.png", pixels)
    write_image(folder / "good.exr", pixels)
    for name in ("good.png", "good.exr"):
        data = (folder / name).read_bytes()
        (folder / f"truncated{name[4:]}").write_bytes(data[:len(data) // 2])
    (folder / "empty.png").write_bytes(b"")
    (folder / "text.png").write_text("a shopping list, not an image\n")
    (folder / "text.exr").write_bytes(b"v/1\x01" + b"\x00" * 64)
    write_png(folder / "wide.png", 20000, 1, 4)  # over the 16384 a GL texture may have
    write_png(folder / "big_heightfield.png", 1100, 1000)  # ~1 GiB of fur volume
    return folder


BAD_IMAGES = {
    "truncated.png": "hit end of file",
    "truncated.exr": "missing or corrupted",
    "empty.png": "the file is empty",
    "text.png": "Not a PNG file",
    "text.exr": "cannot read image",
    "wide.png": "20000x1, larger than the 16384",
}


def run(capfd, *args):
    """The command line in-process; capfd, not capsys: libpng writes to file descriptor 2."""
    code = main([str(a) for a in args])
    captured = capfd.readouterr()
    return code, captured.out, captured.err


def assert_one_line_error(code, err, *fragments):
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err and "libpng" not in err
    for fragment in fragments:
        assert fragment in err, err


def render_scene(tmp_path, capfd, obj):
    """``deferred render`` of a one-object scene; (code, stderr, output path)."""
    scene = tmp_path / "scene.toml"
    lines = ["[[object]]"] + [f"{k} = {v!r}".replace("'", '"') for k, v in obj.items()
                              if k != "params"]
    if "params" in obj:
        lines += ["[object.params]"] + [f'{k} = "{v}"' for k, v in obj["params"].items()]
    scene.write_text("\n".join(lines) + "\n")
    out = tmp_path / "out.png"
    code, _, err = run(capfd, "render", scene, "-o", out, "--size", "32x24")
    return code, err, out


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


# -- the unwrap's child process -------------------------------------------------------------------

def _sleep_for_ever(positions, indices):
    time.sleep(3600)  # xatlas lost in a bad mesh: only ending the process stops it


def _crash(positions, indices):
    os.kill(os.getpid(), signal.SIGKILL)  # a segfault or the OOM killer


def _raise(positions, indices):
    raise ValueError("xatlas said no")


def test_unwrap_time_limit(tmp_path, capfd, monkeypatch):
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    # the fork copies the patched module
    monkeypatch.setattr(deferred.scene.unwrap, "_xatlas_parametrize", _sleep_for_ever)
    monkeypatch.setenv("DEFERRED_UNWRAP_TIMEOUT", "0.3")
    start = time.monotonic()
    code, err, out = render_scene(tmp_path, capfd, {"mesh": "tet.obj", "material": "standard"})
    assert time.monotonic() - start < 10.0
    assert_one_line_error(code, err, "object[0].mesh", "tet.obj",
                          "UV unwrap did not finish in 0.3 s; give the mesh UVs or simplify it")
    assert not out.exists()
    assert multiprocessing.active_children() == []


def test_an_unwrap_ended_before_it_set_its_signals_up_prints_nothing(tmp_path, capfd,
                                                                      monkeypatch):
    """DEFERRED_UNWRAP_TIMEOUT=1e-9 printed the child's traceback now and then: a child ended
    before it set its own signal handlers ran the parent's SIGTERM handler. Here the child
    waits before setting them up, every time: the error is still one line."""
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    real_child = deferred.scene.unwrap._unwrap_child

    def slow_to_start(*args):
        time.sleep(2.0)
        real_child(*args)

    monkeypatch.setattr(deferred.scene.unwrap, "_unwrap_child", slow_to_start)
    monkeypatch.setenv("DEFERRED_UNWRAP_TIMEOUT", "0.2")
    code, err, out = render_scene(tmp_path, capfd, {"mesh": "tet.obj", "material": "standard"})
    assert_one_line_error(code, err, "object[0].mesh", "tet.obj",
                          "UV unwrap did not finish in 0.2 s; give the mesh UVs or simplify it")
    assert multiprocessing.active_children() == []


def test_ctrl_c_ends_the_unwrap(tmp_path, monkeypatch):
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    monkeypatch.setattr(deferred.scene.unwrap, "_xatlas_parametrize", _sleep_for_ever)
    main_thread = threading.main_thread().ident
    timer = threading.Timer(0.3, signal.pthread_kill, (main_thread, signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            load_mesh("tet.obj", tmp_path)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 5.0
    assert multiprocessing.active_children() == []


@pytest.mark.parametrize("child, fragment", [(_crash, "died (signal 9"),
                                             (_raise, "ValueError: xatlas said no")])
def test_unwrap_failures_name_the_mesh(tmp_path, monkeypatch, child, fragment):
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    monkeypatch.setattr(deferred.scene.unwrap, "_xatlas_parametrize", child)
    with pytest.raises(InputError, match="UV unwrap failed") as caught:
        load_mesh("tet.obj", tmp_path)
    assert fragment in str(caught.value) and "tet.obj" in str(caught.value)


@pytest.mark.parametrize("value", ["soon", "0", "-1", "nan"])
def test_bad_unwrap_timeout_is_named(tmp_path, monkeypatch, value):
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    monkeypatch.setenv("DEFERRED_UNWRAP_TIMEOUT", value)
    with pytest.raises(InputError, match="DEFERRED_UNWRAP_TIMEOUT must be a number"):
        load_mesh("tet.obj", tmp_path)


# -- images -------------------------------------------------------------------------------------

# (material, parameter) pairs that name an image file in a scene
IMAGE_KEYS = [("standard", "texture"), ("revie_fur", "heightfield"),
              ("shell_fur", "color_texture"), ("shell_fur", "wetness_mask")]


@pytest.mark.parametrize("material, key", IMAGE_KEYS)
@pytest.mark.parametrize("name", list(BAD_IMAGES))
def test_bad_image_is_a_one_line_error(tmp_path, capfd, images, material, key, name):
    code, err, out = render_scene(tmp_path, capfd, {
        "mesh": "builtin:sphere", "material": material, "params": {key: images / name}})
    assert_one_line_error(code, err, f"scene.toml: object[0].params.{key}", name,
                          BAD_IMAGES[name])
    assert not out.exists()


def test_bad_texture_fails_before_gl_starts(tmp_path, capfd, images, monkeypatch):
    """The standard material reads its texture at draw time; the scene check reads its header
    (and, for a PNG without its IEND chunk, its last row) before any GL context exists."""
    import moderngl

    def no_gl(*args, **kwargs):
        raise AssertionError("GL started for a scene with a bad texture")

    monkeypatch.setattr(moderngl, "create_standalone_context", no_gl)
    code, err, _ = render_scene(tmp_path, capfd, {
        "mesh": "builtin:sphere", "material": "standard",
        "params": {"texture": images / "truncated.png"}})
    assert_one_line_error(code, err, "object[0].params.texture", "truncated.png")


def test_heightfield_memory_budget(tmp_path, capfd, images):
    """A heightfield costs ~1 KiB per texel as a fur volume: 1100x1000 is over 1 GiB."""
    code, err, out = render_scene(tmp_path, capfd, {
        "mesh": "builtin:sphere", "material": "revie_fur",
        "params": {"heightfield": images / "big_heightfield.png"}})
    assert_one_line_error(code, err, "object[0].params.heightfield", "big_heightfield.png",
                          "1100x1000", "GiB of memory")
    assert not out.exists()


def test_image_memory_budget(images, monkeypatch):
    monkeypatch.setattr(deferred.io.images, "IMAGE_MEMORY_BUDGET", 48 * 48 * 16 - 1)
    for read in (read_image, check_image):
        with pytest.raises(InputError, match=r"good.png is 48x48: it would take 36.0 KiB"):
            read(images / "good.png", where="key")
    # read_channels counts the file's own channels (4 here)
    with pytest.raises(InputError, match="good.exr is 48x48"):
        read_channels(images / "good.exr")
    monkeypatch.setattr(deferred.io.images, "IMAGE_MEMORY_BUDGET", 48 * 48 * 16)
    assert read_image(images / "good.png").shape == (48, 48, 4)


def test_gl_size_limit_is_the_callers(images):
    """Where a context is at hand its GL_MAX_TEXTURE_SIZE replaces the 16384 default."""
    with pytest.raises(InputError, match="48x48, larger than the 32 pixels a side"):
        read_image(images / "good.png", max_size=32)
    assert read_channels(images / "wide.png")[0].shape == (1, 20000, 4)  # dumps: no GL limit


@pytest.mark.parametrize("name", list(BAD_IMAGES))
def test_read_functions_name_the_file(images, capfd, name):
    for read in (read_image, check_image):
        with pytest.raises(InputError) as caught:
            read(images / name)
        message = str(caught.value)
        assert str(images / name) in message and BAD_IMAGES[name] in message
        assert "\n" not in message
    if name != "wide.png":  # read_channels has no GL limit: dumps are not textures
        with pytest.raises(InputError, match=name):
            read_channels(images / name)
    assert "libpng" not in capfd.readouterr().err


def test_good_images_still_read(images, capfd):
    assert read_image(images / "good.png").shape == (48, 48, 4)
    assert check_image(images / "good.exr") == (48, 48, 4)
    data = (images / "good.png").read_bytes()
    trailing = images.parent / "trailing.png"
    trailing.write_bytes(data + b"junk after IEND")  # no IEND at the end: the last row decides
    assert check_image(trailing) == (48, 48, 4)
    assert capfd.readouterr().err == ""


@pytest.mark.parametrize("name", ["truncated.exr", "empty.png", "text.exr"])
def test_compare_with_a_bad_dump_exr(tmp_path, capfd, images, name):
    first, second = tmp_path / "a", tmp_path / "b"
    first.mkdir()
    second.mkdir()
    write_image(first / "final.exr", np.zeros((4, 4, 4), np.float32))
    (second / "final.exr").write_bytes((images / name).read_bytes())
    code, out, err = run(capfd, "dump", "--compare", first, second)
    assert_one_line_error(code, err, str(second / "final.exr"))
    # no difference image, compare.json or b-diff folder (the comparison is written whole)
    assert sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*")) \
        == ["a", "a/final.exr", "b", "b/final.exr"]


def test_channels_past_rgba_are_not_checked_and_ringing_reads_as_zero(tmp_path):
    pixels = np.full((4, 5, 5), 0.5, np.float32)
    pixels[..., 4] = np.inf  # a depth channel of background: not read as colour
    pixels[0, 0, 0] = -1e-4  # filter ringing in an HDR image
    write_image(tmp_path / "five.exr", pixels, channels=["R", "G", "B", "A", "Z"])
    read = read_image(tmp_path / "five.exr")
    assert read.shape == (4, 5, 4) and read.min() == 0.0 and np.isfinite(read).all()
    pixels[0, 0, 0] = -0.5
    write_image(tmp_path / "five.exr", pixels, channels=["R", "G", "B", "A", "Z"])
    with pytest.raises(InputError, match="NaN, infinite or negative"):
        read_image(tmp_path / "five.exr")


def test_a_triangle_too_thin_to_unwrap_beside_good_ones_gets_finite_uvs(tmp_path):
    """A triangle thinner than float32 resolves, alone, is a degenerate mesh to the unwrap (the
    thin.obj case); beside a triangle it charts, the mesh loads with finite UVs everywhere."""
    from deferred.scene.meshes import load_mesh

    path = tmp_path / "sliver.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e-12\nf 1 2 3\nf 4 3 1\n")
    mesh = load_mesh(str(path))
    assert np.isfinite(mesh.uvs).all()
    assert np.ptp(mesh.uvs, axis=0).min() > 0.1  # the good triangle is charted
