"""Image files through OpenImageIO: PNG/EXR out (atomically), any OIIO format in.

Output names are checked in :mod:`deferred.io.paths`; ``deferred render`` also writes numbered
sequences (``out_####.png``) and videos (``.mp4``, ``.gif``): :mod:`deferred.io.video`.
"""

from __future__ import annotations

import os
import stat
import sys
import tempfile
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from deferred.errors import InputError, RenderError
from deferred.io.paths import temporary_path, written_through
from deferred.io.safety import raise_if_stop_requested


def srgb_encode(linear: np.ndarray) -> np.ndarray:
    """Linear values in [0, 1] (clipped) as sRGB-encoded ones."""
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, linear * 12.92,
                    1.055 * np.power(linear, 1.0 / 2.4) - 0.055)


def srgb_decode(encoded: np.ndarray) -> np.ndarray:
    """sRGB-encoded values in [0, 1] as linear ones (float64)."""
    encoded = np.asarray(encoded, dtype=np.float64)
    return np.where(encoded <= 0.04045, encoded / 12.92, np.power((encoded + 0.055) / 1.055, 2.4))


CHANNEL_ORDER_ATTRIBUTE = "deferred:channels"


def write_image(path: str | Path, pixels: np.ndarray, channels: Sequence[str] | None = None,
                attributes: dict[str, object] | None = None, half: bool = False) -> Path:
    """Write ``pixels`` (H, W, C), top row first, atomically (temporary file, then rename).

    uint8 data is written as 8-bit; float data as float (or half) EXR with ``channels`` names.
    A channel named ``Z`` becomes the image's ``z_channel``, one named ``A`` its alpha channel.
    """
    import OpenImageIO as oiio

    path = Path(path)
    pixels = np.ascontiguousarray(pixels)
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    height, width, count = pixels.shape
    if pixels.dtype == np.uint8:
        fmt = oiio.UINT8
    else:
        pixels = pixels.astype(np.float16 if half else np.float32)
        fmt = oiio.HALF if half else oiio.FLOAT
    spec = oiio.ImageSpec(width, height, count, fmt)
    if channels is not None:
        if len(channels) != count:
            raise ValueError(f"{len(channels)} channel names for {count} channels")
        names = tuple(channels)
        spec.channelnames = names
        spec.alpha_channel = names.index("A") if "A" in names else -1
        spec.z_channel = names.index("Z") if "Z" in names else -1
        spec.attribute(CHANNEL_ORDER_ATTRIBUTE, ",".join(names))
    for key, value in (attributes or {}).items():
        spec.attribute(key, value)

    def write(temporary: str) -> None:
        def failed(*messages: str) -> RenderError:
            # the reader knows the file by its name, not by the temporary one
            reason = first_line(*messages).replace(os.path.basename(temporary), path.name)
            return RenderError(f"cannot write {path}: {reason}")

        output = oiio.ImageOutput.create(temporary)
        if output is None:
            raise failed(oiio.geterror())
        try:
            if not output.open(temporary, spec):
                raise failed(output.geterror(), oiio.geterror())
            ok = output.write_image(pixels)
        finally:
            closed = output.close()
        # OIIO's PNG writer returns True from write_image and close on a full disk: only
        # has_error tells. Collect every signal, then check the file it left.
        if not ok or not closed or output.has_error:
            raise failed(output.geterror(), oiio.geterror())
        sync_file(temporary, path)
        _check_image_file(temporary, path, width, height, count)

    _write_atomically(path, write)
    return path


def first_line(*messages: str,
               default: str = "the writer reported an error without a reason") -> str:
    """The first line of the first non-empty message (a writer's, a library's exception):
    errors are one line, and a failure always says why (``default``), even when the library
    did not."""
    for message in messages:
        lines = [line.strip() for line in (message or "").splitlines() if line.strip()]
        if lines:
            return lines[0]
    return default


