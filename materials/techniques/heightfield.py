"""A fur heightfield image (Revie 2.4.1): each texel holds the height (0..1 of the fur layer) a
strand reaches there. The fur technique turns it into a fur volume (``fur_volume.py``) in place
of the generated strands, so an artist's image still shapes the fur.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from deferred.api import read_image

from .fur_volume import VOLUME_LAYERS

# Memory a heightfield texel costs on its way to the GPU: heightfield_volume's float64 slices,
# volume_texture's float RGBA copy and its RGBA8 subslices peak at about 870 bytes per texel with
# 16 layers (measured with tracemalloc), against the 16 of a decoded image; read_image's budget
# counts this. On the GPU a texel then takes 61 RGBA8 subslices with their mipmaps, about 325
# bytes.
HEIGHTFIELD_BYTES_PER_TEXEL = VOLUME_LAYERS * 64
HEIGHTFIELD_GPU_BYTES_PER_TEXEL = 325


def load_heightfield(path: Path, where: str | None = None) -> np.ndarray:
    """First channel of an image as heights (values are used as stored: no sRGB decoding);
    ``InputError`` naming the file (and ``where``) for a bad or too large image."""
    return read_image(path, where=where, bytes_per_pixel=HEIGHTFIELD_BYTES_PER_TEXEL)[..., 0]


def heightfield_volume(heights: np.ndarray, layers: int = VOLUME_LAYERS,
                       softness: float = 0.1) -> np.ndarray:
    """A heightfield image (strand height per texel, Revie 2.4.1) as a volume: a texel is covered
    in the slices below its height, faded over ``softness`` as the chapter's smoothstep."""
    h = (np.arange(layers) + 0.5) / layers
    t = np.clip((h[:, None, None] - (heights[None] - softness)) / softness, 0.0, 1.0)
    coverage = 1.0 - t * t * (3.0 - 2.0 * t)
    volume = np.stack([coverage, np.ones_like(coverage)], -1).astype(np.float32)
    return volume
