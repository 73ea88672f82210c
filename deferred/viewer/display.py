"""The viewport on the window: the frames the viewer shows (kept as its own textures, so a
failed render leaves the last good frame), drawn single, split or as a difference."""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from deferred.viewer.shaders import viewer_program

MODES = {"single": 0, "split": 1, "difference": 2}  # the views, in order: their shader ids


@dataclass
class Rect:
    """A rectangle of the window in pixels, top-left origin (as mouse events are)."""

    x: int
    y: int
    width: int
    height: int

    def contains(self, x: float, y: float) -> bool:
        return self.x <= x < self.x + self.width and self.y <= y < self.y + self.height


class FrameSlot:
    """One image the viewport shows (the frame, the split's other side, a buffer view): an RGBA8
    texture of the viewer's, filled by copying a renderer's final target or by an upload."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.texture: moderngl.Texture | None = None
        self.filled = False

    def _fit(self, size: tuple[int, int]) -> moderngl.Texture:
        if self.texture is None or self.texture.size != size:
            if self.texture is not None:
                self.texture.release()
            self.texture = self.ctx.texture(size, 4)
            self.texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
            self.texture.repeat_x = self.texture.repeat_y = False
        return self.texture

    def copy_from(self, source: moderngl.Texture) -> None:
        """Copy a renderer's final target (RGBA8, bottom row first) in."""
        texture = self._fit(source.size)
        src = self.ctx.framebuffer(color_attachments=[source])
        dst = self.ctx.framebuffer(color_attachments=[texture])
        try:
            self.ctx.copy_framebuffer(dst, src)
        finally:
            src.release()
            dst.release()
        self.filled = True

    def upload(self, image: np.ndarray) -> None:
        """An (H, W, 3 or 4) uint8 image, top row first."""
        height, width = image.shape[:2]
        if image.shape[2] == 3:
            image = np.concatenate([image, np.full((height, width, 1), 255, np.uint8)], axis=2)
        texture = self._fit((width, height))
        texture.write(np.ascontiguousarray(image[::-1]).tobytes())
        self.filled = True

    def read(self) -> np.ndarray:
        """The image as (H, W, 4) uint8, top row first."""
        assert self.texture is not None
        width, height = self.texture.size
        data = np.frombuffer(self.texture.read(alignment=1), np.uint8)
        return data.reshape(height, width, 4)[::-1].copy()

    def release(self) -> None:
        if self.texture is not None:
            self.texture.release()
            self.texture = None


class Viewport:
    """Draws the slots into the window's framebuffer at ``rect``: a program for each view and
    for whether the images are the viewport's size (``shaders/viewer/viewport.frag``)."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.programs: dict[tuple[str, bool], moderngl.Program] = {}
        self.vaos: dict[tuple[str, bool], moderngl.VertexArray] = {}

    def _program(self, mode: str, exact: bool) -> tuple[moderngl.Program,
                                                          moderngl.VertexArray]:
        key = (mode, exact)
        if key not in self.programs:
            defines = {"MODE": str(MODES[mode]), **({"EXACT": "1"} if exact else {})}
            program = viewer_program(self.ctx, "viewport.vert", "viewport.frag", defines)
            for name, unit in (("u_left", 0), ("u_right", 1)):
                if name in program:
                    program[name].value = unit
            self.programs[key], self.vaos[key] = program, self.ctx.vertex_array(program, [])
        return self.programs[key], self.vaos[key]

    def draw(self, framebuffer: moderngl.Framebuffer, window_height: int, rect: Rect,
             left: FrameSlot, right: FrameSlot | None = None, mode: str = "single",
             split: float = 0.5, gain: float = 1.0) -> None:
        if left.texture is None:
            return
        ctx = self.ctx
        framebuffer.use()
        origin = (rect.x, window_height - rect.y - rect.height)
        ctx.viewport = (*origin, rect.width, rect.height)
        ctx.enable_only(moderngl.NOTHING)
        left.texture.use(0)
        other = right if right is not None and right.texture is not None else left
        other.texture.use(1)
        if mode != "single" and other is left:
            mode = "single"
        program, vao = self._program(mode, left.texture.size == (rect.width, rect.height))
        for name, value in (("u_split", float(split)), ("u_gain", float(gain)),
                            ("u_origin", tuple(float(v) for v in origin)),
                            ("u_width", float(rect.width))):
            if name in program:
                program[name].value = value
        vao.render(moderngl.TRIANGLES, vertices=3)

    def release(self) -> None:
        for key in list(self.programs):
            self.vaos.pop(key).release()
            self.programs.pop(key).release()
