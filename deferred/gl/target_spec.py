"""The format of a named render target, as a pass declares it when it creates the target."""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from dataclasses import dataclass

_DTYPES = {"8": "f1", "16F": "f2", "32F": "f4"}
_FORMAT = re.compile(r"^(R|RG|RGBA)(8|16F|32F)$")


@dataclass(frozen=True)
class TargetSpec:
    """Format of a target: components and moderngl dtype ('f1' 8-bit unorm, 'f2' half, 'f4'
    float), whether it is a depth target, the value it is cleared to when its creating pass runs
    (``None``: not cleared, the creating pass writes every pixel) and its size relative to the
    frame."""

    components: int
    dtype: str
    description: str = ""
    depth: bool = False
    clear: tuple[float, ...] | None = None
    scale: float = 1.0

    def __post_init__(self) -> None:
        if self.components not in (1, 2, 3, 4) or self.dtype not in ("f1", "f2", "f4"):
            raise ValueError(f"unsupported target format {self.components} x {self.dtype}")
        if not 0.0 < self.scale <= 1.0:
            raise ValueError(f"target scale must be in (0, 1], got {self.scale}")

    @classmethod
    def from_format(cls, name: str, description: str = "",
                    clear: tuple[float, ...] | None = (0.0, 0.0, 0.0, 0.0),
                    scale: float = 1.0) -> TargetSpec:
        """A colour target from a format name: R8, RG8, RGBA8, R16F, ..., RGBA32F."""
        match = _FORMAT.match(name)
        if match is None:
            raise ValueError(f"unknown target format '{name}' (R, RG or RGBA followed by 8, 16F "
                             "or 32F, e.g. RG16F)")
        return cls(len(match.group(1)), _DTYPES[match.group(2)], description, clear=clear,
                   scale=scale)

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

    def size(self, width: int, height: int) -> tuple[int, int]:
        """The target's size at a frame of ``width`` x ``height``: rounded up, so that a reduced
        target's texels cover the whole frame."""
        return (max(1, math.ceil(width * self.scale)), max(1, math.ceil(height * self.scale)))

    def same_format(self, other: TargetSpec) -> bool:
        return (self.components, self.dtype, self.depth, self.scale) == \
            (other.components, other.dtype, other.depth, other.scale)


def targets_bytes(specs: Iterable[TargetSpec], width: int, height: int) -> int:
    """Bytes of the render targets ``specs`` at a frame of ``width`` x ``height``."""
    return sum(spec.bytes_per_pixel * math.prod(spec.size(width, height)) for spec in specs)
