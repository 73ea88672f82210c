"""The format of a named render target."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class TargetSpec:
    """Format of a target: components and moderngl dtype ('f1' RGBA8, 'f2' half, 'f4' float)."""

    components: int
    dtype: str
    description: str = ""
    depth: bool = False

    @property
    def bytes_per_pixel(self) -> int:
        if self.depth:
            return 4  # D24 (+8 bits padding/stencil)
        return self.components * int(self.dtype[1])

    @property
    def format_name(self) -> str:
        if self.depth:
            return "DEPTH24"
        names = {"f1": "8", "f2": "16F", "f4": "32F"}
        return "RGBA"[: self.components] + names[self.dtype]
