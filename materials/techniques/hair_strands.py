"""Guide strands of cartoon hair: read from a file or grown on a scalp (Costigan 4.1-4.2.1), and
the Catmull-Rom spline that smooths them (4.3.1) and interpolates keyframed poses (4.2.3).

Each strand is a guide for a whole clump of hair (Costigan 3.1: a sparse model of hundreds of
strands, not a dense one). A strand set is an array ``(strands, points, 3)`` in object space,
root first; every strand of a set has the same number of points, so the dynamics and the tube
builder work on all strands at once.

- :func:`load_strands` reads JSON ``{"strands": [[[x, y, z], ...], ...]}`` or OBJ ``l``
  polylines (the thesis exported Blender's hair particles as XML, 4.1; these are the open
  formats of the same data). Strands of different point counts are resampled by arc length to
  the largest count.
- :func:`scalp_roots` scatters roots on a mesh's scalp: the whole mesh (Fig. 4.1a) or, where the
  mesh has vertex colours, weighted by their alpha, the fur length scale (the weight-painted
  scalp of Fig. 4.1b; ``builtin:head`` paints its scalp so).
- :func:`grow_strands` grows strands from the roots in a style: ``combed`` (gravity and a
  parting, Fig. 4.3) or ``spiky`` (anime clumps: strands of a clump converge to one tip, the
  thesis' target style after Shin et al.).
- :func:`catmull_rom_weights` is Ogre's ``SimpleSpline`` (the class the thesis used): a
  Catmull-Rom spline through the points, uniform in the point index, as a matrix, so sampling
  every strand is one matrix product.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Literal

import numpy as np

from deferred.api import (
    MAX_COORDINATE,
    InputError,
    MeshData,
    check_memory,
    number_too_long,
    require_regular_file,
)

STRAND_SUFFIXES = (".json", ".obj")
MAX_STRAND_FILE_BYTES = 256 << 20
# Peak bytes parsing a strand file takes a byte of it (a JSON number's text of about 9 bytes
# becomes a Python float in a list; measured 6.7-15 on files of 73-85 MB), checked against the
# memory budget before the file is read
PARSE_BYTES_PER_BYTE = 16
PARSED_KEPT = 4  # strand files kept parsed (path, size, time): their strands are read thrice
_PARSED: dict[tuple[str, int, int], np.ndarray] = {}
MAX_STRANDS = 1_000_000
MAX_POINTS_PER_STRAND = 4096
# the strands resampled to the longest one's points: strands x that count
MAX_STRAND_POINTS = 20_000_000
MAX_STRAND_COORDINATE = MAX_COORDINATE  # as a mesh's: a stray point or the wrong units
HairStyle = Literal["combed", "spiky"]
COMBED_TURN = 35.0  # degrees a combed strand turns at most from one segment to the next
HAIR_STYLES: tuple[str, ...] = ("combed", "spiky")


# --------------------------------------------------------------------------- splines (4.3.1)

@lru_cache(maxsize=64)
def catmull_rom_weights(points: int, samples: int, derivative: bool = False) -> np.ndarray:
    """``(samples, points)`` weights: row ``i`` times the control points is the spline at
    ``t = i / (samples - 1)`` (or its derivative in ``t`` when ``derivative``).

    The spline is Ogre's ``SimpleSpline`` (Costigan 4.3.1, 4.2.3): segment ``k`` runs from point
    ``k`` to ``k + 1`` as ``t`` runs over ``[k, k + 1] / (points - 1)``, a cubic Hermite curve
    with the Catmull-Rom tangents ``(P[k+1] - P[k-1]) / 2``; the end tangents are one-sided,
    ``(P[1] - P[0]) / 2`` and ``(P[n-1] - P[n-2]) / 2``. It passes through every point.
    """
    if points < 2 or samples < 2:
        raise ValueError("a spline needs at least 2 points and 2 samples")
    t = np.linspace(0.0, 1.0, samples) * (points - 1)
    segment = np.minimum(t.astype(np.int64), points - 2)
    u = t - segment
    if derivative:  # d/dt of the Hermite basis, times d(u)/d(t) = points - 1
        h00, h10, h01, h11 = (6 * u * u - 6 * u, 3 * u * u - 4 * u + 1, -6 * u * u + 6 * u,
                              3 * u * u - 2 * u)
        h00, h10, h01, h11 = (h * (points - 1) for h in (h00, h10, h01, h11))
    else:
        h00, h10, h01, h11 = (2 * u ** 3 - 3 * u * u + 1, u ** 3 - 2 * u * u + u,
                              -2 * u ** 3 + 3 * u * u, u ** 3 - u * u)
    # tangent m_k = sum_j tangent[k, j] P_j
    tangent = np.zeros((points, points))
    k = np.arange(1, points - 1)
    tangent[k, k + 1], tangent[k, k - 1] = 0.5, -0.5
    tangent[0, 1], tangent[0, 0] = 0.5, -0.5
    tangent[-1, -1], tangent[-1, -2] = 0.5, -0.5
    rows = np.arange(samples)
    weights = np.zeros((samples, points))
    weights[rows, segment] += h00
    weights[rows, segment + 1] += h01
    weights += h10[:, None] * tangent[segment] + h11[:, None] * tangent[segment + 1]
    weights.setflags(write=False)
    return weights


def sample_spline(strands: np.ndarray, samples: int, derivative: bool = False) -> np.ndarray:
    """Every strand ``(S, P, 3)`` smoothed by its Catmull-Rom spline and sampled at ``samples``
    points evenly spaced in the spline's parameter: ``(S, samples, 3)`` (Costigan 4.3.1)."""
    weights = catmull_rom_weights(strands.shape[1], samples, derivative).astype(strands.dtype)
    return np.einsum("ip,spc->sic", weights, strands)


