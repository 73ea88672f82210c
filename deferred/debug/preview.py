"""Looking at buffers: display colours for any target, false colour, labelled contact sheets.

Everything here turns float buffers (top row first) into RGB in [0, 1] for PNG previews; the
values themselves go to EXR unchanged (:mod:`deferred.debug.dump`). Normals show as
``N * 0.5 + 0.5``, depths through the ``turbo`` colour map over the covered range, material ids
as categorical colours (0, the background, is black).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from deferred.gbuffer.layout import (
    ALBEDO_SPECULAR,
    DEPTH,
    LINEAR_DEPTH,
    MOTION,
    NORMAL_EXPONENT_ID,
    octahedral_decode,
)
from deferred.gl.target_spec import TargetSpec
from deferred.gl.targets import COMPOSITE, FINAL, LIGHT_ACCUMULATION
from deferred.io.images import srgb_encode

BACKGROUND = 0.12  # contact sheet grey
TEXT = 0.9


@dataclass(frozen=True)
class Tile:
    title: str  # first label line (the pass)
    subtitle: str  # second label line (the buffer)
    rgb: np.ndarray  # (H, W, 3) float in [0, 1], top row first


# -- colour maps -------------------------------------------------------------------------------
# Turbo (Mikhailov, Google, 2019; Apache-2.0) at 256 evenly spaced points, float32 RGB: the
# table matplotlib's ``colormaps["turbo"]`` gives, stored so that no plotting library is needed.
TURBO_FILE = Path(__file__).with_name("turbo.npy")
# matplotlib's "tab10" (Tableau 10): categorical colours for ids
TAB10 = np.array([[0x1F, 0x77, 0xB4], [0xFF, 0x7F, 0x0E], [0x2C, 0xA0, 0x2C], [0xD6, 0x27, 0x28],
                  [0x94, 0x67, 0xBD], [0x8C, 0x56, 0x4B], [0xE3, 0x77, 0xC2], [0x7F, 0x7F, 0x7F],
                  [0xBC, 0xBD, 0x22], [0x17, 0xBE, 0xCF]], dtype=np.float32) / 255.0


@lru_cache(maxsize=1)
def _turbo() -> np.ndarray:
    table = np.load(TURBO_FILE)
    table.setflags(write=False)
    return table


def tonemap(hdr: np.ndarray, method: str = "aces", exposure: float = 1.0) -> np.ndarray:
    """numpy twin of ``post/tonemap.frag``: exposure, tone map, sRGB encode."""
    color = np.maximum(np.asarray(hdr, dtype=np.float32)[..., :3], 0.0) * exposure
    if method == "reinhard":
        color = color / (1.0 + color)
    elif method == "aces":
        color = np.clip((color * (2.51 * color + 0.03)) / (color * (2.43 * color + 0.59) + 0.14),
                        0.0, 1.0)
    return srgb_encode(color).astype(np.float32)


def normal_colors(normals: np.ndarray, covered: np.ndarray) -> np.ndarray:
    rgb = np.clip(normals * 0.5 + 0.5, 0.0, 1.0)
    return np.where(covered[..., None], rgb, 0.0).astype(np.float32)


def depth_colors(depth: np.ndarray, covered: np.ndarray) -> np.ndarray:
    """Turbo over the covered range (near blue, far red); uncovered pixels black."""
    rgb = np.zeros(depth.shape + (3,), np.float32)
    if covered.any():
        lo, hi = float(depth[covered].min()), float(depth[covered].max())
        t = (depth - lo) / (hi - lo) if hi > lo else np.zeros_like(depth)
        index = np.clip(np.nan_to_num(t) * 255.0, 0, 255).astype(np.int32)
        rgb[covered] = _turbo()[index[covered]]
    return rgb


def heat_colors(values: np.ndarray, peak: float | None = None) -> np.ndarray:
    """Turbo from 0 to ``peak``, by default the largest finite value (infinite ones at the
    top); exact 0 black. (A band of a larger image is coloured with the image's peak.)"""
    values = np.asarray(values, dtype=np.float32)
    finite = np.isfinite(values)
    if peak is None:
        peak = float(values[finite].max()) if finite.any() else 0.0
    t = np.where(finite, values / peak if peak > 0.0 else 0.0, 1.0)
    rgb = _turbo()[np.clip(t * 255.0, 0, 255).astype(np.int32)]
    return np.where((values != 0.0)[..., None], rgb, 0.0).astype(np.float32)


def id_colors(ids: np.ndarray) -> np.ndarray:
    """Categorical colours by integer id; 0 (background) black."""
    palette = TAB10
    index = np.rint(np.nan_to_num(ids)).astype(np.int64)
    rgb = palette[(np.maximum(index, 1) - 1) % len(palette)]
    return np.where((index > 0)[..., None], rgb, 0.0).astype(np.float32)


def grey(values: np.ndarray) -> np.ndarray:
    """Values already in [0, 1] as they are; anything else stretched over its own range."""
    v = np.nan_to_num(np.asarray(values, dtype=np.float32))
    lo, hi = float(v.min()), float(v.max())
    if lo < 0.0 or hi > 1.0:
        v = (v - lo) / (hi - lo) if hi > lo else np.zeros_like(v)
    return np.repeat(v[..., None], 3, axis=2)


def target_views(name: str, pixels: np.ndarray, spec: TargetSpec, tonemap_method: str = "aces",
                 exposure: float = 1.0) -> list[tuple[str, np.ndarray]]:
    """Display images of one target's raw contents: [(label, RGB)], known targets decoded."""
    if name == ALBEDO_SPECULAR:
        return [("albedo", srgb_encode(pixels[..., :3]).astype(np.float32))]
    if name == NORMAL_EXPONENT_ID:
        covered = pixels[..., 3] > 0.0
        normals = octahedral_decode(pixels[..., :2]).astype(np.float32)
        return [("normal", normal_colors(normals, covered)), ("material id",
                                                              id_colors(pixels[..., 3]))]
    if name == LINEAR_DEPTH:
        return [("linear depth", depth_colors(pixels[..., 0], pixels[..., 0] > 0.0))]
    if spec.depth or name == DEPTH:
        return [("depth", depth_colors(pixels[..., 0], pixels[..., 0] < 1.0))]
    if name in (LIGHT_ACCUMULATION, COMPOSITE):
        return [("tone mapped", tonemap(pixels, tonemap_method, exposure))]
    if name == FINAL:
        return [("", np.clip(pixels[..., :3], 0.0, 1.0))]
    if name == MOTION:
        return [motion_colors(pixels[..., :2])]
    components = pixels.shape[2]
    if components == 1:
        return [("", grey(pixels[..., 0]))]
    rgb = np.zeros(pixels.shape[:2] + (3,), np.float32)
    rgb[..., : min(components, 3)] = pixels[..., :3]
    return [("", np.clip(rgb, 0.0, 1.0))]


def motion_colors(motion: np.ndarray) -> tuple[str, np.ndarray]:
    """Motion vectors as colours: grey where still, x to red (right) or cyan (left), y to
    green (up) or magenta (down), full at the 99th percentile of the lengths; the label says
    that length in pixels."""
    lengths = np.linalg.norm(motion, axis=-1)
    scale = max(float(np.percentile(lengths, 99)), 1e-3)
    rgb = np.empty(motion.shape[:2] + (3,), np.float32)
    rgb[..., 0] = 0.5 + 0.5 * motion[..., 0] / scale
    rgb[..., 1] = 0.5 + 0.5 * motion[..., 1] / scale
    rgb[..., 2] = 0.5 - 0.25 * (motion[..., 0] + motion[..., 1]) / scale
    return f"motion (full at {scale:.3g} px)", np.clip(rgb, 0.0, 1.0)


def to_uint8(rgb: np.ndarray) -> np.ndarray:
    return np.clip(np.rint(np.asarray(rgb) * 255.0), 0, 255).astype(np.uint8)


# -- contact sheet -----------------------------------------------------------------------------
def thumbnail(rgb: np.ndarray, width: int) -> np.ndarray:
    """Shrink by a whole factor with a box filter, so a stipple pattern averages to grey
    instead of aliasing away."""
    height_px, width_px = rgb.shape[:2]
    factor = max(1, width_px // width)
    if factor == 1:
        return rgb
    h, w = height_px // factor, width_px // factor
    blocks = rgb[: h * factor, : w * factor].reshape(h, factor, w, factor, rgb.shape[2])
    return blocks.mean(axis=(1, 3))


@lru_cache(maxsize=4)
def _font(pixels: int):
    """Pillow's bundled font (a scalable one where Pillow has FreeType), so labels look the
    same on every machine."""
    from PIL import ImageFont

    return ImageFont.load_default(size=pixels)


WORD_SPACE = 0.45  # the gap between words, in text heights


def text_mask(text: str, pixels: int = 12) -> np.ndarray | None:
    """Coverage (H, W) in [0, 1] of ``text`` rendered ``pixels`` high; None if no font.
    A glyph the font lacks (CJK in an object's name) is drawn as a box. Words are drawn
    ``WORD_SPACE`` x ``pixels`` apart: the bundled font's own space, a fifth of its height,
    rounds to 2 pixels at label sizes, where "without self" read as one word."""
    if not text:
        return None
    from PIL import Image, ImageDraw

    try:
        font = _font(pixels)
        bottom = font.getbbox(text)[3]
        space = max(font.getlength(" "), WORD_SPACE * pixels)
        starts, x = [], 0.0
        for word in text.split(" "):
            starts.append((round(x), word))
            x += font.getlength(word) + space
        right = max((start + font.getbbox(word)[2] for start, word in starts if word),
                    default=0)
        if right <= 0 or bottom <= 0:
            return None
        image = Image.new("L", (right, bottom), 0)
        draw = ImageDraw.Draw(image)
        for start, word in starts:
            draw.text((start, 0), word, fill=255, font=font)
        return np.asarray(image, dtype=np.float32) / 255.0
    except (OSError, ValueError):
        return None  # a sheet without labels beats no sheet


def labelled(image: np.ndarray, text: str, pixels: int = 12,
             color: tuple[int, int, int] = (255, 255, 255),
             box: tuple[int, int, int] | None = (0, 0, 0)) -> np.ndarray:
    """A copy of ``image`` (H, W, 3) uint8 with ``text`` in its top left corner, in
    ``color`` on a ``box`` of that colour (None: on the image): the figure scripts'
    labels."""
    picture = np.array(image, dtype=np.uint8)[..., :3].copy()
    mask = text_mask(text, pixels)
    if mask is None:
        return picture
    pad = max(pixels // 4, 2)
    height, width = mask.shape[0] + 2 * pad, mask.shape[1] + 2 * pad
    if box is not None:
        picture[:height, :width] = box
    mask = mask[: picture.shape[0] - pad, : picture.shape[1] - pad, None]
    region = picture[pad: pad + mask.shape[0], pad: pad + mask.shape[1]].astype(np.float32)
    blended = region * (1.0 - mask) + np.asarray(color, np.float32) * mask
    picture[pad: pad + mask.shape[0], pad: pad + mask.shape[1]] = np.round(blended)
    return picture


def _draw_text(sheet: np.ndarray, text: str, x: int, y: int, width: int) -> None:
    mask = text_mask(text)
    if mask is None:
        return
    mask = mask[: max(0, sheet.shape[0] - y), : max(0, min(width, sheet.shape[1] - x))]
    region = sheet[y: y + mask.shape[0], x: x + mask.shape[1]]
    region[:] = region * (1.0 - mask[..., None]) + TEXT * mask[..., None]


def contact_sheet(tiles: Sequence[Tile], thumb_width: int = 240, columns: int = 6) -> np.ndarray:
    """Tiles in order, left to right, top to bottom, each under a two-line label; uint8 RGB."""
    if not tiles:
        return np.full((16, 16, 3), to_uint8(BACKGROUND), np.uint8)
    thumbs = [thumbnail(tile.rgb, thumb_width) for tile in tiles]
    cell_w = max(t.shape[1] for t in thumbs)
    cell_h = max(t.shape[0] for t in thumbs)
    label_h, pad = 32, 6
    columns = min(columns, len(tiles))
    rows = -(-len(tiles) // columns)
    sheet = np.full((rows * (cell_h + label_h + pad) + pad, columns * (cell_w + pad) + pad, 3),
                    BACKGROUND, np.float32)
    for k, (tile, thumb) in enumerate(zip(tiles, thumbs, strict=True)):
        x = pad + (k % columns) * (cell_w + pad)
        y = pad + (k // columns) * (cell_h + label_h + pad)
        _draw_text(sheet, tile.title, x, y, cell_w)
        _draw_text(sheet, tile.subtitle, x, y + label_h // 2, cell_w)
        sheet[y + label_h: y + label_h + thumb.shape[0], x: x + thumb.shape[1]] = thumb
    return to_uint8(sheet)
