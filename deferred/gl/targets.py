"""Named render targets of a frame, and framebuffers assembled from them.

Passes declare what they create, read and write by target name (:mod:`deferred.core.graph` checks
it); the dump and the benchmark use the same names. Core targets are the G-buffer (see
:mod:`deferred.gbuffer.layout`), the light accumulation, the composition buffer and the final
image; a material or effect pass may create more.
"""

from __future__ import annotations

import math

import moderngl
import numpy as np

from deferred.gl.target_spec import TargetSpec

LIGHT_ACCUMULATION = "light_accumulation"
DIFFUSE_LIGHT = "diffuse_light"  # where the scene splits its light (SPLIT_LIGHTING)
COMPOSITE = "composite"
FINAL = "final"

LIGHT_ACCUMULATION_SPEC = TargetSpec(4, "f2", "linear HDR light accumulated by every light")
DIFFUSE_LIGHT_SPEC = TargetSpec(4, "f2", "the diffuse part of the light accumulation, of the "
                                "shading models that split their light")
COMPOSITE_SPEC = TargetSpec(4, "f2", "composition buffer: light accumulation + material phase")
FINAL_SPEC = TargetSpec(4, "f1", "tone mapped, sRGB encoded")


class FrameTargets:
    """Owns the textures of the named targets of a frame at one size, and framebuffers over
    them. The renderer declares the targets the pass graph creates."""

    def __init__(self, ctx: moderngl.Context, width: int, height: int):
        self.ctx = ctx
        self.width = width
        self.height = height
        self.specs: dict[str, TargetSpec] = {}
        self.textures: dict[str, moderngl.Texture] = {}
        self._framebuffers: dict[tuple, moderngl.Framebuffer] = {}
        # (x, y, width, height) in GL pixels applied to every framebuffer handed out, draws and
        # clears alike: the dump's pixel history replays a frame restricted to one pixel.
        self.scissor: tuple[int, int, int, int] | None = None

    def declare(self, name: str, spec: TargetSpec) -> moderngl.Texture:
        """Create target ``name`` (or return it if it exists with the same format)."""
        if name in self.textures:
            if not self.specs[name].same_format(spec):
                raise ValueError(f"target '{name}' already declared as {self.specs[name]}")
            return self.textures[name]
        size = self.size_of(spec)
        if spec.depth:
            texture = self.ctx.depth_texture(size)
            texture.compare_func = ""  # read as depth values (a sampler2D), not compared
        else:
            texture = self.ctx.texture(size, spec.components, dtype=spec.dtype)
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        texture.repeat_x = texture.repeat_y = False
        self.specs[name] = spec
        self.textures[name] = texture
        return texture

    def size_of(self, spec: TargetSpec) -> tuple[int, int]:
        return spec.size(self.width, self.height)

    def clear(self, name: str) -> None:
        """Clear target ``name`` to its declared clear value (scissor applies)."""
        spec = self.specs[name]
        if spec.clear is None:
            return
        if spec.depth:
            fbo = self.framebuffer((), name)
            fbo.depth_mask = True  # a cached framebuffer keeps the mask its last pass set
            fbo.clear(depth=spec.clear[0])
        else:
            value = (*spec.clear, 0.0, 0.0, 0.0, 0.0)[:4]
            self.framebuffer((name,)).clear(*value)

    def __getitem__(self, name: str) -> moderngl.Texture:
        return self.textures[name]

    def __contains__(self, name: str) -> bool:
        return name in self.textures

    def framebuffer(self, colors: tuple[str, ...] | list[str],
                    depth: str | None = None) -> moderngl.Framebuffer:
        key = (tuple(colors), depth)
        fbo = self._framebuffers.get(key)
        if fbo is None:
            fbo = self.ctx.framebuffer(
                color_attachments=[self.textures[c] for c in colors],
                depth_attachment=self.textures[depth] if depth else None)
            self._framebuffers[key] = fbo
        fbo.scissor = self.scissor_at(fbo.size)
        return fbo

    def scissor_at(self, size: tuple[int, int]) -> tuple[int, int, int, int] | None:
        """The scissor over a target of ``size`` (a reduced one: the texels covering the
        frame's scissor)."""
        if self.scissor is None or size == (self.width, self.height):
            return self.scissor
        return self.rect_at(self.scissor, size)

    def rect_at(self, rect: tuple[int, int, int, int],
                size: tuple[int, int]) -> tuple[int, int, int, int]:
        """The texels of a target of ``size`` that cover ``rect`` (x, y, width, height in the
        frame's GL pixels)."""
        x, y, width, height = rect
        sx, sy = size[0] / self.width, size[1] / self.height
        x0, y0 = math.floor(x * sx), math.floor(y * sy)
        x1, y1 = math.ceil((x + width) * sx), math.ceil((y + height) * sy)
        return (x0, y0, max(1, x1 - x0), max(1, y1 - y0))

    def read_raw(self, name: str) -> np.ndarray:
        """Target contents in their stored type (uint8, float16 or float32), (H, W, C), bottom
        row first (GL order). Depth targets read as float32."""
        spec = self.specs[name]
        dtype = np.float32 if spec.depth else {"f1": np.uint8, "f2": np.float16,
                                                "f4": np.float32}[spec.dtype]
        data = np.frombuffer(self.textures[name].read(alignment=1), dtype=dtype)
        width, height = self.size_of(spec)
        return data.reshape(height, width, 1 if spec.depth else spec.components)

    def read(self, name: str) -> np.ndarray:
        """Target contents as float32 (H, W, C), bottom row first (GL order)."""
        data = self.read_raw(name)
        if data.dtype == np.uint8:
            return data.astype(np.float32) / 255.0
        return data.astype(np.float32)

    def release(self) -> None:
        for fbo in self._framebuffers.values():
            fbo.release()
        self._framebuffers.clear()
        for texture in self.textures.values():
            texture.release()
        self.textures.clear()
        self.specs.clear()
