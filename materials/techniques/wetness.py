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
near one (:class:`UVSeams`) is blended into the chart across it too, its centre carried over the
edge by the map that takes that edge's UVs on one side to its UVs on the other (a similarity,
mirrored where the charts are), so the clump goes on across the seam instead of being cut at the
chart's edge. Each droplet only wets texels of its own chart (the texels the chart covers and a
gutter of :data:`GUTTER_TEXELS` around it), never a neighbouring chart that is far away on the
surface but packed beside it in UV space.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from deferred.api import InputError, MeshData, check_image, read_image

from .topology import weld

DRY_CENTRE = -8.0  # the (R, G) of a dry texel: no clump centre is ever within reach of it
BLEND_BAND_TEXELS = 1 << 18  # texels blended at once (a dozen float64 arrays of them)
# texels around a chart that belong to it: the 2x2 texels a bilinear lookup at the chart's edge
# reads, and Algorithm 2's displaced lookups just past it, see the chart's own clumps
GUTTER_TEXELS = 3
RASTER_BAND = 1 << 20  # (triangle, texel) candidates rasterized at once
OVERLAP_CHECK_SIZE = 256  # texels a side of the raster that finds charts overlapping


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


def footprint_texels(droplets: list[Droplet], size: int,
                     wrap: tuple[bool, bool] = (False, False),
                     seams: UVSeams | None = None) -> int:
    """The texels :func:`blend_droplet` visits for ``droplets`` on a mask of ``size``: the work
    of blending them, which grows with each droplet's radius squared; with ``seams``, their
    copies across chart seams (:meth:`UVSeams.copies`) counted too."""
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
    :meth:`UVSeams.chart_texels`) and a ``chart`` other than -1, only that chart's texels."""
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


def _union_charts(face_count: int, pairs: np.ndarray) -> np.ndarray:
    """Each face's chart (0 .. charts - 1): the faces joined through ``pairs`` of faces."""
    labels = np.arange(face_count)
    while len(pairs):
        low = np.minimum(labels[pairs[:, 0]], labels[pairs[:, 1]])
        before = labels.copy()
        np.minimum.at(labels, pairs[:, 0], low)
        np.minimum.at(labels, pairs[:, 1], low)
        while True:  # pointer jumping: every face points at its group's smallest face
            jumped = labels[labels]
            if np.array_equal(jumped, labels):
                break
            labels = jumped
        if np.array_equal(labels, before):
            break
    return np.unique(labels, return_inverse=True)[1].reshape(-1)


