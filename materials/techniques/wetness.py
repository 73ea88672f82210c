"""The wetness mask (Silva et al., "Curling and Clumping Fur Represented by Texture Layers",
section 3.1, Algorithm 1): a texture over the mesh's UVs whose texels say which clump of wet fur
they belong to: (R, G) the clump centre, B its radius (both in UV units), A the wetness rho.

Droplets are blended in one at a time with Algorithm 1, over the texels the droplet covers (UV
distance to its centre at most its radius). A droplet whose centre is within its radius of a
texel's clump centre joins that clump (centre and radius move toward the droplet's by its share
of the wetness, the wetness adds up); any other texel it covers becomes part of a new clump: the
droplet's. Dry texels hold no clump: their centre lies far outside UV space (``DRY_CENTRE``), so a
droplet never mistakes the UV origin for the centre of a dry texel's clump, and a texel whose
wetness dries to 0 is reset to dry (drying brings the curl back and dissolves the clump).

The array is (size, size, 4) float32, row ``i`` at ``v = (i + 0.5) / size`` (GL's texel order:
uploaded as it is), column ``j`` at ``u = (j + 0.5) / size``. Where a mesh's UVs wrap around
(the cylindrical unwrap of a sphere or torus: :func:`uv_wrap`), distances in that direction are
taken round the cylinder, so a droplet on the seam wets both sides and its clump is whole.

A mesh cut into several UV charts (an xatlas unwrap) has seams between charts: an edge of the
surface that the two triangles beside it put at different places in UV space. A droplet fallen
near one (``uv_seams.UVSeams``) is blended into the chart across it too, its centre carried over the
edge by the map that takes that edge's UVs on one side to its UVs on the other (a similarity,
mirrored where the charts are), so the clump goes on across the seam instead of being cut at the
chart's edge. Each droplet only wets texels of its own chart (the texels the chart covers and a
gutter around it), never a neighbouring chart that is far away on the surface but packed beside
it in UV space. The charts and their seams are ``uv_seams.py``'s.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

from deferred.api import InputError, MeshData, check_image, read_image

from .topology import weld

DRY_CENTRE = -8.0  # the (R, G) of a dry texel: no clump centre is ever within reach of it
BLEND_BAND_TEXELS = 1 << 18  # texels blended at once (a dozen float64 arrays of them)


@dataclass(frozen=True)
class Droplet:
    """A droplet in the mask's UV space: centre (u, v), radius (UV units), wetness in [0, 1]."""

    centre: tuple[float, float]
    radius: float
    wetness: float
    face: int = -1  # the triangle it fell on (:func:`random_droplets`); -1: not known


def dry_mask(size: int) -> np.ndarray:
    """A mask of dry fur: no clumps, wetness 0."""
    mask = np.zeros((size, size, 4), np.float32)
    mask[..., 0:2] = DRY_CENTRE
    return mask


def wrap_delta(delta: np.ndarray, wrap: tuple[bool, bool]) -> np.ndarray:
    """``delta`` (..., 2) in UV units, taken the short way round on wrapped axes."""
    out = np.array(delta, dtype=np.float64)
    for axis in (0, 1):
        if wrap[axis]:
            out[..., axis] -= np.round(out[..., axis])
    return out


def _texel_range(centre: float, radius: float, size: int, wrap: bool) -> np.ndarray:
    """Indices of the texels whose centres can lie within ``radius`` of ``centre`` (wrapped
    axes: possibly outside 0 .. size - 1, to be taken modulo size)."""
    first, last = int(np.floor((centre - radius) * size)), int(np.ceil((centre + radius) * size))
    if wrap:
        return np.arange(first, min(last, first + size))
    return np.arange(max(first, 0), min(last, size))


class SeamCopies(Protocol):
    """Where droplets are copied across a mesh's UV seams (``uv_seams.UVSeams``)."""

    def copies(self, droplet: Droplet) -> list[tuple[Droplet, int]]: ...


def footprint_texels(droplets: list[Droplet], size: int,
                     wrap: tuple[bool, bool] = (False, False),
                     seams: SeamCopies | None = None) -> int:
    """The texels :func:`blend_droplet` visits for ``droplets`` on a mask of ``size``: the work
    of blending them, which grows with each droplet's radius squared; with ``seams``, their
    copies across chart seams (``UVSeams.copies``) counted too."""
    total = 0
    if seams is not None:
        droplets = [copy for droplet in droplets for copy, _ in seams.copies(droplet)]
    for droplet in droplets:
        columns = _texel_range(droplet.centre[0], droplet.radius, size, wrap[0])
        rows = _texel_range(droplet.centre[1], droplet.radius, size, wrap[1])
        total += len(columns) * len(rows)
    return total


