"""Hatching with tonal art maps (Costigan, "Cartoon Hair Simulation", 2.4.3 and 4.3.8, after
Praun et al., "Real-time hatching", SIGGRAPH 2001): a map made once (``tam.py``: the settings,
the stroke and the generator, re-exported here) and cached on disk (:func:`tonal_art_map`), and
its lookups.

For the GPU the TAM is one 2D texture, an atlas of the tones side by side, each cell padded by a
wrapped gutter so that hardware filtering tiles seamlessly at every level
(:meth:`ToneArtMap.atlas`, :func:`tam_texture`); ``materials/techniques/hatching.glsl`` blends the
two tones nearest a lit tone, on the surface (Praun et al.) or in screen space (Lake et al.,
Fig. 4.20a). :func:`blend_tones` is the same blend in numpy.
"""

from __future__ import annotations

import hashlib
import json
import zipfile
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from deferred.api import cache_folder, write_cached_arrays

from .tam import (
    DEFAULT_STROKE_SHAPE,
    GENERATOR_VERSION,
    TamSettings,
    ToneArtMap,
    check_stroke,
    default_stroke,
    generate_tam,
    load_stroke,
    resample,
    resolve_stroke,
    tone_stroke_counts,
)

if TYPE_CHECKING:
    import moderngl

__all__ = ["DEFAULT_STROKE_SHAPE", "TamSettings", "ToneArtMap", "blend_tones", "cache_folder",
           "cache_key", "cache_path", "check_stroke", "default_stroke", "generate_tam",
           "load_stroke", "resample", "resolve_stroke", "sample_wrapped", "tam_texture",
           "tonal_art_map", "tone_blend", "tone_stroke_counts"]

CACHE_SUBFOLDER = "hatching"
DEFAULT_SETTINGS = TamSettings()  # frozen: one default for every call
FLOAT_SETTINGS = ("stroke_length", "stroke_width", "angle", "angle_jitter", "length_jitter")


# -- the cache ----------------------------------------------------------------------------------

def cache_key(settings: TamSettings, stroke: np.ndarray) -> str:
    """A hash of the generator's version, the settings and the stroke's pixels."""
    # numbers as Python's own, so 6 and 6.0 (or a numpy integer) name the same map
    values = {key: value if value is None else (float(value) if key in FLOAT_SETTINGS
                                                else int(value))
              for key, value in asdict(settings).items()}
    digest = hashlib.sha256()
    digest.update(json.dumps({"generator": GENERATOR_VERSION, **values},
                             sort_keys=True).encode())
    digest.update(repr(stroke.shape).encode())
    digest.update(np.ascontiguousarray(stroke, np.float32).tobytes())
    return digest.hexdigest()[:32]


def cache_path(settings: TamSettings, stroke: np.ndarray | str | Path | None = None,
               folder: Path | None = None) -> Path:
    """The file a TAM of these settings and stroke is cached in."""
    stroke = resolve_stroke(stroke)
    folder = cache_folder() if folder is None else Path(folder)
    return folder / CACHE_SUBFOLDER / f"tam-{cache_key(settings, stroke)}.npz"


def _read_cached(path: Path, settings: TamSettings) -> ToneArtMap | None:
    """The TAM in ``path``, or None where it is missing, unreadable or not what was asked."""
    try:
        with np.load(path, allow_pickle=False) as data:
            levels = tuple(np.array(data[f"level{m}"]) for m in range(settings.mips))
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile):
        return None
    for m, level in enumerate(levels):
        side = settings.size >> m
        if level.dtype != np.uint8 or level.shape != (settings.tones, side, side):
            return None
    return ToneArtMap(levels)


def _write_cached(path: Path, tam: ToneArtMap) -> None:
    """Write ``tam`` to ``path`` (atomically; a cache that cannot be written is skipped)."""
    write_cached_arrays(path, {f"level{m}": level for m, level in enumerate(tam.levels)})


