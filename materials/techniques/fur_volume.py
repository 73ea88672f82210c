"""The fur volume: a tileable stack of slices through a patch of strands (Lengyel et al. 2001,
"Real-Time Fur over Arbitrary Surfaces": the shells are slices of a volume texture made from a
geometric model of a patch of hair).

Strands are generated, seeded, over a square tile, their roots spread as blue noise
(:func:`strand_roots`). Each strand has a root position, a length (1 minus up to
``length_variation``), a random lean, a brightness and a diameter that tapers linearly from
``thickness_base`` at the root to ``thickness_tip`` at the tip (both relative to the mean spacing
between strands). Slice ``k`` of ``layers`` is the cut through the patch at height
``(k + 0.5) / layers`` of the fur layer: each texel holds the strand's
coverage of it (anti-aliased disc edges) and the strand's brightness.

The texture is a 2D array (a slice per layer) of RGBA8 holding brightness * coverage in R and
coverage in A, with mipmaps: a mip texel's alpha is the fraction of the area strands cover and
R / A their mean brightness, so distant fur averages to the right colour and density instead of
going bald (thresholding) or noisy (no filtering).

A shell at height h reads the volume between two slices, interpolated. The texture holds
``SUBSLICES`` interpolated slices per interval between two generated ones, so a shell reads one
(the nearest, ``materials/techniques/fur.glsl``) instead of two: half the filtered lookups, for
heights rounded to a quarter of the slice spacing (Silva's h = (1 + n)/N falls exactly on one for
N = 16 and 64 and every power of two).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import moderngl
import numpy as np

VOLUME_LAYERS = 16  # slices through the fur layer
SUBSLICES = 4  # texture slices per interval between two generated slices (linear in between)


@dataclass(frozen=True)
class FurPattern:
    """How a tile of strands is made (see the module documentation)."""

    strands: int = 1024  # per tile (rounded to a square number)
    thickness_base: float = 0.8  # diameter at the root / mean strand spacing
    thickness_tip: float = 0.15  # diameter at the tip / mean strand spacing
    length_variation: float = 0.35  # lengths are uniform in [1 - variation, 1]
    lean: float = 0.6  # how far a tip wanders from above its root, in strand spacings
    patches: float = 0.0  # > 0: strand length scaled by a tileable low-frequency noise
    seed: int = 1
    size: int = 256  # texels per tile side: about 8 across the spacing of fine strands
    layers: int = VOLUME_LAYERS


def pattern(name: str, **overrides) -> FurPattern:
    """A built-in pattern, with any field overridden."""
    presets = {
        "fine": FurPattern(),
        "coarse": FurPattern(strands=196, thickness_base=0.7, thickness_tip=0.2, lean=0.35),
        "patchy": FurPattern(strands=1024, patches=0.8, length_variation=0.2),
    }
    if name not in presets:
        raise ValueError(f"unknown fur pattern '{name}' (choose from {', '.join(presets)})")
    fields = {key: value for key, value in overrides.items() if value is not None}
    return FurPattern(**{**presets[name].__dict__, **fields})


def _tileable_noise(rng: np.random.Generator, size: int, cells: int) -> np.ndarray:
    """Smooth value noise in [0, 1] that tiles, ``cells`` lattice cells across."""
    lattice = rng.uniform(0.0, 1.0, (cells, cells))
    t = (np.arange(size) + 0.5) / size * cells
    i = np.floor(t).astype(int)
    f = t - i
    f = f * f * (3.0 - 2.0 * f)
    i0, i1 = i % cells, (i + 1) % cells
    rows = lattice[i0][:, i0] * (1 - f)[None, :] + lattice[i0][:, i1] * f[None, :]
    rows1 = lattice[i1][:, i0] * (1 - f)[None, :] + lattice[i1][:, i1] * f[None, :]
    return rows * (1 - f)[:, None] + rows1 * f[:, None]


ROOT_CANDIDATES = 20  # candidates per root in strand_roots


@lru_cache(maxsize=16)
def strand_roots(count: int, seed: int) -> np.ndarray:
    """(count, 2) root positions in the unit tile, spread as blue noise: Mitchell's best
    candidate, each root the one of ``ROOT_CANDIDATES`` random points farthest from the roots
    so far, distances measured across the tile's wrap. Seeded, read-only.

    Not a jittered grid: roots kept inside the cells of a grid would leave straight lanes along
    every grid line, which the triplanar mapping lines up with the object's axes (and the UV
    mapping with the UV axes), so fur seen along an axis would show a straight parting down
    to the skin (down the front of Silva Fig. 7's curled ball). Blue noise keeps the roots
    apart as evenly, with no lanes in any direction."""
    rng = np.random.default_rng([seed, 0x5EED])
    roots = np.empty((count, 2))
    roots[0] = rng.uniform(0.0, 1.0, 2)
    for i in range(1, count):
        trial = rng.uniform(0.0, 1.0, (ROOT_CANDIDATES, 2))
        d = np.abs(trial[:, None, :] - roots[None, :i, :])
        d = np.minimum(d, 1.0 - d)  # the tile wraps
        roots[i] = trial[np.argmax((d * d).sum(-1).min(axis=1))]
    roots.flags.writeable = False
    return roots


def strand_volume(p: FurPattern) -> np.ndarray:
    """(layers, size, size, 2) float32: coverage and brightness of each slice, tileable, the
    same for the same pattern (``seed``)."""
    rng = np.random.default_rng(p.seed)
    grid = max(1, round(np.sqrt(p.strands)))
    count = grid * grid
    spacing = 1.0 / grid  # tile units
    roots = strand_roots(count, p.seed)  # (y, x) in [0, 1)
    lengths = 1.0 - p.length_variation * rng.uniform(0.0, 1.0, count)
    if p.patches > 0.0:
        noise = _tileable_noise(rng, p.size, 4)
        at_root = noise[(roots[:, 0] * p.size).astype(int) % p.size,
                        (roots[:, 1] * p.size).astype(int) % p.size]
        lengths *= 1.0 - p.patches * np.clip(1.0 - 2.0 * at_root, 0.0, 1.0)
    angle = rng.uniform(0.0, 2.0 * np.pi, count)
    lean = p.lean * spacing * rng.uniform(0.3, 1.0, count)
    lean_vector = np.stack([np.sin(angle), np.cos(angle)], -1) * lean[:, None]
    brightness = rng.uniform(0.7, 1.0, count)

    size = p.size
    texel = 1.0 / size
    radius_max = 0.5 * spacing * max(p.thickness_base, p.thickness_tip)
    reach = int(np.ceil(radius_max / texel)) + 1
    offsets = np.arange(-reach, reach + 1)
    oy, ox = np.meshgrid(offsets, offsets, indexing="ij")
    volume = np.zeros((p.layers, size, size, 2), np.float32)
    for k in range(p.layers):
        h = (k + 0.5) / p.layers
        alive = lengths > h
        if not alive.any():
            continue
        t = h / lengths[alive]  # position along each strand, root 0 to tip 1
        centre = roots[alive] + lean_vector[alive] * t[:, None] ** 2  # a gentle curve
        radius = 0.5 * spacing * (p.thickness_base + (p.thickness_tip - p.thickness_base) * t)
        base = np.floor(centre / texel).astype(int)  # (n, 2)
        ty = base[:, 0, None, None] + oy[None]
        tx = base[:, 1, None, None] + ox[None]
        dy = (ty + 0.5) * texel - centre[:, 0, None, None]
        dx = (tx + 0.5) * texel - centre[:, 1, None, None]
        distance = np.sqrt(dy * dy + dx * dx)
        # Anti-aliased disc: the fraction of a texel inside the strand's cross-section.
        coverage = np.clip((radius[:, None, None] - distance) / texel + 0.5, 0.0, 1.0)
        index = ((ty % size) * size + (tx % size)).ravel()
        coverage = coverage.ravel()
        covered = np.zeros(size * size)
        np.maximum.at(covered, index, coverage)
        # brightness: the coverage-weighted mean of the strands over the texel (overlaps are few)
        weight = np.zeros(size * size)
        weighted = np.zeros(size * size)
        np.add.at(weight, index, coverage)
        np.add.at(weighted, index, coverage * np.repeat(brightness[alive], oy.size))
        volume[k, ..., 0] = covered.reshape(size, size)
        volume[k, ..., 1] = np.where(weight > 0.0, weighted / np.maximum(weight, 1e-12),
                                     1.0).reshape(size, size)
    return volume


def subslice_bytes(rgba: np.ndarray, per_interval: int = SUBSLICES) -> np.ndarray:
    """RGBA8 of ``(layers, ...)`` float slices in [0, 1] with ``per_interval - 1`` linearly
    interpolated ones between each two: ``(per_interval * (layers - 1) + 1, ...)``, slice j at
    generated slice j / per_interval (made a slice at a time: heightfield volumes are large)."""
    count = per_interval * (len(rgba) - 1) + 1
    data = np.empty((count, *rgba.shape[1:]), np.uint8)
    for j in range(count):
        below, t = divmod(j, per_interval)
        t /= per_interval
        mixed = rgba[below] if t == 0.0 else rgba[below] * np.float32(1.0 - t) + \
            rgba[below + 1] * np.float32(t)
        data[j] = np.clip(np.rint(mixed * 255.0), 0, 255)
    return data


def volume_texture(ctx: moderngl.Context, volume: np.ndarray) -> moderngl.TextureArray:
    """The volume as a mip-mapped, repeating RGBA8 2D array texture (see the module doc), with
    ``SUBSLICES`` slices per interval between two of ``volume``'s."""
    _, height, width, _ = volume.shape
    coverage, brightness = volume[..., 0], volume[..., 1]
    rgba = np.zeros((*volume.shape[:3], 4), np.float32)
    rgba[..., 0] = brightness * coverage  # premultiplied: mips average it with the coverage
    rgba[..., 3] = coverage
    data = subslice_bytes(rgba[:, ::-1])  # GL rows bottom-up
    layers = len(data)
    texture = ctx.texture_array((width, height, layers), 4, data)
    texture.build_mipmaps()
    texture.repeat_x = texture.repeat_y = True
    texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    return texture


