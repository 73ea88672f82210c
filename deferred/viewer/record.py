"""Screenshots and recordings: the frame shown as .png (the image) or .exr (the linear
composite), and a recording to .mp4 or .gif (or a numbered sequence) through the writers
``deferred render`` uses."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from deferred.io.images import write_image
from deferred.io.paths import check_output_path
from deferred.io.video import AnimationWriter, check_video_writer, describe_written


def save_screenshot(path: str | Path, image: np.ndarray, hdr: np.ndarray | None = None
                    ) -> Path:
    """``image`` (uint8, top row first) to .png, or ``hdr`` (float RGBA) to .exr."""
    out = check_output_path(str(path), "screenshot", (".png", ".exr"), patterns=False)
    if out.suffix.lower() == ".exr":
        if hdr is None:
            raise ValueError("an .exr screenshot needs the frame's linear composite")
        return write_image(out, hdr, channels=("R", "G", "B", "A"))
    return write_image(out, image[..., :3] if image.shape[-1] == 4 else image)


class Recording:
    """Frames written as they are shown, at the timeline's rate."""

    def __init__(self, path: str | Path, fps: float):
        out = check_output_path(str(path), "record")
        check_video_writer(out, "record")
        self.path = out
        self.writer = AnimationWriter(out, fps, "record")
        self.frames = 0

    def write(self, image: np.ndarray, hdr: np.ndarray | None = None) -> None:
        self.writer.write(hdr if self.writer.wants_hdr and hdr is not None else image)
        self.frames += 1

    def close(self) -> str:
        return describe_written(self.writer.close())

    def abort(self) -> None:
        self.writer.abort()