def interpolate_keyframes(keyframes: np.ndarray, key_times: np.ndarray, time: float) -> np.ndarray:
    """The pose at ``time`` on the Catmull-Rom spline through ``keyframes`` ``(K, ...)`` at the
    increasing ``key_times`` (Costigan 4.2.3: anchors move on a spline, not linearly, which looks
    mechanical). Each key interval is one Hermite segment with Catmull-Rom tangents (one-sided at
    the ends); before the first key and after the last the pose holds."""
    keys = len(keyframes)
    if keys == 1 or time <= key_times[0]:
        return keyframes[0]
    if time >= key_times[-1]:
        return keyframes[-1]
    k = int(np.searchsorted(key_times, time, side="right")) - 1
    u = (time - key_times[k]) / (key_times[k + 1] - key_times[k])
    start, end = keyframes[k], keyframes[k + 1]
    m0 = 0.5 * (end - keyframes[k - 1]) if k > 0 else 0.5 * (end - start)
    m1 = 0.5 * (keyframes[k + 2] - start) if k + 2 < keys else 0.5 * (end - start)
    return ((2 * u ** 3 - 3 * u * u + 1) * start + (u ** 3 - 2 * u * u + u) * m0
            + (-2 * u ** 3 + 3 * u * u) * end + (u ** 3 - u * u) * m1)


def rotation_minimising_frames(points: np.ndarray, tangents: np.ndarray,
                               reference: np.ndarray | None = None) -> np.ndarray:
    """Unit normals ``(S, N, 3)`` of rotation-minimising frames along ``points`` ``(S, N, 3)``
    with unit ``tangents``, by double reflection (Wang, Juttler, Zheng and Liu 2008), the first
    normal being ``reference`` ``(S, 3)`` made perpendicular to the first tangent (default: the
    world axis least along it). Sequential along the strand, vectorised over strands."""
    count, samples = points.shape[:2]
    t0 = tangents[:, 0]
    if reference is None:
        reference = np.eye(3, dtype=points.dtype)[np.abs(t0).argmin(axis=1)]
    r = reference - (reference * t0).sum(-1, keepdims=True) * t0
    r = r / np.maximum(np.linalg.norm(r, axis=-1, keepdims=True), 1e-12)
    normals = np.empty_like(points)
    normals[:, 0] = r
    eps = np.finfo(points.dtype).tiny * 1e6
    for i in range(samples - 1):
        v1 = points[:, i + 1] - points[:, i]
        c1 = (v1 * v1).sum(-1, keepdims=True)
        k1 = np.where(c1 > eps, 2.0 / np.maximum(c1, eps), 0.0)
        r_l = r - (k1 * (v1 * r).sum(-1, keepdims=True)) * v1
        t_l = tangents[:, i] - (k1 * (v1 * tangents[:, i]).sum(-1, keepdims=True)) * v1
        v2 = tangents[:, i + 1] - t_l
        c2 = (v2 * v2).sum(-1, keepdims=True)
        k2 = np.where(c2 > eps, 2.0 / np.maximum(c2, eps), 0.0)
        r = r_l - (k2 * (v2 * r_l).sum(-1, keepdims=True)) * v2
        normals[:, i + 1] = r
    return normals


