"""Issue #22: a full disk never gives exit 0 with a damaged file, nor destroys the old output.

A small tmpfs is filled to leave a few different byte counts free around each format's size
(PNG, EXR, GIF, MP4); every render either writes a whole file that reads back, or exits 1 with
one line and leaves the old file as it was, and no temporary file behind. Skipped where a tmpfs
cannot be mounted (not root, or no mount permission in the container)."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from deferred.cli import main
from deferred.io.images import read_image

DISK_BYTES = 512 * 1024
PAGE = 4096
OLD = b"the old output"


@pytest.fixture
def small_disk(tmp_path):
    disk = tmp_path / "disk"
    disk.mkdir()
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("mounting a tmpfs needs root and mount(8)")
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={DISK_BYTES}", "tmpfs",
                              str(disk)], capture_output=True, text=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.strip()}")
    try:
        yield disk
    finally:
        subprocess.run(["umount", str(disk)], capture_output=True)


def free_bytes(folder: Path) -> int:
    stat = os.statvfs(folder)
    return stat.f_bavail * stat.f_frsize


def fill_leaving(folder: Path, free: int) -> None:
    """Fill ``folder``'s disk with one file until about ``free`` bytes are left."""
    (folder / "fill").unlink(missing_ok=True)
    with open(folder / "fill", "wb") as file:
        file.write(b"\0" * max(0, free_bytes(folder) - free))


def render(capfd, out: Path, *extra: str) -> tuple[int, str]:
    """The CLI's exit code and all it printed to file descriptor 2 (libpng prints there)."""
    code = main(["render", "-o", str(out), "--size", "96x54", *extra])
    return code, capfd.readouterr().err


def whole(path: Path) -> bool:
    """Read by another reader than the writer's check: every pixel of an image; every frame
    of a GIF (Pillow); an MP4 by imageio's ffmpeg reader, to its last frame."""
    if path.suffix in (".png", ".exr"):
        read_image(path)  # raises on a cut-short file
    elif path.suffix == ".gif":
        from PIL import Image, ImageSequence

        with Image.open(path) as image:  # Pillow merges the demo's identical frames
            for frame in ImageSequence.Iterator(image):
                frame.load()  # raises on a cut-short file
    else:
        import imageio.v2 as iio

        with iio.get_reader(str(path), format="FFMPEG") as reader:
            assert sum(1 for _ in reader) == 6
    return True


@pytest.mark.slow
@pytest.mark.parametrize("suffix, extra", [(".png", ()), (".exr", ()),
                                           (".gif", ("--frames", "6")),
                                           (".mp4", ("--frames", "6"))])
def test_a_full_disk_never_leaves_a_damaged_file_or_loses_the_old_one(small_disk, capfd,
                                                                      suffix, extra):
    out = small_disk / f"out{suffix}"
    code, err = render(capfd, out, *extra)  # its size with room to spare
    assert code == 0, err
    size = out.stat().st_size
    out.unlink()
    counts = sorted({max(PAGE, size - 2 * PAGE), max(PAGE, size - PAGE), size, size + PAGE,
                     size // 2, 2 * size})
    outcomes = set()
    for free in counts:
        out.write_bytes(OLD)
        fill_leaving(small_disk, free)
        code, err = render(capfd, out, *extra)
        lines = err.strip().splitlines()
        if code == 0:
            assert whole(out), (free, err)
        else:
            assert code == 1 and len(lines) == 1 and lines[0].startswith(
                f"render failed: cannot write {out}:"), (free, err)
            assert out.read_bytes() == OLD, free  # the old file, as it was
        assert sorted(p.name for p in small_disk.iterdir()) == ["fill", out.name], free
        outcomes.add(code)
        (small_disk / "fill").unlink()
    assert outcomes == {0, 1}, outcomes  # the counts straddle the size: both were seen
