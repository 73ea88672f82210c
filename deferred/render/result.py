"""One rendered frame: its image, its HDR composite (read from the GPU when first asked for) and
its draw calls."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from deferred.errors import InputError, RenderError
from deferred.io.images import write_image


@dataclass
class RenderResult:
    """One frame: ``image`` (H, W, 4) uint8 sRGB, top row first (None: rendered with
    ``readback=False``); ``hdr`` the linear float composite (H, W, 4), read from the GPU when
    first asked for, or before the renderer draws its next frame or is released while the
    result is still held (a result dropped unread costs no read; ``render(hdr=True)`` reads it
    at once); the draw calls, in all and by pass. ``save(path)`` writes the frame (.png the
    image, .exr the composite); in a notebook the result shows as its image."""

    image: np.ndarray | None
    draw_calls: int
    draws_by_pass: dict[str, int]
    gl_call_seconds: float = 0.0  # inside drawing GL calls (FrameStats; time_gl_calls only)
    _hdr: np.ndarray | None = field(default=None, repr=False)
    _read_hdr: Callable[[], np.ndarray] | None = field(default=None, repr=False, compare=False)

    @property
    def hdr(self) -> np.ndarray:
        if self._hdr is None:
            if self._read_hdr is None:
                raise RenderError("this result has no HDR composite (rendered with "
                                  "readback=False)")
            self._hdr = self._read_hdr()
            self._read_hdr = None
        return self._hdr

    def save(self, path: str | Path) -> Path:
        """Write the frame to ``path``: the image as .png, the linear composite as .exr
        (float RGBA). Written whole or not at all; returns the path."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix == ".exr":
            return write_image(path, self.hdr, channels=("R", "G", "B", "A"))
        if suffix != ".png":
            raise InputError(f"saves .png (the image) or .exr (the linear composite), got "
                             f"'{path.name}'", "path")
        if self.image is None:
            raise RenderError("this result has no image (rendered with readback=False)")
        return write_image(path, self.image)

    def _repr_png_(self) -> bytes | None:
        """The image as PNG bytes: how Jupyter shows a result."""
        if self.image is None:
            return None
        from io import BytesIO

        from PIL import Image

        buffer = BytesIO()
        Image.fromarray(np.ascontiguousarray(self.image)).save(buffer, format="PNG")
        return buffer.getvalue()