# --------------------------------------------------------------------------- files (4.1-4.2.1)

def load_strands(path: str | Path, where: str | None = None) -> np.ndarray:
    """Strands from a JSON or OBJ file as ``(strands, points, 3)`` float64, root first.

    JSON: ``{"strands": [[[x, y, z], ...], ...]}``. OBJ: ``v`` lines and ``l`` polylines (1-based
    or negative indices); an ``l`` line that starts where the previous one ended continues its
    strand (Blender writes a polyline as one ``l`` per edge). Every strand needs at least 2
    points, each of 3 finite numbers; strands of different point counts are resampled by arc
    length to the largest count. A bad file is one ``InputError`` naming the file (``where``,
    default the path) and what is wrong.
    """
    path = Path(path)
    where = where or str(path)
    require_regular_file(path, "strand file", where)
    suffix = path.suffix.lower()
    if suffix not in STRAND_SUFFIXES:
        raise InputError(f"unsupported strand file format '{path.suffix}' (use "
                         f"{', '.join(STRAND_SUFFIXES)})", where)
    stat = path.stat()
    size = stat.st_size
    if size > MAX_STRAND_FILE_BYTES:
        raise InputError(f"strand file is {size:,} bytes, more than the "
                         f"{MAX_STRAND_FILE_BYTES:,} read", where)
    known = (str(path.resolve()), size, stat.st_mtime_ns)
    if known in _PARSED:  # a file is asked for again by the checks, the cost model, the state
        return _PARSED[known].copy()
    # before the text is read: parsing holds Python lists of every number
    check_memory(size * PARSE_BYTES_PER_BYTE, f"parsing the {size:,}-byte strand file "
                                              f"{path.name} needs about {{}}", where,
                 "a smaller file, or fewer points a strand")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"strand file is not UTF-8 text (byte {exc.start})", where) from None
    except OSError as exc:
        raise InputError(f"cannot read strand file: {exc.strerror or exc}", where) from None
    strands = _json_strands(text, where) if suffix == ".json" else _obj_strands(text, where)
    del text
    loaded = _common_points(strands, where)
    if len(_PARSED) >= PARSED_KEPT:
        del _PARSED[next(iter(_PARSED))]
    _PARSED[known] = loaded.copy()
    return loaded


def _json_strands(text: str, where: str) -> list[np.ndarray]:
    try:
        document = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"not valid JSON: {exc.msg} (line {exc.lineno}, column {exc.colno})",
                         where) from None
    except RecursionError:
        raise InputError("not valid JSON: nested too deeply", where) from None
    except ValueError:  # an integer of more digits than Python converts
        raise InputError(f"{number_too_long(text)}: not a coordinate", where) from None
    if not isinstance(document, dict) or "strands" not in document:
        raise InputError('expected an object {"strands": [[[x, y, z], ...], ...]}', where)
    listed = document["strands"]
    if not isinstance(listed, list) or not listed:
        raise InputError("'strands' must be a non-empty list of strands", where)
    if len(listed) > MAX_STRANDS:
        raise InputError(f"{len(listed):,} strands, more than the {MAX_STRANDS:,} allowed", where)
    strands = []
    for number, strand in enumerate(listed):
        if not isinstance(strand, list):
            raise InputError(f"strand {number} must be a list of [x, y, z] points", where)
        for index, point in enumerate(strand):
            if (not isinstance(point, list) or len(point) != 3
                    or not all(isinstance(c, int | float) and not isinstance(c, bool)
                               and not (isinstance(c, int) and abs(c) > 1e300)
                               for c in point)):
                raise InputError(f"strand {number} point {index} must be 3 numbers [x, y, z], "
                                 f"got {json.dumps(point)[:40]}", where)
        strands.append(_checked_strand(np.array(strand, dtype=np.float64).reshape(-1, 3),
                                       number, where))
    return strands


