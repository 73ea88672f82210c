"""Tonal art maps and hatching (Costigan, "Cartoon Hair Simulation", 2.4.3 and 4.3.8, after Praun
et al., "Real-time hatching", SIGGRAPH 2001).

A tonal art map (TAM) is a row of hatching images of rising tone, each with its own mip levels
(the thesis: 6 tones x 3 mips at 512x512, 78 strokes, 10 candidates; Table 5.1). It is made
from one stroke image (the thesis' appendix Fig. 6; here a soft-ended dark line unless an image
is given) by adding strokes one at a time:

- **candidates** (2.4.3, 4.3.8): each stroke is the best of ``candidates`` random ones, the one
  that adds most tone per unit of its own ink (a stroke over paper beats one over strokes), which
  spreads strokes evenly (the thesis' appendix Figs. 7-9);
- **nesting** (4.3.8): a darker tone starts from the lighter tone's images and only adds
  strokes, so every stroke of a lighter tone is in every darker one;
- **mip levels** (2.4.3, 4.3.8): a stroke spans the same fraction of the tile at every level but
  is drawn at the same width in pixels, not downsampled; each coarser level follows the finest
  level's tone, taking a stroke only where that brings it closer, so it holds fewer strokes
  ("custom mipmaps which drop strokes", 4.3.8); a candidate's worth is averaged over the levels
  that take it;
- **tiling** (4.3.8, Figs. 4.21-4.22): a stroke crossing an edge continues from the opposite
  edge, the thesis' hidden extra stroke; here every pixel index wraps, so the two are one.

Tones are spread evenly in ink: the darkest tone holds ``strokes`` strokes at the finest level,
shared among the tones by the expected coverage of strokes placed at random, so each tone adds
about the same ink. Generation is deterministic for a seed; ``hatching.py`` caches it on disk
(``hatching.tonal_art_map``) and gives it to the GPU.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from deferred.api import InputError, read_image

# Bumped whenever the generator's output for the same settings changes (part of the cache key).
GENERATOR_VERSION = 1
DEFAULT_STROKE_SHAPE = (32, 256)  # samples across and along the default stroke
WHERE = "hatching"


@dataclass(frozen=True)
class TamSettings:
    """What a tonal art map is made of (the defaults: the thesis' Table 5.1 row, 512x512, 6
    tones x 3 mips, 78 strokes, 10 candidates)."""

    size: int = 512  # the finest level's side in pixels; a multiple of 2^(mips - 1)
    tones: int = 6
    mips: int = 3
    strokes: int = 78  # strokes of the darkest tone at the finest level
    candidates: int = 10  # random candidates per stroke, the best kept
    seed: int = 0
    stroke_length: float = 0.5  # fraction of the tile's side, the same at every level
    stroke_width: float = 6.0  # pixels, the same at every level
    angle: float = 0.0  # degrees from the texture's u axis
    angle_jitter: float = 8.0  # degrees, uniform either side of ``angle``
    length_jitter: float = 0.25  # relative, uniform either side of ``stroke_length``
    cross_from: int | None = None  # tones from this index on hatch across (angle + 90 degrees)

    def check(self) -> None:
        """Raise :class:`InputError` naming the first setting out of range."""
        def need(ok: bool, key: str, what: str) -> None:
            if not ok:
                raise InputError(f"{key} {what}, got {getattr(self, key)!r}", WHERE)

        for key in ("size", "tones", "mips", "strokes", "candidates", "seed"):
            value = getattr(self, key)
            need(isinstance(value, int | np.integer) and not isinstance(value, bool),
                 key, "must be an integer")
        need(1 <= self.mips <= 8, "mips", "must be within [1, 8]")
        need(16 <= self.size <= 4096, "size", "must be within [16, 4096]")
        need(self.size % (1 << (self.mips - 1)) == 0, "size",
             f"must be a multiple of 2^(mips - 1) = {1 << (self.mips - 1)}")
        need(1 <= self.tones <= 64, "tones", "must be within [1, 64]")
        need(self.tones <= self.strokes <= 100_000, "strokes",
             f"must be within [tones = {self.tones}, 100000]")
        need(1 <= self.candidates <= 1000, "candidates", "must be within [1, 1000]")
        need(0.0 < self.stroke_length <= 0.9, "stroke_length", "must be within (0, 0.9]")
        need(0.5 <= self.stroke_width <= 64.0, "stroke_width", "must be within [0.5, 64]")
        need(0.0 <= self.angle_jitter <= 45.0, "angle_jitter", "must be within [0, 45]")
        need(0.0 <= self.length_jitter < 1.0, "length_jitter", "must be within [0, 1)")
        need(math.isfinite(self.angle), "angle", "must be finite")
        need(self.cross_from is None or 0 <= self.cross_from < self.tones, "cross_from",
             f"must be a tone index within [0, {self.tones - 1}] or None")
        coarsest = int(self.size) >> (int(self.mips) - 1)
        need(1.5 * self.stroke_width + 8 < coarsest, "stroke_width",
             f"must fit the coarsest level ({coarsest} px) across")
        longest = self.stroke_length * (1.0 + self.length_jitter) * coarsest
        need(longest + self.stroke_width + 4 < coarsest, "stroke_length",
             f"with stroke_width, must fit the coarsest level ({coarsest} px)")


@dataclass(frozen=True, eq=False)
class ToneArtMap:
    """A tonal art map: ``levels[m]`` is mip level m, (tones, size >> m, size >> m) uint8 ink
    (0 paper, 255 full ink), tone 0 the lightest; row 0 lies at v = 0 (the GL convention)."""

    levels: tuple[np.ndarray, ...]

    @property
    def tones(self) -> int:
        return int(self.levels[0].shape[0])

    @property
    def size(self) -> int:
        return int(self.levels[0].shape[1])

    @property
    def mips(self) -> int:
        return len(self.levels)

    @property
    def gutter(self) -> int:
        """The wrapped border of each atlas cell at level 0: one texel at the coarsest level."""
        return 1 << (self.mips - 1)

    def ink(self, level: int = 0) -> np.ndarray:
        """Level ``level`` as float32 ink in [0, 1]."""
        return self.levels[level].astype(np.float32) / 255.0

    def atlas(self, level: int = 0) -> np.ndarray:
        """Level ``level`` of the GPU atlas: the tones side by side in cells of side
        ``(size + 2 gutter) >> level``, each tone padded by its own wrapped pixels, uint8
        (rows, columns), row 0 at v = 0."""
        pad = self.gutter >> level
        cells = np.pad(self.levels[level], ((0, 0), (pad, pad), (pad, pad)), mode="wrap")
        return np.ascontiguousarray(np.concatenate(list(cells), axis=1))


# -- the stroke ---------------------------------------------------------------------------------

def default_stroke(shape: tuple[int, int] = DEFAULT_STROKE_SHAPE) -> np.ndarray:
    """A soft-ended dark line, (rows across, columns along) float32 ink in [0, 1]: full width in
    the middle, thinning and fading toward both ends as a pen lifts (the role of the thesis'
    Fig. 6)."""
    rows, columns = shape
    along = (np.arange(columns) + 0.5) / columns
    across = np.abs((np.arange(rows) + 0.5) / rows * 2.0 - 1.0)
    pressure = np.sin(np.pi * along) ** 0.5
    edge = np.clip((pressure[None, :] - across[:, None]) / 0.3, 0.0, 1.0)
    soft = edge * edge * (3.0 - 2.0 * edge)
    return (soft * (0.8 + 0.15 * pressure[None, :])).astype(np.float32)


def load_stroke(path: str | Path) -> np.ndarray:
    """A stroke image file as ink, (rows across, columns along) float32 in [0, 1]: dark on
    light, the stroke lying along the image's width; ink = (1 - luminance) x alpha."""
    pixels = read_image(path, where=WHERE)
    luminance = pixels[..., :3] @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    return check_stroke(np.clip((1.0 - luminance) * pixels[..., 3], 0.0, 1.0), str(path))


