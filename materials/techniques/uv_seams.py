"""A mesh's UV charts and the seams between them, for the wetness mask (``wetness.py``): a droplet
fallen near a seam between two charts is blended into the chart across it too, its centre
carried over the edge by the map that takes that edge's UVs on one side to its UVs on the other
(a similarity, mirrored where the charts are), so the clump goes on across the seam instead of
being cut at the chart's edge. Each droplet only wets texels of its own chart (the texels the
chart covers and a gutter of :data:`GUTTER_TEXELS` around it), never a neighbouring chart that
is far away on the surface but packed beside it in UV space.
"""

from __future__ import annotations

import numpy as np

from deferred.api import MeshData

from .topology import weld
from .wetness import Droplet, blend_droplet

# texels around a chart that belong to it: the 2x2 texels a bilinear lookup at the chart's edge
# reads, and Algorithm 2's displaced lookups just past it, see the chart's own clumps
GUTTER_TEXELS = 3
RASTER_BAND = 1 << 20  # (triangle, texel) candidates rasterized at once
OVERLAP_CHECK_SIZE = 256  # texels a side of the raster that finds charts overlapping


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