def _obj_strands(text: str, where: str) -> list[np.ndarray]:
    vertices: list[tuple[float, float, float]] = []
    chains: list[list[int]] = []
    for line_number, line in enumerate(text.splitlines(), 1):
        fields = line.split("#", 1)[0].split()
        if not fields:
            continue
        if fields[0] == "v":
            try:
                x, y, z = (float(f) for f in fields[1:4])
            except ValueError:
                raise InputError(f"line {line_number}: a vertex needs 3 numbers, got "
                                 f"'{line.strip()[:40]}'", where) from None
            vertices.append((x, y, z))
        elif fields[0] == "l":
            try:
                numbers = [int(f.split("/")[0]) for f in fields[1:]]
            except ValueError:
                raise InputError(f"line {line_number}: a polyline needs vertex numbers, got "
                                 f"'{line.strip()[:40]}'", where) from None
            indices = []
            for n in numbers:
                index = n - 1 if n > 0 else len(vertices) + n
                if n == 0 or not 0 <= index < len(vertices):
                    raise InputError(f"line {line_number}: vertex {n} does not exist (the "
                                     f"file has {len(vertices)} so far)", where)
                indices.append(index)
            if len(indices) < 2:
                raise InputError(f"line {line_number}: a polyline needs at least 2 points",
                                 where)
            if chains and chains[-1][-1] == indices[0]:
                chains[-1].extend(indices[1:])
            else:
                chains.append(indices)
    if not chains:
        raise InputError("no strands: the OBJ file has no 'l' polylines", where)
    if len(chains) > MAX_STRANDS:
        raise InputError(f"{len(chains):,} strands, more than the {MAX_STRANDS:,} allowed", where)
    points = np.array(vertices, dtype=np.float64).reshape(-1, 3)
    return [_checked_strand(points[chain], number, where) for number, chain in enumerate(chains)]


def _checked_strand(strand: np.ndarray, number: int, where: str) -> np.ndarray:
    if len(strand) < 2:
        raise InputError(f"strand {number} has {len(strand)} point{'s' * (len(strand) != 1)}; "
                         "a strand needs at least 2", where)
    if len(strand) > MAX_POINTS_PER_STRAND:
        raise InputError(f"strand {number} has {len(strand):,} points, more than the "
                         f"{MAX_POINTS_PER_STRAND:,} a strand may have", where)
    if not np.isfinite(strand).all():
        raise InputError(f"strand {number} has a coordinate that is not a finite number "
                         "(NaN or infinity)", where)
    beyond = np.abs(strand) > MAX_STRAND_COORDINATE
    if beyond.any():
        point, axis = np.argwhere(beyond)[0]
        raise InputError(f"strand {number} point {point} has {'xyz'[axis]} = "
                         f"{strand[point, axis]:g}, beyond +-{MAX_STRAND_COORDINATE:.0e} (as a "
                         "mesh's coordinates): a stray point or the wrong units", where)
    if not (np.linalg.norm(np.diff(strand, axis=0), axis=1) > 0.0).all():
        raise InputError(f"strand {number} repeats a point (a segment of length 0)", where)
    return strand


def _common_points(strands: list[np.ndarray], where: str | None = None) -> np.ndarray:
    """The strands as one array, each resampled by arc length to the largest point count;
    ``InputError`` where that array would pass ``MAX_STRAND_POINTS`` (a million two-point
    strands and one long one would ask for tens of gigabytes)."""
    count = max(len(s) for s in strands)
    if len(strands) * count > MAX_STRAND_POINTS:
        raise InputError(f"{len(strands):,} strands resampled to the longest one's {count:,} "
                         f"points are {len(strands) * count:,} points, more than the "
                         f"{MAX_STRAND_POINTS:,} held", where)
    return np.stack([s if len(s) == count else resample_strand(s, count) for s in strands])


def resample_strand(strand: np.ndarray, count: int) -> np.ndarray:
    """``count`` points evenly spaced by arc length along the polyline ``strand``."""
    lengths = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(strand, axis=0), axis=1))])
    at = np.linspace(0.0, lengths[-1], count)
    return np.stack([np.interp(at, lengths, strand[:, c]) for c in range(3)], axis=1)


# --------------------------------------------------------------------------- growing (4.1)

@dataclass(frozen=True)
class ScalpRoots:
    """Roots scattered on a scalp: positions and unit surface normals, ``(strands, 3)``."""

    positions: np.ndarray
    normals: np.ndarray


def scalp_weights(mesh: MeshData) -> np.ndarray:
    """Per-vertex scalp weight in [0, 1]: the vertex colours' alpha (the fur length scale; a
    weight-painted scalp, Costigan Fig. 4.1b) where the mesh has colours, else 1 everywhere (the
    whole object is the scalp, Fig. 4.1a)."""
    if mesh.has_comb:
        return np.clip(np.asarray(mesh.comb[:, 3], dtype=np.float64), 0.0, 1.0)
    return np.ones(len(mesh.positions))


