"""Animation output: the times of a run of frames, numbered image sequences and videos.

``deferred render --frames N --fps F --time T`` renders frame ``i`` at ``T + i / F`` seconds (the
scene's ``[[event]]`` timeline and animated materials follow ``frame.time``) and writes

- a numbered sequence for a name with a run of ``#`` (``out_####.png``, ``.exr`` too): the run
  becomes the frame number, zero-padded to its length (wider numbers keep every digit);
- a video for ``.mp4`` (H.264, yuv420p, through imageio's ffmpeg plugin, the ``video`` extra;
  even sizes only) or
  ``.gif`` (Pillow, looping forever; Pillow merges identical consecutive frames into one longer
  frame, so a GIF's frames are held, a byte a pixel, until it is written at the end:
  :func:`check_animation_memory` refuses more than the memory budget before the first frame).

A video is written to a hidden temporary file next to the output and renamed when complete, so
a failure or Ctrl-C leaves no partial file; each file of a sequence is written atomically.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from PIL import Image

from deferred.errors import InputError, RenderError
from deferred.io.extras import VIDEO, require_extra
from deferred.io.images import first_line, sync_file, write_image
from deferred.io.memory import check_memory
from deferred.io.paths import expand_pattern, output_kind, temporary_path, written_through
from deferred.io.safety import raise_if_stop_requested

GIF_TICK_MS = 10  # GIF frame delays are whole hundredths of a second
MP4_QUALITY = 7  # imageio's 0..10 scale: libx264 CRF 15


def frame_times(frames: int, fps: float, start: float = 0.0) -> list[float]:
    """The time in seconds of each of ``frames`` frames: ``start + i / fps``."""
    if not (isinstance(frames, int) and frames >= 1):
        raise InputError(f"must be a whole number >= 1, got {frames!r}", "--frames")
    if not (math.isfinite(fps) and fps > 0.0):
        raise InputError(f"must be a finite number > 0, got {fps!r}", "--fps")
    if not (math.isfinite(start) and start >= 0.0):
        raise InputError(f"must be a finite number of seconds >= 0, got {start!r}", "--time")
    if not math.isfinite(start + (frames - 1) / fps):
        raise InputError(f"{fps!r} frames a second puts the last frame at no finite time; "
                         "give a larger rate", "--fps")
    return [start + index / fps for index in range(frames)]


def check_video_size(path: str | Path, size: tuple[int, int], where: str = "-o") -> None:
    """H.264 in yuv420p halves the colour resolution: an .mp4 needs an even width and
    height (``InputError`` otherwise, before anything is rendered)."""
    width, height = size
    if Path(path).suffix.lower() == ".mp4" and (width % 2 or height % 2):
        even = f"{width + width % 2}x{height + height % 2}"
        raise InputError(f"an .mp4 (H.264, yuv420p) needs an even width and height, got "
                         f"{width}x{height}; render at --size {even}", where)


# What a GIF frame holds until the file is written at the end (Pillow merges identical
# frames and crops each to what changed, so it takes every frame before writing one): the
# writer's palette frame and Pillow's copy of it, a byte a pixel each
GIF_BYTES_PER_PIXEL = 2


def check_animation_memory(path: str | Path, size: tuple[int, int], frames: int,
                           where: str = "--frames", renderer_bytes: int = 0) -> None:
    """Refuse, before a frame is rendered, a GIF whose frames would take more than the memory
    budget, with ``renderer_bytes`` (the renderer's targets and textures, once it is made) (a
    sequence or an .mp4 holds none: each frame goes to its file or to ffmpeg)."""
    if Path(path).suffix.lower() != ".gif":
        return
    width, height = size
    held = f"{frames:,} frames of {width}x{height} held for a GIF"
    check_memory(frames * width * height * GIF_BYTES_PER_PIXEL + renderer_bytes,
                 f"{held}, with the render targets and textures, take {{}}" if renderer_bytes
                 else f"{held} take {{}}", where,
                 "fewer frames, a smaller size, an .mp4 or a frame pattern")


def gif_durations(frames: int, fps: float) -> list[int]:
    """Delay of each frame in ms, whole GIF ticks, rounded on the running total so the
    animation keeps its rate (24 fps: 40, 40, 40, 50, ...); at least one tick each."""
    ticks = [round(index * 1000.0 / fps / GIF_TICK_MS) for index in range(frames + 1)]
    return [max(1, b - a) * GIF_TICK_MS for a, b in zip(ticks, ticks[1:], strict=False)]


def check_video_writer(path: str | Path, where: str = "-o") -> None:
    """An ``.mp4`` needs the ``video`` extra (imageio and imageio-ffmpeg): ``InputError`` naming
    it when missing (a ``.gif`` needs Pillow alone)."""
    if Path(path).suffix.lower() == ".mp4":
        require_extra(VIDEO, ("imageio", "imageio_ffmpeg"), "writing .mp4", where)


def ffmpeg_executable(where: str = "-o") -> str:
    """The ffmpeg imageio uses (imageio-ffmpeg's own binary unless ``IMAGEIO_FFMPEG_EXE``
    names another); ``InputError`` without the ``video`` extra, ``RenderError`` when it has
    no ffmpeg for this machine."""
    require_extra(VIDEO, ("imageio", "imageio_ffmpeg"), "writing .mp4", where)
    import imageio_ffmpeg

    try:
        return imageio_ffmpeg.get_ffmpeg_exe()
    except RuntimeError as exc:
        raise RenderError(f"mp4 output needs ffmpeg: {exc}") from None


class AnimationWriter:
    """Writes the frames of an animation to a numbered sequence or a video, in order.

    ``write(pixels)`` takes one frame, top row first: (H, W, 4) uint8 sRGB, or float32 linear
    RGBA where :attr:`wants_hdr` (an ``.exr`` sequence). ``close()`` completes the output (a
    video is renamed into place); ``abort()``, or leaving a ``with`` block by an exception,
    removes an unfinished video. Frames of a sequence are written as they come.
    """

    def __init__(self, path: str | Path, fps: float, where: str = "-o"):
        self.path = Path(path)
        self.fps = float(fps)
        self.kind = output_kind(self.path)
        if self.kind == "image":
            raise ValueError(f"{self.path}: not a frame pattern or a video")
        if not (math.isfinite(self.fps) and self.fps > 0.0):
            raise InputError(f"must be a finite number > 0, got {fps!r}", "--fps")
        self.suffix = self.path.suffix.lower()
        if self.kind == "sequence":
            expand_pattern(self.path, 0, where)  # one run of '#', an image suffix
        elif self.suffix == ".mp4":
            ffmpeg_executable(where)  # before any frame is rendered
        self.written: list[Path] = []  # files completed
        self.frames = 0
        self._temporary: Path | None = None
        self._video = None  # the imageio ffmpeg writer
        self._gif_frames: list[Image.Image] = []  # palette images
        self._closed = False

    @property
    def wants_hdr(self) -> bool:
        """Whether frames should be the linear float composite (``.exr`` sequences)."""
        return self.kind == "sequence" and self.suffix == ".exr"

    def write(self, pixels: np.ndarray) -> None:
        if self._closed:
            raise ValueError("the writer is closed")
        if self.kind == "sequence":
            target = expand_pattern(self.path, self.frames)
            if self.wants_hdr:
                write_image(target, pixels, channels=("R", "G", "B", "A"))
            else:
                write_image(target, pixels)
            self.written.append(target)
        else:
            rgb = np.ascontiguousarray(np.asarray(pixels)[..., :3])
            if rgb.dtype != np.uint8:
                raise ValueError("video frames are uint8 sRGB")
            if self.suffix == ".gif":
                # a byte a pixel from here on: Pillow makes the same adaptive palette of an RGB
                # frame when it saves, so the file is the one the RGB frames give
                self._gif_frames.append(Image.fromarray(rgb).convert(
                    "P", palette=Image.Palette.ADAPTIVE))
            else:
                try:
                    self._mp4().append_data(rgb)
                except Exception as exc:  # noqa: BLE001 - ffmpeg gone: a full disk, a kill
                    self.abort()
                    raise RenderError(f"cannot write {self.path}: "
                                      f"{video_failure(exc, self.path)}") from exc
        self.frames += 1

    def _mp4(self):
        if self._video is None:
            import imageio.v2 as iio

            self._temporary = temporary_path(written_through(self.path))
            self._video = iio.get_writer(
                str(self._temporary), format="FFMPEG", mode="I", fps=self.fps,
                codec="libx264", pixelformat="yuv420p", quality=MP4_QUALITY,
                macro_block_size=1, ffmpeg_log_level="quiet")  # failures: video_failure
        return self._video

    def close(self) -> list[Path]:
        """Complete the output; returns the files written."""
        if self._closed:
            return self.written
        try:
            if self.kind == "video" and self.frames:
                if self.suffix == ".gif":
                    self._write_gif()
                else:
                    video, self._video = self._video, None
                    video.close()
                # written to the end, or not renamed over the old file: a full disk leaves
                # a video cut short while its writer says nothing (ffmpeg's trailer, Pillow)
                sync_file(self._temporary, self.path)
                check_video_file(self._temporary, self.path, self.suffix)
                raise_if_stop_requested()  # a signal's exception lost on the way
                os.replace(self._temporary, written_through(self.path))
                self._temporary = None
                self.written.append(self.path)
        except Exception as exc:
            self.abort()
            if isinstance(exc, RenderError | InputError):
                raise
            raise RenderError(f"cannot write {self.path}: {video_failure(exc, self.path)}") \
                from exc
        self._closed = True
        return self.written

    def _write_gif(self) -> None:
        # Pillow directly, into a file this writer closes: its errors (a full or read-only
        # disk) surface here, once, with no writer object left to fail again when collected
        self._temporary = temporary_path(written_through(self.path))
        frames, self._gif_frames = self._gif_frames, []
        with open(self._temporary, "wb") as file:
            frames[0].save(file, format="GIF", save_all=True, append_images=frames[1:],
                           duration=gif_durations(self.frames, self.fps), loop=0)

    def abort(self) -> None:
        """Stop and remove an unfinished video (completed sequence frames stay)."""
        self._closed = True
        self._gif_frames.clear()
        video, self._video = self._video, None
        if video is not None:
            try:
                video.close()
            except Exception:  # noqa: BLE001 - ffmpeg may already be gone (Ctrl-C)
                pass
        if self._temporary is not None:
            self._temporary.unlink(missing_ok=True)
            self._temporary = None

    def __enter__(self) -> AnimationWriter:
        return self

    def __exit__(self, kind, value, traceback) -> None:
        if kind is None:
            self.close()
        else:
            self.abort()


def video_failure(exc: BaseException, path: Path) -> str:
    """One line saying why a video writer failed: a full disk by name (ffmpeg's own words
    are many lines, ending in a broken pipe), else the first line of the error."""
    try:
        stat = os.statvfs(path.parent if str(path.parent) else ".")
        if stat.f_bavail * stat.f_frsize < (1 << 20):
            return "no space left on the disk"
    except OSError:
        pass
    reason = first_line(str(exc), default="")
    return f"{type(exc).__name__}: {reason}" if reason else type(exc).__name__


def _gif_decodes(file) -> bool:
    """Whether a GIF decodes to its last frame and ends with its trailer."""
    from PIL import Image, ImageSequence

    try:
        with Image.open(file) as image:
            for frame in ImageSequence.Iterator(image):
                frame.load()
        file.seek(-1, os.SEEK_END)
        return file.read(1) == b"\x3b"
    except (OSError, ValueError, SyntaxError, EOFError):
        return False


def check_video_file(temporary: Path, path: Path, suffix: str) -> None:
    """A written video is whole: a GIF ends with its trailer byte; an MP4's top-level boxes
    fill the file exactly and include ``moov`` (the index ffmpeg writes last: a full disk
    loses it first). ``RenderError`` naming ``path`` otherwise."""
    size = temporary.stat().st_size
    with open(temporary, "rb") as file:
        if suffix == ".gif":
            whole = _gif_decodes(file)
        else:
            boxes, offset = set(), 0
            while offset + 8 <= size:
                file.seek(offset)
                header = file.read(16)
                length = int.from_bytes(header[:4], "big")
                boxes.add(header[4:8])
                if length == 1 and len(header) == 16:  # a 64-bit size follows the type
                    length = int.from_bytes(header[8:16], "big")
                elif length == 0:  # the box runs to the end of the file
                    length = size - offset
                if length < 8:
                    break
                offset += length
            whole = offset == size and b"moov" in boxes
    if not whole:
        raise RenderError(f"cannot write {path}: the written {suffix[1:]} is cut short; "
                          "is the disk full?")


def describe_written(files: Sequence[Path]) -> str:
    """``out_00.png`` .. ``out_09.png`` (10 files), or the one file."""
    if len(files) == 1:
        return str(files[0])
    return f"{files[0]} .. {files[-1].name} ({len(files)} files)"