def check_stroke(stroke: np.ndarray, where: str = WHERE) -> np.ndarray:
    """``stroke`` as contiguous float32, or an :class:`InputError` saying what is wrong."""
    array = np.asarray(stroke, dtype=np.float32)
    if array.ndim != 2 or min(array.shape) < 2:
        raise InputError(f"a stroke must be a 2D image of at least 2x2, got shape {array.shape}",
                         where)
    if not np.all(np.isfinite(array)) or array.min() < 0.0 or array.max() > 1.0:
        raise InputError("a stroke's ink must lie within [0, 1]", where)
    if array.max() <= 0.0:
        raise InputError("the stroke holds no ink (a dark stroke on a light ground is needed)",
                         where)
    return np.ascontiguousarray(array)


def resolve_stroke(stroke: np.ndarray | str | Path | None) -> np.ndarray:
    if stroke is None:
        return default_stroke()
    if isinstance(stroke, str | Path):
        return load_stroke(stroke)
    return check_stroke(stroke)


def resample(stroke: np.ndarray, rows: int, columns: int) -> np.ndarray:
    """``stroke`` at (rows, columns), area-filtered (Pillow's bilinear widens its support when
    shrinking), with one zero sample around it so that bilinear lookups fade out at its ends."""
    from PIL import Image

    image = Image.fromarray(stroke, mode="F").resize((columns, rows),
                                                     Image.Resampling.BILINEAR)
    return np.pad(np.asarray(image, np.float32), 1)