def tonal_art_map(settings: TamSettings = DEFAULT_SETTINGS,
                  stroke: np.ndarray | str | Path | None = None,
                  cache: Path | bool = True) -> ToneArtMap:
    """The tonal art map of ``settings`` and ``stroke`` (None: :func:`default_stroke`; a path:
    an image file; an array: ink), read from the cache where it holds one, else generated and
    cached. ``cache``: True for :func:`cache_folder`, a folder, or False for none. A cache file
    that cannot be read is regenerated and replaced."""
    settings.check()
    stroke = resolve_stroke(stroke)
    if cache is False:
        return generate_tam(settings, stroke)
    path = cache_path(settings, stroke, None if cache is True else Path(cache))
    tam = _read_cached(path, settings)
    if tam is None:
        tam = generate_tam(settings, stroke)
        _write_cached(path, tam)
    return tam


# -- lookups ------------------------------------------------------------------------------------

def sample_wrapped(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Bilinear samples of a tiling ``image`` (rows, columns) at ``uv`` (..., 2), texel centres
    at (i + 0.5) / side, wrapping at every edge (what GL_REPEAT with GL_LINEAR does)."""
    rows, columns = image.shape
    x = np.asarray(uv[..., 0], np.float64) * columns - 0.5
    y = np.asarray(uv[..., 1], np.float64) * rows - 0.5
    x0 = np.floor(x)
    y0 = np.floor(y)
    fx = x - x0
    fy = y - y0
    i0 = x0.astype(np.int64) % columns
    j0 = y0.astype(np.int64) % rows
    i1 = (i0 + 1) % columns
    j1 = (j0 + 1) % rows
    top = image[j0, i0] * (1 - fx) + image[j0, i1] * fx
    bottom = image[j1, i0] * (1 - fx) + image[j1, i1] * fx
    return top * (1 - fy) + bottom * fy


def tone_blend(tone: np.ndarray, tones: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The two TAM tones nearest a lit tone in [0, 1] (1 lit: paper, 0: the darkest tone) and
    the darker one's weight: s = (1 - tone) x tones runs over paper (s = 0) and the tones
    (s = 1 ... tones); between two, their linear mix (-1 stands for paper)."""
    s = np.clip(1.0 - np.asarray(tone, np.float64), 0.0, 1.0) * tones
    darker = np.minimum(np.floor(s), tones - 1).astype(np.int64)
    return darker - 1, darker, s - darker


def blend_tones(tam: ToneArtMap, tone: np.ndarray, uv: np.ndarray, level: int = 0) -> np.ndarray:
    """Ink of the TAM at lit ``tone`` (n,) and texture coordinates ``uv`` (n, 2) at mip level
    ``level``: the two nearest tones, each sampled bilinearly with wrapping, mixed linearly
    (the blend of ``hatching_ink`` in ``materials/techniques/hatching.glsl``)."""
    tone = np.asarray(tone, np.float64)
    uv = np.asarray(uv, np.float64)
    lighter, darker, weight = tone_blend(tone, tam.tones)
    images = tam.ink(level).astype(np.float64)
    samples = np.stack([sample_wrapped(image, uv) for image in images])  # (tones, n)
    columns = np.arange(tone.shape[0])
    dark = samples[darker, columns]
    light = np.where(lighter >= 0, samples[np.maximum(lighter, 0), columns], 0.0)
    return light + weight * (dark - light)


def tam_texture(ctx: moderngl.Context, tam: ToneArtMap) -> moderngl.Texture:
    """The TAM's atlas as a single-channel texture whose mip levels are the TAM's own
    (trilinear filtering, clamped: the gutters do the wrapping). The GLSL takes it with
    ``tam.tones`` and ``tam.gutter``."""
    import moderngl

    first = tam.atlas(0)
    texture = ctx.texture((first.shape[1], first.shape[0]), 1, first.tobytes())
    texture.build_mipmaps(0, tam.mips - 1)  # allocates the levels, replaced below
    for m in range(1, tam.mips):
        level = tam.atlas(m)
        texture.write(level.tobytes(), level=m)
    texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    texture.repeat_x = texture.repeat_y = False
    return texture