def scalp_roots(mesh: MeshData, count: int, seed: int = 0) -> ScalpRoots:
    """``count`` roots on ``mesh``'s scalp, deterministic for ``seed``: triangles drawn with
    probability proportional to area times their vertices' mean scalp weight, points uniform
    in each triangle, normals interpolated from the vertex normals."""
    positions = np.asarray(mesh.positions, dtype=np.float64)
    normals = np.asarray(mesh.normals, dtype=np.float64)
    faces = np.asarray(mesh.indices, dtype=np.int64)
    corners = positions[faces]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                         corners[:, 2] - corners[:, 0]), axis=1)
    weight = area * scalp_weights(mesh)[faces].mean(axis=1)
    total = weight.sum()
    if not total > 0.0:
        raise InputError("the mesh has no scalp: its vertex colours' alpha (the scalp weight) "
                         "is 0 everywhere", mesh.name)
    rng = np.random.default_rng(seed)
    cumulative = np.cumsum(weight / total)
    chosen = np.minimum(np.searchsorted(cumulative, rng.random(count), side="right"),
                        len(faces) - 1)
    r1, r2 = rng.random(count), rng.random(count)
    s = np.sqrt(r1)
    bary = np.stack([1.0 - s, s * (1.0 - r2), s * r2], axis=1)
    root = np.einsum("sk,skc->sc", bary, corners[chosen])
    normal = np.einsum("sk,skc->sc", bary, normals[faces[chosen]])
    return ScalpRoots(root, unit_vectors(normal))


def grow_strands(roots: ScalpRoots, length: float, segments: int, style: HairStyle = "combed",
                 seed: int = 0, spheres: np.ndarray | None = None, parting: float = 0.0,
                 gravity: tuple[float, float, float] = (0.0, -1.0, 0.0),
                 clump_size: int = 6) -> np.ndarray:
    """Strands ``(strands, segments + 1, 3)`` grown from ``roots``, deterministic for ``seed``.

    ``combed``: each strand leaves the scalp along its normal and turns, segment by segment,
    first away from the parting (the plane ``x = parting`` times the roots' half-width, so
    ``parting`` is in [-1, 1]) and then down along ``gravity``. ``spiky``: roots are grouped in
    clumps of about ``clump_size``; a clump points along its seed root's normal, drooping a
    little, and its strands run straight to one shared tip, a spike. Lengths vary by up to 15%
    per strand (combed) or per clump (spiky). ``spheres`` ``(K, 4)`` (centre, radius), when
    given, keep every point outside them, as the head's collision spheres will.
    """
    if style not in HAIR_STYLES:
        raise ValueError(f"unknown hair style {style!r} (choose from {', '.join(HAIR_STYLES)})")
    rng = np.random.default_rng(seed)
    root, normal = roots.positions, roots.normals
    count = len(root)
    down = unit_vectors(np.asarray(gravity, dtype=np.float64)[None])[0]
    segment_length = length / segments
    if style == "combed":
        scale = segment_length * rng.uniform(0.85, 1.0, count)
        half_width = max(np.abs(root[:, 0]).max(), 1e-9)
        side = np.where(root[:, 0] >= parting * half_width, 1.0, -1.0)[:, None] * [1.0, 0.0, 0.0]
        points = [root]
        previous = None
        for k in range(segments):
            s = (k + 0.5) / segments
            # leave along the normal, sweep away from the parting, fall with gravity
            direction = unit_vectors((1.0 - s) ** 2 * 1.5 * normal + 2.0 * s * (1.0 - s) * side
                              + s * s * 2.0 * down)
            if spheres is not None:  # slide over the head rather than bounce off it
                direction = _slide(points[-1], direction, spheres, segment_length)
            if previous is not None:
                direction = _turn_at_most(previous, direction, COMBED_TURN)
            nxt = points[-1] + scale[:, None] * direction
            if spheres is not None:
                nxt = _outside(nxt, spheres, 0.25 * segment_length)
                nxt = points[-1] + scale[:, None] * unit_vectors(nxt - points[-1])
            previous = unit_vectors(nxt - points[-1])
            points.append(nxt)
        return np.stack(points, axis=1)
    clumps = max(1, round(count / max(clump_size, 1)))
    seeds = rng.choice(count, size=clumps, replace=False)
    member = _nearest(root, root[seeds])
    clump_normal = normal[seeds]
    droop = rng.uniform(0.2, 0.6, clumps)[:, None]
    direction = unit_vectors(clump_normal + droop * down)
    clump_length = length * rng.uniform(0.85, 1.0, clumps)
    tip = root[seeds] + clump_length[:, None] * direction
    tip = tip[member]
    s = np.linspace(0.0, 1.0, segments + 1)[None, :, None]
    # straight to the shared tip, bowed outward a little near the root so clumps look full
    bow = (0.15 * length) * (s * (1.0 - s) ** 2 * 4.0) * normal[:, None, :]
    points = root[:, None, :] * (1.0 - s) + tip[:, None, :] * s + bow
    if spheres is not None:
        inner = _outside(points[:, 1:].reshape(-1, 3), spheres, 0.25 * segment_length)
        points[:, 1:] = inner.reshape(count, segments, 3)
    return points