# -- the generator ------------------------------------------------------------------------------

@dataclass
class _Level:
    """One mip level while strokes are added."""

    side: int
    stroke: np.ndarray  # the stroke resampled for this level, zero-padded
    ink: np.ndarray  # (side, side) float32


def tone_stroke_counts(settings: TamSettings, ink_per_stroke: float) -> list[int]:
    """Strokes at the finest level after each tone (cumulative): the expected coverage
    1 - (1 - a)^n of n strokes of coverage a each is split evenly among the tones, so each adds
    about the same ink; every tone adds at least one stroke, the last ends at ``strokes``."""
    n, tones = settings.strokes, settings.tones
    a = min(max(ink_per_stroke, 1e-9), 0.5)
    total = 1.0 - (1.0 - a) ** n
    counts = []
    for tone in range(tones):
        coverage = total * (tone + 1) / tones
        counts.append(round(math.log1p(-coverage) / math.log1p(-a)))
    counts[-1] = n
    for tone in range(tones):  # at least one stroke each, and room for the rest
        low = counts[tone - 1] + 1 if tone else 1
        counts[tone] = min(max(counts[tone], low), n - (tones - 1 - tone))
    return counts


def _candidate_strokes(level: _Level, settings: TamSettings, centres: np.ndarray,
                       angles: np.ndarray, lengths: np.ndarray, along_u: bool):
    """The candidates' ink at one level, over the pixels near each: for each pixel column
    (``along_u``; rows otherwise) the stroke crosses, a band of pixels about its centre line.
    Returns the ink (K, P, B) and the pixels' rows and columns, wrapped into the tile
    (broadcasting to (K, P, B)); every pixel index wraps, so a stroke leaving one edge enters
    from the opposite one (4.3.8, Fig. 4.22)."""
    side, width = level.side, settings.stroke_width
    length_px = lengths * side
    cos, sin = np.cos(angles), np.sin(angles)
    # the main axis: columns for strokes nearer u, rows for those nearer v
    main_cos, cross_sin = (cos, sin) if along_u else (sin, cos)
    half_main = np.abs(main_cos) * length_px / 2 + np.abs(cross_sin) * width / 2
    main_count = 2 * math.ceil(half_main.max()) + 3
    # a stroke of width w spans w / |cos| across a column; +1.5 px for its filtered edge
    band = 2 * math.ceil((width / 2 / np.abs(main_cos)).max() + 1.5) + 1
    centre = centres * side
    main_centre, cross_centre = (centre[:, 0], centre[:, 1]) if along_u \
        else (centre[:, 1], centre[:, 0])
    main = np.floor(main_centre).astype(np.int64)[:, None] - main_count // 2 \
        + np.arange(main_count)  # (K, P)
    d_main = main + 0.5 - main_centre[:, None]
    line = cross_centre[:, None] + d_main * (cross_sin / main_cos)[:, None]  # centre line
    cross = np.floor(line).astype(np.int64)[:, :, None] - band // 2 + np.arange(band)
    d_main = d_main.astype(np.float32)[:, :, None]  # (K, P, 1)
    d_cross = (cross + 0.5 - cross_centre[:, None, None]).astype(np.float32)  # (K, P, B)
    dx, dy = (d_main, d_cross) if along_u else (d_cross, d_main)
    # stroke coordinates in samples of the level's resampled (and zero-padded) stroke: along
    # the stroke scaled by the candidate's length, across at the fixed pixel width
    stroke = level.stroke
    along_samples = stroke.shape[1] - 2
    across_samples = stroke.shape[0] - 2
    cos = cos.astype(np.float32)[:, None, None]
    sin = sin.astype(np.float32)[:, None, None]
    scale_along = (along_samples / length_px).astype(np.float32)[:, None, None]
    x = (dx * cos + dy * sin) * scale_along + np.float32(along_samples / 2 + 0.5)
    y = (dy * cos - dx * sin) * np.float32(across_samples / width) \
        + np.float32(across_samples / 2 + 0.5)
    np.clip(x, 0.0, stroke.shape[1] - 1.001, out=x)
    np.clip(y, 0.0, stroke.shape[0] - 1.001, out=y)
    xi = x.astype(np.int32)
    yi = y.astype(np.int32)
    x -= xi
    y -= yi
    flat = stroke.ravel()
    index = yi * stroke.shape[1] + xi
    top = np.take(flat, index)
    top += x * (np.take(flat, index + 1) - top)
    index += stroke.shape[1]
    bottom = np.take(flat, index)
    bottom += x * (np.take(flat, index + 1) - bottom)
    top += y * (bottom - top)
    main %= side
    cross %= side
    if along_u:
        return top, cross, main[:, :, None]
    return top, main[:, :, None], cross