class UVSeams:
    """A mesh's UV charts and the seams between them (see the module's docstring).

    ``face_chart``: each triangle's chart (triangles sharing an edge with the same UVs on both
    sides are in one chart). The seam records, one per side of each seam edge between two
    charts: the chart it leaves (``source``) with the edge's UVs there (``a``, ``b``), the chart
    it enters (``target``), and the map from the first to the second (``z -> offset + scale *
    (z or conj(z))``, complex UVs, ``mirror`` where conjugated). Seams inside one chart (a
    cylinder's, which :func:`uv_wrap` takes round) are left to the wrap."""

    def __init__(self, mesh: MeshData):
        faces = np.asarray(mesh.indices, dtype=np.int64).reshape(-1, 3)
        uvs = np.asarray(mesh.uvs, np.float64)
        welded = weld(mesh.positions)
        self.face_chart = np.zeros(len(faces), np.int64)
        self.faces, self.uvs = faces, uvs
        self.mirror = np.zeros(0, bool)
        self.source = self.target = np.zeros(0, np.int64)
        self.a = self.b = self.offset = self.scale = np.zeros(0, np.complex128)
        self._solid = np.zeros(0, np.int64)
        self._charts: dict[int, np.ndarray] = {}
        self._laid_out: bool | None = None
        if len(faces) == 0:
            return
        # triangles of no area on the surface (a grid sphere's pole row) are in no chart: they
        # show nothing, and their UV area must not take texels from the charts
        p = np.asarray(mesh.positions, np.float64)[faces]
        area = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=-1)
        solid = np.flatnonzero(area > 1e-12 * max(float(np.ptp(p.reshape(-1, 3), 0).max()),
                                                  1e-30) ** 2)
        # every triangle's three edges: corner k to corner k + 1, the third corner opposite
        first = faces[solid].reshape(-1)
        second = faces[solid][:, [1, 2, 0]].reshape(-1)
        third = faces[solid][:, [2, 0, 1]].reshape(-1)
        face = np.repeat(solid, 3)
        # ordered by welded position, so both sides of an edge list its ends alike
        swap = welded[first] > welded[second]
        start = np.where(swap, second, first)
        end = np.where(swap, first, second)
        keys = np.stack([welded[start], welded[end]], -1)
        _, group, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
        group = group.reshape(-1)
        order = np.argsort(group, kind="stable")
        paired = counts[group[order]] == 2  # manifold edges: two triangles (not borders)
        order = order[paired]
        one, two = order[0::2], order[1::2]
        same = (np.abs(uvs[start[one]] - uvs[start[two]]).max(-1) < 1e-6) & \
            (np.abs(uvs[end[one]] - uvs[end[two]]).max(-1) < 1e-6)
        charts = _union_charts(len(faces), np.stack([face[one], face[two]], -1)[same])
        self.face_chart = np.full(len(faces), -1, np.int64)
        self.face_chart[solid] = np.unique(charts[solid], return_inverse=True)[1].reshape(-1)
        self._solid = solid
        one, two = one[~same], two[~same]
        across = self.face_chart[face[one]] != self.face_chart[face[two]]
        one, two = one[across], two[across]
        # both directions: from side 1 into side 2, and back
        src = np.concatenate([one, two])
        dst = np.concatenate([two, one])
        z = uvs[:, 0] + 1j * uvs[:, 1]
        a1, b1, t1 = z[start[src]], z[end[src]], z[third[src]]
        a2, b2, t2 = z[start[dst]], z[end[dst]], z[third[dst]]
        edge1 = np.where(np.abs(b1 - a1) > 1e-12, b1 - a1, 1e-12)
        scale = (b2 - a2) / edge1
        # the unfolding puts the source's triangle on the far side of the edge from the
        # target's; where the plain similarity puts it beside the target's, the charts are
        # mirror images of each other
        def side(t: np.ndarray) -> np.ndarray:
            return np.sign(((b2 - a2).conj() * (t - a2)).imag)
        mirror = side(a2 + (t1 - a1) * scale) == side(t2)
        scale = np.where(mirror, (b2 - a2) / edge1.conj(), scale)
        self.source = self.face_chart[face[src]]
        self.target = self.face_chart[face[dst]]
        self.a, self.b, self.mirror, self.scale = a1, b1, mirror, scale
        self.offset = a2 - np.where(mirror, a1.conj(), a1) * scale

    @property
    def chart_count(self) -> int:
        return int(self.face_chart.max()) + 1 if len(self.face_chart) else 0

    def carry(self, record: int, centre: tuple[float, float]) -> tuple[float, float]:
        """``centre`` (UVs of seam record ``record``'s source chart) in its target chart."""
        z = complex(*centre)
        z = z.conjugate() if self.mirror[record] else z
        moved = self.offset[record] + self.scale[record] * z
        return float(moved.real), float(moved.imag)

    def copies(self, droplet: Droplet) -> list[tuple[Droplet, int]]:
        """``droplet`` in its own chart and in each chart across a seam within its radius
        (through that chart's nearest seam edge, its radius scaled as the edge's length is;
        from a copy on to the charts across its seams, so charts meeting the droplet's chart
        at a corner only are reached too), with the chart each is to wet; a droplet of no
        known triangle, or on a mesh not :attr:`laid_out`: itself, for any chart."""
        if not 0 <= droplet.face < len(self.face_chart) or self.face_chart[droplet.face] < 0 \
                or not self.laid_out:
            return [(droplet, -1)]
        out = [(droplet, int(self.face_chart[droplet.face]))]
        reached = {out[0][1]}
        for here, chart in out:  # grows as charts are reached
            near = np.flatnonzero((self.source == chart)
                                  & ~np.isin(self.target, list(reached)))
            if len(near) == 0:
                continue
            c = complex(*here.centre)
            a, b = self.a[near], self.b[near]
            edge = b - a
            along = np.clip(((c - a) * edge.conj()).real
                            / np.maximum(np.abs(edge) ** 2, 1e-24), 0.0, 1.0)
            distance = np.abs(c - (a + along * edge))
            reach = distance <= here.radius
            for target in np.unique(self.target[near[reach]]):
                candidates = np.flatnonzero(reach & (self.target[near] == target))
                record = int(near[candidates[np.argmin(distance[candidates])]])
                centre = self.carry(record, here.centre)
                radius = here.radius * float(np.abs(self.scale[record]))
                out.append((Droplet(centre, radius, here.wetness, here.face), int(target)))
                reached.add(int(target))
        return out

    @property
    def laid_out(self) -> bool:
        """Whether each texel is at most one place on the surface: two charts or more, UVs in
        the unit square, no charts overlapping (a cube whose faces share the square does not
        qualify: its mask is one for all faces, and no copy could be only on one)."""
        if self._laid_out is None:
            uv = self.uvs
            self._laid_out = bool(self.chart_count >= 2 and uv.min() >= -1e-6
                                  and uv.max() <= 1.0 + 1e-6)
            if self._laid_out:
                _, covered, overlaps = self._raster(OVERLAP_CHECK_SIZE)
                self._laid_out = overlaps <= 0.01 * covered
        return self._laid_out

    def chart_texels(self, size: int) -> np.ndarray | None:
        """(size, size) each mask texel's chart (row i at v = (i + 0.5) / size), -1 for texels
        of none: those whose centre a chart's triangle covers, and around them a gutter of
        :data:`GUTTER_TEXELS` taking the nearest chart's. None (every texel any droplet's)
        unless :attr:`laid_out`."""
        if not self.laid_out:
            return None
        if size not in self._charts:
            charts = self._raster(size)[0]
            for _ in range(GUTTER_TEXELS):  # grow each chart a texel (8-neighbours; repeating)
                empty = charts < 0
                if not empty.any():
                    break
                grown = charts.copy()
                for dy, dx in ((0, 1), (0, -1), (1, 0), (-1, 0), (1, 1), (1, -1), (-1, 1),
                               (-1, -1)):
                    shifted = np.roll(charts, (dy, dx), axis=(0, 1))
                    take = empty & (grown < 0) & (shifted >= 0)
                    grown[take] = shifted[take]
                charts = grown
            self._charts[size] = charts
        return self._charts[size]

    def _raster(self, size: int) -> tuple[np.ndarray, int, int]:
        """The charts' triangles rasterized at texel centres: (charts, texels covered, texels
        covered by two charts or more)."""
        charts = np.full((size, size), -1, np.int64)
        overlaps = 0
        faces = self.faces[self._solid]
        face_chart = self.face_chart[self._solid]
        t = self.uvs[faces] * size - 0.5  # texel-centre coordinates
        low = np.clip(np.ceil(t.min(1)), 0, size - 1).astype(np.int64)
        high = np.clip(np.floor(t.max(1)), -1, size - 1).astype(np.int64)
        width = np.maximum(high[:, 0] - low[:, 0] + 1, 0)
        height = np.maximum(high[:, 1] - low[:, 1] + 1, 0)
        count = width * height
        ends = np.cumsum(count)
        begin = 0
        # (triangle, texel) candidates over each triangle's box, a band of triangles at a time
        while begin < len(count):
            stop = int(np.searchsorted(ends, ends[begin] - count[begin] + RASTER_BAND,
                                       side="right"))
            band = np.arange(begin, max(stop, begin + 1))
            begin = band[-1] + 1
            tri = np.repeat(band, count[band])
            k = np.arange(len(tri)) - np.repeat(ends[band] - count[band], count[band])
            col = low[tri, 0] + k % np.maximum(width[tri], 1)
            row = low[tri, 1] + k // np.maximum(width[tri], 1)
            p0, e1, e2 = t[tri, 0], t[tri, 1] - t[tri, 0], t[tri, 2] - t[tri, 0]
            q = np.stack([col, row], -1) - p0
            det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
            det = np.where(np.abs(det) > 1e-18, det, 1e-18)
            s = (q[:, 0] * e2[:, 1] - q[:, 1] * e2[:, 0]) / det
            r = (e1[:, 0] * q[:, 1] - e1[:, 1] * q[:, 0]) / det
            inside = (s >= -1e-9) & (r >= -1e-9) & (s + r <= 1.0 + 1e-9)
            row, col, chart = row[inside], col[inside], face_chart[tri[inside]]
            before = charts[row, col]
            charts[row, col] = chart
            clash = ((before >= 0) & (before != chart)) | (charts[row, col] != chart)
            overlaps += len(np.unique(row[clash] * size + col[clash]))
        return charts, int((charts >= 0).sum()), overlaps

    def blend(self, mask: np.ndarray, droplet: Droplet,
              wrap: tuple[bool, bool] = (False, False)) -> None:
        """Blend ``droplet`` into ``mask`` (Algorithm 1, :func:`blend_droplet`) in its own
        chart and across the seams it reaches (:meth:`copies`)."""
        charts = self.chart_texels(mask.shape[0])
        for copy, chart in self.copies(droplet):
            blend_droplet(mask, copy, wrap, charts, chart)


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
