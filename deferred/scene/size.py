"""Frame sizes: ``WIDTHxHEIGHT`` text and (width, height) pairs, checked."""

from __future__ import annotations

import numbers
import re
from collections.abc import Sequence

import numpy as np

from deferred.errors import InputError

MAX_SIZE = 16384
SIZE_TEXT = re.compile(r"([0-9]+)\s*[xX]\s*([0-9]+)")


def parse_size(text: str, where: str = "--size") -> tuple[int, int]:
    match = SIZE_TEXT.fullmatch(text.strip())  # digits only: int() takes "1_60" and "+160"
    if match is None:
        raise InputError(f"expected WIDTHxHEIGHT such as 1280x720, got '{text}'", where)
    return check_size((int(match.group(1)), int(match.group(2))), where)


def check_size(size: tuple[int, int], where: str) -> tuple[int, int]:
    """``size`` as (width, height) in whole pixels, each 1..``MAX_SIZE``; ``InputError``
    naming ``where`` otherwise (a string, three numbers, a fraction of a pixel)."""
    if isinstance(size, np.ndarray) and size.ndim == 1:
        size = size.tolist()
    if isinstance(size, str | bytes) or not isinstance(size, Sequence) or len(size) != 2 or \
            not all(isinstance(side, numbers.Integral) and not isinstance(side, bool)
                    for side in size):
        raise InputError(f"expected (width, height) in whole pixels, e.g. (1280, 720), "
                         f"got {size!r}", where)
    width, height = (int(side) for side in size)
    if not (1 <= width <= MAX_SIZE and 1 <= height <= MAX_SIZE):
        raise InputError(f"size {width}x{height} is impossible (each side 1..{MAX_SIZE})", where)
    return width, height
