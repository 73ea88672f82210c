"""Image files through OpenImageIO: PNG/EXR out (atomically), any OIIO format in.

``deferred render`` also writes numbered sequences (``out_####.png``) and videos (``.mp4``,
``.gif``): :mod:`deferred.animation`.
"""

from __future__ import annotations

import os
import secrets
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .errors import InputError, RenderError

IMAGE_SUFFIXES = (".png", ".exr")
VIDEO_SUFFIXES = (".mp4", ".gif")
OUTPUT_SUFFIXES = (*IMAGE_SUFFIXES, *VIDEO_SUFFIXES)  # what ``deferred render -o`` writes


def srgb_encode(linear: np.ndarray) -> np.ndarray:
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, linear * 12.92,
                    1.055 * np.power(linear, 1.0 / 2.4) - 0.055)


def srgb_decode(encoded: np.ndarray) -> np.ndarray:
    encoded = np.asarray(encoded, dtype=np.float64)
    return np.where(encoded <= 0.04045, encoded / 12.92, np.power((encoded + 0.055) / 1.055, 2.4))


def check_output_path(path: str | Path, where: str = "-o",
                      suffixes: tuple[str, ...] = OUTPUT_SUFFIXES,
                      patterns: bool = True) -> Path:
    """An output file named by option ``where``: one of ``suffixes``, in an existing folder,
    not itself a folder. With ``patterns``, a name with a run of ``#`` is a numbered image
    sequence (:func:`deferred.animation.expand_pattern`), checked as its first file."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise InputError(f"output must end in {_either(suffixes)}: {path}", where)
    if not path.parent.is_dir():
        raise InputError(f"output folder does not exist: {path.parent}", where)
    first = path
    if patterns and "#" in path.name:
        from .animation import expand_pattern

        first = expand_pattern(path, 0, where)
    if first.is_dir():
        raise InputError(f"output is a folder, not a file: {first}", where)
    return path


def _either(suffixes: Sequence[str]) -> str:
    return suffixes[0] if len(suffixes) == 1 else \
        f"{', '.join(suffixes[:-1])} or {suffixes[-1]}"


# OpenEXR stores channels sorted by name; this attribute keeps the order they were written in.
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
        output = oiio.ImageOutput.create(temporary)
        if output is None or not output.open(temporary, spec):
            raise RenderError(f"cannot write {path}: {oiio.geterror()}")
        ok = output.write_image(pixels)
        output.close()
        if not ok:
            raise RenderError(f"cannot write {path}: {oiio.geterror()}")

    _write_atomically(path, write)
    return path


def write_text(path: str | Path, text: str) -> Path:
    """Write a text file atomically (JSON manifests, CSV)."""
    path = Path(path)
    _write_atomically(path, lambda temporary: Path(temporary).write_text(text, encoding="utf-8"))
    return path


def temporary_path(path: str | Path) -> Path:
    """A hidden name next to ``path`` to write to before renaming over it; the suffix stays
    last so writers pick the format from it."""
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    # Not mkstemp: its 0600 mode would survive the rename; the writer creates the file under
    # the umask like any other output.
    return directory / f".{path.stem}.{secrets.token_hex(6)}.tmp{path.suffix}"


def _write_atomically(path: Path, write) -> None:
    """``write(temporary)`` next to ``path``, then rename over it: readers never see half a file."""
    temporary = str(temporary_path(path))
    try:
        write(temporary)
        os.replace(temporary, path)
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)


def read_image(path: str | Path, srgb_to_linear: bool = False,
               unassociated_alpha: bool = False) -> np.ndarray:
    """Read an image as float32 RGBA (H, W, 4), top row first. ``unassociated_alpha`` keeps the
    colour channels as stored where a format would associate them with alpha (PNG: data in
    RGBA channels, such as a wetness mask, must not be premultiplied)."""
    import OpenImageIO as oiio

    path = Path(path)
    config = oiio.ImageSpec()
    if unassociated_alpha:
        config.attribute("oiio:UnassociatedAlpha", 1)
    image = oiio.ImageInput.open(str(path), config)
    if image is None:
        raise InputError(f"cannot read image: {oiio.geterror() or 'unknown format'}", str(path))
    try:
        pixels = np.asarray(image.read_image(format=oiio.FLOAT), dtype=np.float32)
        spec = image.spec()
    finally:
        image.close()
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    count = pixels.shape[2]
    if count < 3:
        pixels = np.concatenate([np.repeat(pixels[..., :1], 3, axis=2),
                                 pixels[..., 1:2] if count == 2 else
                                 np.ones(pixels.shape[:2] + (1,), np.float32)], axis=2)
    elif count == 3:
        pixels = np.concatenate([pixels, np.ones(pixels.shape[:2] + (1,), np.float32)], axis=2)
    pixels = pixels[..., :4]
    if srgb_to_linear and spec.format.basetype != oiio.FLOAT and spec.format.basetype != oiio.HALF:
        pixels[..., :3] = srgb_decode(pixels[..., :3])
    return pixels


def read_channels(path: str | Path) -> tuple[np.ndarray, list[str], dict[str, object]]:
    """Read every channel of an image (EXR dumps): pixels (H, W, C), names, a few attributes.

    Channels come back in the order they were written when the file records it (EXR itself
    sorts them by name); ``z_channel`` and ``alpha_channel`` index into that order (-1: none).
    """
    import OpenImageIO as oiio

    image = oiio.ImageInput.open(str(path))
    if image is None:
        raise InputError(f"cannot read image: {oiio.geterror()}", str(path))
    try:
        spec = image.spec()
        pixels = np.asarray(image.read_image(format=oiio.FLOAT), dtype=np.float32)
        names = list(spec.channelnames)
        order = spec.getattribute(CHANNEL_ORDER_ATTRIBUTE)
    finally:
        image.close()
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    if isinstance(order, str) and sorted(order.split(",")) == sorted(names):
        wanted = order.split(",")
        pixels = pixels[..., [names.index(n) for n in wanted]]
        names = wanted
    attributes = {"z_channel": names.index("Z") if "Z" in names else -1,
                  "alpha_channel": names.index("A") if "A" in names else -1}
    return pixels, names, attributes