def blend_droplet(mask: np.ndarray, droplet: Droplet,
                  wrap: tuple[bool, bool] = (False, False),
                  charts: np.ndarray | None = None, chart: int = -1) -> None:
    """Blend ``droplet`` into ``mask`` in place with Algorithm 1, at every texel it covers;
    ``wrap``: whether the UVs wrap around in u, in v; with ``charts`` (each texel's chart,
    ``UVSeams.chart_texels``) and a ``chart`` other than -1, only that chart's texels."""
    size = mask.shape[0]
    cu, cv = droplet.centre
    r = droplet.radius
    columns = _texel_range(cu, r, size, wrap[0])
    rows = _texel_range(cv, r, size, wrap[1])
    if len(columns) == 0 or len(rows) == 0:
        return
    # a band of rows at a time: each texel's update is its own, and a droplet covering a
    # 4096^2 mask would otherwise hold a dozen float64 copies of it at once (2.7 GB)
    band = max(1, BLEND_BAND_TEXELS // len(columns))
    for first in range(0, len(rows), band):
        _blend_block(mask, rows[first:first + band], columns, droplet, wrap,
                     None if charts is None or chart < 0 else (charts, chart))


def _blend_block(mask: np.ndarray, rows: np.ndarray, columns: np.ndarray, droplet: Droplet,
                 wrap: tuple[bool, bool], only: tuple[np.ndarray, int] | None = None) -> None:
    """Algorithm 1 over the texels of ``rows`` x ``columns`` (texel indices, possibly outside
    the mask on wrapped axes, taken modulo its size)."""
    size = mask.shape[0]
    cu, cv = droplet.centre
    r = droplet.radius
    index = np.ix_(rows % size, columns % size)
    block = mask[index]
    u = (columns + 0.5) / size
    v = (rows + 0.5) / size
    covered = (u[None, :] - cu) ** 2 + (v[:, None] - cv) ** 2 <= r * r
    if only is not None:
        covered &= only[0][index] == only[1]

    c_mask = block[..., 0:2].astype(np.float64)
    r_mask = block[..., 2].astype(np.float64)
    rho_mask = block[..., 3].astype(np.float64)
    c_drop = np.array([cu, cv])
    rho_drop = droplet.wetness
    # the texel's centre seen from the droplet's, the short way round wrapped axes
    toward = wrap_delta(c_mask - c_drop, wrap)
    near = np.linalg.norm(toward, axis=-1) <= r  # ||c_mask - c_drop|| <= r_drop
    # joins the texel's clump where that clump is wet
    joins = covered & near & (rho_mask != 0.0)
    rho_total = np.clip(rho_mask + rho_drop, 0.0, 1.0)
    merge = joins & (rho_total != 0.0)
    alpha = np.where(merge, rho_drop / np.where(rho_total != 0.0, rho_total, 1.0), 0.0)
    # (1 - alpha) c_mask + alpha c_drop, along the short way between them
    new_c = c_drop + (1.0 - alpha)[..., None] * toward
    for axis in (0, 1):
        if wrap[axis]:
            new_c[..., axis] %= 1.0
    new_r = (1.0 - alpha) * r_mask + alpha * r
    # a new clump (the droplet's) where the texel's centre is out of reach
    replace = covered & ~near
    block[..., 0:2] = np.where(merge[..., None], new_c, block[..., 0:2])
    block[..., 2] = np.where(merge, new_r, block[..., 2])
    block[..., 3] = np.where(joins, rho_total, block[..., 3])
    block[..., 0:2] = np.where(replace[..., None], c_drop, block[..., 0:2])
    block[..., 2] = np.where(replace, r, block[..., 2])
    block[..., 3] = np.where(replace, rho_drop, block[..., 3])
    _reset_dry(block)
    mask[index] = block


def _reset_dry(mask: np.ndarray) -> None:
    dry = mask[..., 3] <= 0.0
    mask[..., 0:2][dry] = DRY_CENTRE
    mask[..., 2][dry] = 0.0
    mask[..., 3][dry] = 0.0


def dry_out(mask: np.ndarray, amount: float) -> None:
    """Lower every texel's wetness by ``amount`` (drying); texels reaching 0 become dry."""
    if amount <= 0.0:
        return
    wet = mask[..., 3] > 0.0
    mask[..., 3][wet] = np.maximum(mask[..., 3][wet] - amount, 0.0)
    _reset_dry(mask)


def uv_wrap(mesh: MeshData, tolerance: float = 1e-3) -> tuple[bool, bool]:
    """Whether the mesh's UVs wrap around in u and in v: a vertex split at a seam has copies
    whose u (v) differ by 1 (a cylindrical unwrap, as the built-in sphere and torus have)."""
    welded = weld(mesh.positions)
    uvs = np.asarray(mesh.uvs, np.float64)
    order = np.argsort(welded, kind="stable")
    same = welded[order][1:] == welded[order][:-1]
    delta = np.abs(uvs[order][1:] - uvs[order][:-1])[same]
    return tuple(bool(np.any(np.abs(delta[:, axis] - 1.0) < tolerance)) for axis in (0, 1))


def uv_scale(mesh: MeshData, model: np.ndarray) -> np.ndarray:
    """World units per UV unit of each triangle (sqrt of world area over UV area); 0 where the
    triangle has no UV area."""
    faces = np.asarray(mesh.indices, dtype=np.int64).reshape(-1, 3)
    world = np.asarray(mesh.positions, np.float64) @ model[:3, :3].T
    p = world[faces]
    t = np.asarray(mesh.uvs, np.float64)[faces]
    world_area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=-1)
    e1, e2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    uv_area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    return np.where(uv_area > 1e-12, np.sqrt(world_area / np.maximum(uv_area, 1e-12)), 0.0)