def _slide(points: np.ndarray, directions: np.ndarray, spheres: np.ndarray,
           reach: float) -> np.ndarray:
    """``directions`` ``(S, 3)`` from ``points`` with their way into each sphere taken out,
    fully at its surface and fading out ``reach`` beyond it: a strand combed over a head
    bends round it instead of being pushed back out in a kink."""
    directions = directions.copy()
    for cx, cy, cz, radius in np.asarray(spheres, dtype=np.float64):
        offset = points - (cx, cy, cz)
        distance = np.linalg.norm(offset, axis=1, keepdims=True)
        outward = offset / np.maximum(distance, 1e-12)
        weight = np.clip(1.0 - (distance - radius) / reach, 0.0, 1.0)
        inward = np.minimum((directions * outward).sum(axis=1, keepdims=True), 0.0)
        directions = unit_vectors(directions - weight * inward * outward)
    return directions


def _turn_at_most(previous: np.ndarray, directions: np.ndarray, degrees: float) -> np.ndarray:
    """Unit ``directions`` turned back toward the unit ``previous`` ones where they turn away
    from them by more than ``degrees`` (in the plane of the two)."""
    cosine = np.clip((previous * directions).sum(axis=1, keepdims=True), -1.0, 1.0)
    limit = np.cos(np.radians(degrees))
    across = unit_vectors(directions - cosine * previous)
    limited = limit * previous + np.sqrt(1.0 - limit * limit) * across
    return np.where(cosine < limit, limited, directions)


def unit_vectors(v: np.ndarray) -> np.ndarray:
    """Vectors ``(..., 3)`` made unit length (zero ones left zero)."""
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def _nearest(points: np.ndarray, centres: np.ndarray, block: int = 4096) -> np.ndarray:
    """Index of the nearest centre of each point, in blocks of points (bounded memory)."""
    out = np.empty(len(points), dtype=np.int64)
    squared = (centres ** 2).sum(axis=1)
    for start in range(0, len(points), block):
        part = points[start:start + block]
        # |p - c|^2 = |p|^2 - 2 p.c + |c|^2, |p|^2 the same for all of a point's centres: one
        # matrix product a block rather than a (block, centres, 3) array of differences
        out[start:start + block] = (squared[None, :] - 2.0 * (part @ centres.T)).argmin(axis=1)
    return out


def _outside(points: np.ndarray, spheres: np.ndarray, margin: float) -> np.ndarray:
    """``points`` pushed radially out of each sphere (grown by ``margin``), sphere by sphere."""
    points = points.copy()
    for cx, cy, cz, radius in np.asarray(spheres, dtype=np.float64):
        offset = points - (cx, cy, cz)
        distance = np.linalg.norm(offset, axis=1)
        inside = distance < radius + margin
        if inside.any():
            away = offset[inside] / np.maximum(distance[inside], 1e-12)[:, None]
            points[inside] = (cx, cy, cz) + away * (radius + margin)
    return points


def strand_parameter(points: int) -> np.ndarray:
    """The parameter along a strand, 0 at the root and 1 at the tip, of each of ``points``
    evenly spaced points (the ``x`` of the thesis' quadratic curves, section 3.6)."""
    return np.linspace(0.0, 1.0, points)


def quadratic(curve: tuple[float, float, float] | np.ndarray, x: np.ndarray) -> np.ndarray:
    """``a x^2 + b x + c`` (Costigan 3.6: the H, S and E curves: tube radius, anchor stiffness and
    silhouette fade along the strand)."""
    a, b, c = (float(v) for v in curve)
    return (a * x + b) * x + c