def _os_reason(exc: OSError) -> str:
    return exc.strerror or str(exc) or type(exc).__name__


def sync_file(temporary: str | Path, path: Path) -> None:
    """Flush the written file to the disk: delayed allocation and network file systems report
    a full disk only here, after the writer closed the file without complaint."""
    try:
        fd = os.open(temporary, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError as exc:
        raise RenderError(f"cannot write {path}: {_os_reason(exc)}") from exc


# Rows a written image is read back at a time (about 16 MB of float pixels at most)
READ_BACK_BYTES = 1 << 24


def _check_image_file(temporary: str, path: Path, width: int, height: int, count: int) -> None:
    """Read a written image back, all of it, a band of rows at a time: a writer that lost data
    without saying so (OIIO's PNG and EXR writers on a full disk leave a file cut short and
    report success) leaves an empty, unreadable or truncated file, caught here before it
    replaces the old one."""
    import OpenImageIO as oiio

    if os.path.getsize(temporary) == 0:
        raise RenderError(f"cannot write {path}: the writer left an empty file")
    image = oiio.ImageInput.open(temporary)
    if image is None:
        raise RenderError(f"cannot write {path}: the written file does not read back: "
                          f"{first_line(oiio.geterror())}")
    try:
        spec = image.spec()
        got = (spec.width, spec.height, spec.nchannels)
        if got != (width, height, count):
            raise RenderError(f"cannot write {path}: the written file reads back as "
                              f"{got[0]}x{got[1]} with {got[2]} channels, not "
                              f"{width}x{height} with {count}")
        rows = max(1, READ_BACK_BYTES // (4 * width * count))
        for first in range(0, height, rows):
            with _quiet_stderr():  # libpng prints a cut-short file's error itself
                band = image.read_scanlines(0, 0, first, min(first + rows, height), 0, 0,
                                            count, "float")
            if band is None or image.has_error:
                raise RenderError(f"cannot write {path}: the written file is cut short or "
                                  f"damaged ({first_line(image.geterror(), oiio.geterror())}); "
                                  "is the disk full?")
    finally:
        image.close()


def write_text(path: str | Path, text: str) -> Path:
    """Write a text file atomically (JSON manifests, CSV), flushed to the disk before the
    rename so a full disk fails here instead of leaving a short file."""
    path = Path(path)

    def write(temporary: str) -> None:
        with open(temporary, "w", encoding="utf-8") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())

    _write_atomically(path, write)
    return path


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Write a file's bytes atomically, flushed before the rename (a frame a worker encoded):
    readers see the old file or the whole new one, never part of it."""
    path = Path(path)

    def write(temporary: str) -> None:
        with open(temporary, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())

    _write_atomically(path, write)
    return path


NEGATIVE_TOLERANCE = 1e-3  # image values this far below 0 read as 0 (HDR filter ringing)
def _write_atomically(path: Path, write: Callable[[str], None]) -> None:
    """``write(temporary)`` next to ``path``, then rename over it: readers never see half a file,
    and a failure (an error, Ctrl-C) leaves the old file as it was and no temporary.

    OS errors become a ``RenderError`` naming the file and the reason. A symbolic link is
    written through: the file it points to is replaced, the link stays."""
    path = written_through(path)
    temporary = str(temporary_path(path))
    try:
        write(temporary)
        raise_if_stop_requested()  # a signal's exception lost on the way: no output still
        os.replace(temporary, path)
    except OSError as exc:
        raise RenderError(f"cannot write {path}: {_os_reason(exc)}") from exc
    finally:
        try:
            if os.path.lexists(temporary):
                os.unlink(temporary)
        except OSError:
            pass  # the write's own error (or success) is what the caller needs to hear


# -- reading ----------------------------------------------------------------------------------
# Every read opens the header first and refuses, before decoding a pixel, an image larger than a
# GL texture may be or one whose decoded pixels would take more than the memory budget: a
# 16384 x 16384 texture is 4 GiB as float RGBA (more again on its way to the GPU) and would get
# the process killed, not a one-line error.
MAX_TEXTURE_SIZE = 16384  # GL_MAX_TEXTURE_SIZE of desktop GPUs and llvmpipe; the context's own
#                           value where one is at hand (``max_size``)
IMAGE_MEMORY_BUDGET = 1 << 30  # bytes an image may take once decoded (``bytes_per_pixel`` each)
RGBA_FLOAT_BYTES = 16  # what read_image makes of every pixel: float32 RGBA
READ_BAND_PIXELS = 1 << 20  # pixels read_image converts at once


def read_image(path: str | Path, srgb_to_linear: bool = False,
               unassociated_alpha: bool = False, *, where: str | None = None,
               max_size: int | None = MAX_TEXTURE_SIZE,
               bytes_per_pixel: int = RGBA_FLOAT_BYTES,
               dtype: type = np.float32) -> np.ndarray:
    """Read an image as RGBA (H, W, 4) of ``dtype`` (float32; float16 for a texture, checked
    before the conversion), top row first. ``unassociated_alpha`` keeps the
    colour channels as stored where a format would associate them with alpha (PNG: data in
    RGBA channels, such as a wetness mask, must not be premultiplied).

    A missing, empty, truncated or corrupt file, one over ``max_size`` pixels a side or over
    ``IMAGE_MEMORY_BUDGET`` at ``bytes_per_pixel`` (what the caller makes of each pixel), or one
    holding NaN, infinite or negative values, is an ``InputError`` naming the file, and
    ``where`` (a scene key) where given.
    """
    import OpenImageIO as oiio

    path = Path(path)
    config = oiio.ImageSpec()
    if unassociated_alpha:
        config.attribute("oiio:UnassociatedAlpha", 1)
    pixels, spec = _decode(path, where, config, max_size, lambda _: bytes_per_pixel)
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    height, width, count = pixels.shape
    decode_srgb = srgb_to_linear and spec.format.basetype not in (oiio.FLOAT, oiio.HALF)
    out = np.empty((height, width, 4), dtype)
    # a band of rows at a time: the whole image's temporaries (its RGBA expansion, the value
    # checks, the sRGB curve in float64) were several times the image
    rows = max(1, READ_BAND_PIXELS // max(width, 1))
    for first in range(0, height, rows):
        band = _rgba(pixels[first:first + rows], count)
        _check_values(band, first, pixels, count, path, where)
        np.maximum(band, 0.0, out=band)
        if decode_srgb:
            band[..., :3] = srgb_decode(band[..., :3])
        out[first:first + rows] = band
    return out


def _rgba(pixels: np.ndarray, count: int) -> np.ndarray:
    """(H, W, C) pixels as float32 RGBA: grey to RGB, an opaque alpha where there is none, extra
    channels (a depth, an id) left out (not read: not checked)."""
    band = np.empty(pixels.shape[:2] + (4,), np.float32)
    band[..., :3] = pixels[..., :1] if count < 3 else pixels[..., :3]
    band[..., 3] = pixels[..., 1] if count == 2 else pixels[..., 3] if count >= 4 else 1.0
    return band


def _check_values(band: np.ndarray, first: int, pixels: np.ndarray, count: int, path: Path,
                  where: str | None) -> None:
    """Every image a scene reads (colours, heights, wetness) holds values from 0 up: NaN,
    infinity or a clearly negative value (a float EXR) would shade black or spread NaN through
    the frame; slightly negative values (filter ringing in an HDR image) read as 0. ``band``
    is rows ``first ...`` of ``pixels``; an error counts the bad values of the whole image."""
    def bad_values(rgba: np.ndarray) -> np.ndarray:
        return ~np.isfinite(rgba) | (rgba < -NEGATIVE_TOLERANCE)

    bad = bad_values(band)
    if not bad.any():
        return
    y, x = np.argwhere(bad.any(axis=-1))[0]
    rows = len(band)
    total = int(bad.sum()) + sum(
        int(bad_values(_rgba(pixels[start:start + rows], count)).sum())
        for start in range(first + rows, len(pixels), rows))
    values = "a value that is" if total == 1 else f"{total:,} values that are"
    raise InputError(f"image {_culprit(path, where)} has {values} "
                     f"NaN, infinite or negative (the first at pixel {x}, {first + y}: "
                     f"{np.array2string(band[y, x], precision=3)}); images hold values "
                     ">= 0", where)


def read_channels(path: str | Path, *, where: str | None = None, max_size: int | None = None
                  ) -> tuple[np.ndarray, list[str], dict[str, object]]:
    """Read every channel of an image (EXR dumps): pixels (H, W, C), names, a few attributes.

    Channels come back in the order they were written when the file records it (EXR itself
    sorts them by name); ``z_channel`` and ``alpha_channel`` index into that order (-1: none).
    Bad files are ``InputError`` as in :func:`read_image` (the budget counts float32 channels).
    """
    pixels, spec = _decode(Path(path), where, None, max_size, lambda count: 4 * count)
    names = list(spec.channelnames)
    order = spec.getattribute(CHANNEL_ORDER_ATTRIBUTE)
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    if isinstance(order, str) and sorted(order.split(",")) == sorted(names):
        wanted = order.split(",")
        pixels = pixels[..., [names.index(n) for n in wanted]]
        names = wanted
    attributes = {"z_channel": names.index("Z") if "Z" in names else -1,
                  "alpha_channel": names.index("A") if "A" in names else -1}
    return pixels, names, attributes


def check_image(path: str | Path, where: str | None = None, *,
                max_size: int | None = MAX_TEXTURE_SIZE,
                bytes_per_pixel: int = RGBA_FLOAT_BYTES) -> tuple[int, int, int]:
    """``(width, height, channels)`` of an image that :func:`read_image` will read, checked as
    it checks, without decoding it: for scene validation, before GL starts, of files read later.

    The file must be complete too: a PNG ends in its IEND chunk; otherwise (a PNG with bytes
    after it, another format) the last row is read, which for EXR is one chunk and finds the
    chunks a truncated file lacks.
    """
    path = Path(path)
    image, spec = _open(path, where, None, max_size, lambda _: bytes_per_pixel)
    try:
        if not _ends_in_png_iend(path):
            with _quiet_stderr() as chatter:
                row = image.read_scanlines(0, 0, spec.y + spec.height - 1, spec.y + spec.height,
                                           0, 0, spec.nchannels, _oiio().FLOAT)
            if row is None or image.has_error:
                raise _unreadable(path, where, image.geterror(), chatter)
            _echo(chatter)
        return spec.width, spec.height, spec.nchannels
    finally:
        image.close()


def _oiio():
    import OpenImageIO as oiio

    return oiio


def _culprit(path: Path, where: str | None) -> str:
    # under a scene key the file's name is enough; alone the message is all there is
    return path.name if where else str(path)


def _unreadable(path: Path, where: str | None, error: str, chatter: list[str]) -> InputError:
    lines = [line.strip() for text in (error, *chatter) for line in (text or "").splitlines()
             if line.strip()]
    reason = lines[0] if lines else "not an image it can read"
    return InputError(f"cannot read image {_culprit(path, where)}: {reason} (truncated or "
                      f"corrupt?)", where)


def _open(path: Path, where: str | None, config, max_size: int | None, bytes_per_pixel):
    """An open ``ImageInput`` and its spec, the file's size checked; ``bytes_per_pixel`` maps a
    channel count to the bytes the caller's pixels take."""
    oiio = _oiio()
    name = _culprit(path, where)
    try:
        size = path.stat().st_size
    except OSError as exc:
        reason = "not found" if isinstance(exc, FileNotFoundError) else exc.strerror or str(exc)
        raise InputError(f"cannot read image {name}: {reason}", where) from None
    if not stat.S_ISREG(path.stat().st_mode):
        kind = "a folder" if path.is_dir() else "not a regular file (a device or pipe)"
        raise InputError(f"cannot read image {name}: it is {kind}", where)
    if size == 0:
        raise InputError(f"cannot read image {name}: the file is empty (0 bytes)", where)
    with _quiet_stderr() as chatter:
        image = oiio.ImageInput.open(str(path), config) if config is not None else \
            oiio.ImageInput.open(str(path))
    if image is None:
        raise _unreadable(path, where, oiio.geterror(), chatter)
    _echo(chatter)
    spec = image.spec()
    width, height, count = spec.width, spec.height, spec.nchannels
    problem = None
    if max_size is not None and max(width, height) > max_size:
        problem = (f"is {width}x{height}, larger than the {max_size} pixels a side a GL "
                   f"texture may have; scale it down")
    elif width * height * bytes_per_pixel(count) > IMAGE_MEMORY_BUDGET:
        need = width * height * bytes_per_pixel(count)
        problem = (f"is {width}x{height}: it would take {amount(need)} of memory here, more "
                   f"than the {amount(IMAGE_MEMORY_BUDGET)} allowed; scale it down")
    if problem is not None:
        image.close()
        raise InputError(f"image {name} {problem}", where)
    return image, spec


def _decode(path: Path, where: str | None, config, max_size: int | None, bytes_per_pixel):
    """The pixels (float32, as OIIO gives them) and spec of a checked image."""
    oiio = _oiio()
    image, spec = _open(path, where, config, max_size, bytes_per_pixel)
    try:
        with _quiet_stderr() as chatter:
            pixels = image.read_image(format=oiio.FLOAT)
        # OIIO answers a failed read with None (a truncated file), not an exception
        if pixels is None or image.has_error:
            raise _unreadable(path, where, image.geterror(), chatter)
        _echo(chatter)
    finally:
        image.close()
    return np.asarray(pixels, dtype=np.float32), spec


def amount(size: int) -> str:
    """``size`` bytes as people read it: ``12.5 MiB``, ``3.0 KiB``, ``7 bytes``."""
    for unit, scale in (("TiB", 1 << 40), ("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)):
        if size >= scale:
            return f"{size / scale:.1f} {unit}"
    return f"{size} byte{'' if size == 1 else 's'}"


_PNG_IEND = b"\x00\x00\x00\x00IEND\xaeB`\x82"


def _ends_in_png_iend(path: Path) -> bool:
    """A PNG whose last bytes are its IEND chunk is complete (the cheap completeness check)."""
    if path.suffix.lower() != ".png":
        return False
    with open(path, "rb") as file:
        file.seek(max(0, path.stat().st_size - len(_PNG_IEND)))
        return file.read() == _PNG_IEND


@contextmanager
def _quiet_stderr() -> Iterator[list[str]]:
    """File descriptor 2 into a temporary file while OIIO reads: libpng prints its errors
    itself (``libpng error: IDAT: ...``), which would break the command line's one-line errors.
    The list yielded gets what was printed: after a successful read the caller prints it after
    all (:func:`_echo`: warnings stay visible), after a failure its error says it.
    Process-wide, like the descriptor: output of other threads in between is held back too."""
    chatter: list[str] = []
    try:
        saved = os.dup(2)
    except OSError:  # no descriptor 2 at all: nothing to keep quiet
        yield chatter
        return
    with tempfile.TemporaryFile() as capture:
        sys.stderr.flush()
        os.dup2(capture.fileno(), 2)
        try:
            yield chatter
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            capture.seek(0)
            chatter.append(capture.read().decode(errors="replace"))


def _echo(chatter: list[str]) -> None:
    text = "".join(chatter)
    if text:
        sys.stderr.write(text)