def generate_tam(settings: TamSettings = TamSettings(),
                 stroke: np.ndarray | str | Path | None = None) -> ToneArtMap:
    """Make a tonal art map (no cache: :func:`tonal_art_map` is the cached one)."""
    settings.check()
    stroke = resolve_stroke(stroke)
    rng = np.random.default_rng(settings.seed)
    width = settings.stroke_width
    levels = []
    for m in range(settings.mips):
        side = settings.size >> m
        levels.append(_Level(side, resample(stroke, max(2, round(width)),
                                            max(2, round(settings.stroke_length * side))),
                             np.zeros((side, side), np.float32)))
    # the ink one stroke leaves at the finest level, as a fraction of the tile
    finest = levels[0]
    sample_area = (width / (finest.stroke.shape[0] - 2)) \
        * (settings.stroke_length * finest.side / (finest.stroke.shape[1] - 2))
    ink_per_stroke = float(finest.stroke.sum()) * sample_area / finest.side ** 2
    counts = tone_stroke_counts(settings, ink_per_stroke)
    out = [np.empty((settings.tones, level.side, level.side), np.uint8) for level in levels]
    placed = 0
    jitter = math.radians(settings.angle_jitter)
    k = settings.candidates
    darkness = np.zeros(settings.mips)  # each level's mean ink
    areas = np.array([float(level.side) ** 2 for level in levels])
    for tone, count in enumerate(counts):
        base = math.radians(settings.angle)
        if settings.cross_from is not None and tone >= settings.cross_from:
            base += math.pi / 2
        taken = np.zeros(settings.mips, bool)  # the levels this tone has added a stroke to
        for index in range(placed, count):
            centres = rng.random((k, 2))
            angles = base + rng.uniform(-jitter, jitter, k)
            lengths = settings.stroke_length * (1.0 + rng.uniform(-1.0, 1.0, k)
                                                * settings.length_jitter)
            gain = np.empty((k, settings.mips))  # tone each candidate adds at each level
            alone = np.empty((k, settings.mips))  # ... and would add on blank paper
            # candidates nearer u and nearer v are rasterised in bands of their own axis
            along_u = np.abs(np.cos(angles)) >= np.abs(np.sin(angles))
            groups = []
            for members, axis_u in ((np.flatnonzero(along_u), True),
                                    (np.flatnonzero(~along_u), False)):
                if not members.size:
                    continue
                strokes = [_candidate_strokes(level, settings, centres[members],
                                              angles[members], lengths[members], axis_u)
                           for level in levels]
                for m, (level, (ink, rows, columns)) in enumerate(zip(levels, strokes,
                                                                      strict=True)):
                    under = np.take(level.ink, rows * level.side + columns)
                    alone[members, m] = ink.sum(axis=(1, 2), dtype=np.float64) / areas[m]
                    gain[members, m] = np.einsum("kpb,kpb->k", ink, 1.0 - under,
                                                 dtype=np.float64) / areas[m]
                groups.append((members, strokes))
            target = darkness[0] + gain[:, :1]  # the finest level's tone with the candidate
            closer = np.abs(darkness + gain - target) < np.abs(darkness - target)
            closer[:, 0] = True
            if index == count - 1:  # every level darkens with every tone
                closer[:, ~taken] = True
            share = np.where(closer, gain / np.maximum(alone, 1e-12), 0.0)
            score = share.sum(axis=1) / closer.sum(axis=1)
            best = int(np.argmax(score))
            members, strokes = next(group for group in groups if best in group[0])
            within = int(np.flatnonzero(members == best)[0])
            for m, (level, (ink, rows, columns)) in enumerate(zip(levels, strokes, strict=True)):
                if closer[best, m]:
                    pixels = rows[within] * level.side + columns[within]  # unique
                    flat = level.ink.reshape(-1)
                    flat[pixels] = 1.0 - (1.0 - np.take(flat, pixels)) * (1.0 - ink[within])
                    darkness[m] += gain[best, m]
                    taken[m] = True
        placed = count
        for m, level in enumerate(levels):
            out[m][tone] = np.rint(np.clip(level.ink, 0.0, 1.0) * 255.0).astype(np.uint8)
    return ToneArtMap(tuple(out))
