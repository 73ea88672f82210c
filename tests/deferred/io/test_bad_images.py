"""Bad image files (textures, heightfields, dumps to compare) are one-line errors (exit 2) naming
the file and the scene key, before GL starts, with no traceback and no library chatter; images
past the memory budget or a GL texture's size are refused; good images still read."""

import numpy as np
import OpenImageIO as oiio
import pytest
from command_line import assert_one_line_error, render_scene, run

import deferred.io.images
from deferred.errors import InputError
from deferred.io.images import check_image, read_channels, read_image, write_image


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