def mean_uv_scale(mesh: MeshData, model: np.ndarray) -> float:
    """World units per UV unit over the whole mesh: sqrt(world area / UV area)."""
    faces = np.asarray(mesh.indices, dtype=np.int64).reshape(-1, 3)
    world = np.asarray(mesh.positions, np.float64) @ model[:3, :3].T
    p = world[faces]
    t = np.asarray(mesh.uvs, np.float64)[faces]
    world_area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]),
                                      axis=-1).sum()
    e1, e2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    uv_area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()
    if uv_area <= 1e-12:
        raise InputError(f"mesh {mesh.name} has no UV area for fur over its UVs "
                         "(fur_mapping = \"triplanar\" needs none)")
    return float(np.sqrt(world_area / uv_area))


def random_droplets(mesh: MeshData, model: np.ndarray, count: int, radius: float,
                    wetness: float, seed: int, start: int = 0) -> list[Droplet]:
    """Droplets ``start .. start + count - 1`` of the object's seeded sequence: each hits the
    surface at a uniformly random point (by world area), with a radius of ``radius`` world units
    times a random 0.7 .. 1, converted to UV units by the hit triangle's UV scale."""
    if count <= 0:
        return []
    faces = np.asarray(mesh.indices, dtype=np.int64).reshape(-1, 3)
    world = np.asarray(mesh.positions, np.float64) @ model[:3, :3].T
    p = world[faces]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=-1)
    scale = uv_scale(mesh, model)
    weights = np.where(scale > 0.0, area, 0.0)
    if weights.sum() <= 0.0:
        raise InputError(f"mesh {mesh.name} has no UV area for droplets to land on")
    # four numbers per droplet, drawn in sequence order: droplet k is the same whatever the
    # batch it falls in
    rng = np.random.default_rng([seed, 0x5EED])
    numbers = rng.uniform(0.0, 1.0, (start + count, 4))[start:]
    cumulative = np.cumsum(weights / weights.sum())
    tri = np.minimum(np.searchsorted(cumulative, numbers[:, 0], side="right"), len(faces) - 1)
    a, b = numbers[:, 1], numbers[:, 2]
    flip = a + b > 1.0
    a, b = np.where(flip, 1.0 - a, a), np.where(flip, 1.0 - b, b)
    jitter = 0.7 + 0.3 * numbers[:, 3]
    uv = np.asarray(mesh.uvs, np.float64)[faces[tri]]
    centres = uv[:, 0] + a[:, None] * (uv[:, 1] - uv[:, 0]) + b[:, None] * (uv[:, 2] - uv[:, 0])
    radii = radius * jitter / scale[tri]
    return [Droplet((float(c[0]), float(c[1])), float(r), float(wetness), int(t))
            for c, r, t in zip(centres, radii, tri, strict=True)]


def read_mask_image(path: Path) -> np.ndarray:
    """A wetness mask image's pixels, (H, W, 4) RGBA as stored (no sRGB decoding), top row
    first; ``InputError`` unless it has the four channels (an RGB image is not a mask with
    wetness 1 everywhere)."""
    _, _, channels = check_image(path)  # the header only: a mask is refused before decoding
    if channels < 4:
        raise InputError(f"wetness mask {path.name} needs 4 channels (R, G centre, B radius, "
                         f"A wetness), it has {channels}")
    # unassociated: the colour channels are data, not colour premultiplied by the alpha
    return read_image(path, unassociated_alpha=True)


def load_wetness_mask(path: Path, size: int) -> np.ndarray:
    """A wetness mask image (R, G clump centre, B radius, A wetness; as stored, no sRGB
    decoding; top row first as images are) as a mask array of ``size``. Texels of wetness 0 are
    dry. The image is resampled (nearest) to ``size``: centres must never be interpolated."""
    pixels = read_mask_image(path)
    height, width = pixels.shape[:2]
    rows = (np.arange(size) + 0.5) / size * height
    cols = (np.arange(size) + 0.5) / size * width
    # the image's top row is v = 1: the mask's last row
    image_rows = (height - 1 - np.floor(rows).astype(int)).clip(0, height - 1)
    image_cols = np.floor(cols).astype(int).clip(0, width - 1)
    mask = np.ascontiguousarray(pixels[image_rows][:, image_cols, :4], dtype=np.float32)
    if not np.isfinite(mask).all():
        raise InputError(f"wetness mask {path.name} holds values that are not finite")
    mask[..., 3] = np.clip(mask[..., 3], 0.0, 1.0)
    _reset_dry(mask)
    return mask


def mask_image(mask: np.ndarray) -> np.ndarray:
    """The mask as an image to save (top row first, dry texels black): the inverse of
    :func:`load_wetness_mask` for masks of wet texels with centres in [0, 1]."""
    image = mask[::-1].copy()
    dry = image[..., 3] <= 0.0
    image[dry] = 0.0
    return image
