"""Shadow map sizes by screen coverage (the ``[shadows]`` table's ``allocation = "coverage"``).

A spot or point light's maps are sized by how much of the view its shadowed region covers: the
bounding sphere of its cone (spot; the cone cut where it leaves the scene's box) or of its reach
(point), projected to the screen as the rectangle of its tangent planes (exact for a sphere in
front of the eye), cut to the rectangle of the scene's box within the sphere and to the view.
The map's side is its ``shadow_resolution`` times the square root of the covered fraction of the
screen (texels per pixel across the region held near what the full resolution gives a light
filling the view), rounded up to a power of two, at least :data:`MIN_TILE` and at most the
``shadow_resolution``. A light whose sphere lies outside the view gets no map; cascades cover the
view and keep their resolution.

Every size is a function of the frame alone (the camera and the light at its time), so a frame
of ``deferred render`` or a farm's worker is the same whatever came before. The live viewer
asks for hysteresis (:func:`map_size`'s ``previous``): a map grows as soon as its light needs
more texels and shrinks only once the light covers half the area the next smaller size
suffices for, so a camera moving back and forth about a size's edge does not redraw the map
every frame.

When the maps do not fit the atlas (the sum of their areas: power-of-two squares packed largest
first fill a power-of-two square exactly), the largest maps are halved, those covering least of
the screen first, down to :data:`MIN_TILE`, before any light is left unshadowed
(:func:`fit_sizes`).
"""

from __future__ import annotations

import math

import numpy as np

from deferred.interfaces.light import MIN_SHADOW_RESOLUTION, Light
from deferred.names import ShadowProjection

MIN_TILE = MIN_SHADOW_RESOLUTION  # texels on a side of the smallest map
# in log2 of a map's side: how far below a size's lower edge a light's need must fall before
# the live viewer shrinks its map (0.5: half the covered area)
SHRINK_MARGIN = 0.5


# the eight corners of a box, as 0/1 picks of its low and high ends
CORNERS = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], bool)


def shadowed_spheres(lights: list[Light], bounds: tuple[np.ndarray, np.ndarray] | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """The world bounding spheres (centres (n, 3), radii (n,)) of what spot and point
    ``lights`` shadow: a spot's cone of its ``radius`` and outer angle, cut where it leaves the
    world box ``bounds`` of the scene's objects (nothing beyond receives its light), bounded by
    the cone's circumsphere where the angle is at most 45 degrees, else by the sphere around its
    base disc; a point light's reach."""
    params = [light.params for light in lights]
    centres = np.array([p.position for p in params], np.float64).reshape(-1, 3)
    radii = np.array([p.radius for p in params], np.float64)
    spot = np.array([light.shadow_projection == ShadowProjection.PERSPECTIVE
                     for light in lights], bool)
    if not spot.any():
        return centres, radii
    position = centres[spot]
    direction = np.array([p.direction for p, is_spot in zip(params, spot, strict=True)
                          if is_spot], np.float64)
    direction /= np.maximum(np.linalg.norm(direction, axis=1, keepdims=True), 1e-12)
    length = radii[spot]
    if bounds is not None:  # the box's farthest corner along each axis
        reach = np.maximum(direction * (bounds[0] - position),
                           direction * (bounds[1] - position)).sum(axis=1)
        length = np.minimum(length, np.maximum(reach, 1e-6))
    angle = np.radians([p.outer_angle for p, is_spot in zip(params, spot, strict=True)
                        if is_spot])
    narrow = angle <= math.pi / 4.0
    radius = np.where(narrow, length / (2.0 * np.cos(angle)), length * np.sin(angle))
    along = np.where(narrow, radius, length * np.cos(angle))
    centres[spot] = position + direction * along[:, None]
    radii[spot] = radius
    return centres, radii


def _extent(centre: np.ndarray, depth: np.ndarray, radius: np.ndarray,
            scale: float) -> tuple[np.ndarray, np.ndarray]:
    """The NDC interval along one axis of spheres at (``centre``, ``depth`` > ``radius``) in
    that axis's plane with the view axis: the slopes of the two lines from the eye tangent to
    each, times the projection's ``scale`` (P00 or P11)."""
    d2 = depth * depth - radius * radius
    root = radius * np.sqrt(np.maximum(centre * centre + d2, 0.0))
    return np.maximum(scale * (centre * depth - root) / d2, -1.0), \
        np.minimum(scale * (centre * depth + root) / d2, 1.0)


def screen_coverage(centres: np.ndarray, radii: np.ndarray, view: np.ndarray,
                    projection: np.ndarray,
                    bounds: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """The fraction of the screen covered by each world sphere (``centres`` (n, 3), ``radii``)
    where it meets the world box ``bounds`` of what can receive its shadow: the rectangle
    bounding the sphere under ``view`` and the perspective ``projection`` (Mara and McGuire
    2013, "2D Polyhedral Bounds of a Clipped, Perspective-Projected 3D Sphere": the planes
    through each screen axis tangent to it), cut to the rectangle of the box's part within the
    sphere's box where that lies wholly in front of the eye, and to the view. 1 where the
    sphere reaches the eye's plane. Sub-pixel offsets of the projection (jitter) are left
    out."""
    centres = np.asarray(centres, np.float64).reshape(-1, 3)
    radii = np.asarray(radii, np.float64).reshape(-1)
    view = np.asarray(view, np.float64)
    seen = centres @ view[:3, :3].T + view[:3, 3]
    depth = -seen[:, 2]
    front = depth > radii
    safe = np.where(front, depth, radii + 1.0)  # the others' rectangles are not used
    scale = (float(projection[0, 0]), float(projection[1, 1]))
    x0, x1 = _extent(seen[:, 0], safe, radii, scale[0])
    y0, y1 = _extent(seen[:, 1], safe, radii, scale[1])
    if bounds is not None:
        low = np.maximum(bounds[0], centres - radii[:, None])
        high = np.minimum(bounds[1], centres + radii[:, None])
        empty = np.any(low > high, axis=1)
        corners = np.where(CORNERS[None], high[:, None], low[:, None])  # (n, 8, 3)
        points = corners @ view[:3, :3].T + view[:3, 3]
        ahead = np.all(points[..., 2] < -1e-6, axis=1)
        w = np.where(ahead[:, None], -points[..., 2], 1.0)
        sx, sy = scale[0] * points[..., 0] / w, scale[1] * points[..., 1] / w
        x0 = np.where(ahead, np.maximum(x0, sx.min(axis=1)), x0)
        x1 = np.where(ahead, np.minimum(x1, sx.max(axis=1)), x1)
        y0 = np.where(ahead, np.maximum(y0, sy.min(axis=1)), y0)
        y1 = np.where(ahead, np.minimum(y1, sy.max(axis=1)), y1)
        front &= ~empty
        out = empty
    else:
        out = np.zeros(len(radii), bool)
    area = np.maximum(x1 - x0, 0.0) * np.maximum(y1 - y0, 0.0) / 4.0
    return np.where(front, area, np.where(out, 0.0, 1.0))


def needed_log2(resolution: int, coverage: float) -> float:
    """log2 of the map side a light covering ``coverage`` of the screen needs."""
    return math.log2(resolution * math.sqrt(max(coverage, 1e-12)))


def map_size(resolution: int, coverage: float, previous: int | None = None) -> int:
    """A light's map side for its ``coverage`` of the screen: ``resolution`` x sqrt(coverage)
    rounded up to a power of two, in [:data:`MIN_TILE`, ``resolution``]; 0 for a light that
    covers nothing. With the ``previous`` frame's side (the live viewer), that side is kept
    unless the need is above it or :data:`SHRINK_MARGIN` below its lower edge."""
    if coverage <= 0.0:
        return 0
    need = needed_log2(resolution, coverage)
    top = int(math.log2(resolution))
    if previous:
        held = int(math.log2(previous))
        if held - 1 - SHRINK_MARGIN <= need <= held:
            return min(max(previous, MIN_TILE), resolution)
    level = min(max(math.ceil(need - 1e-9), int(math.log2(MIN_TILE))), top)
    return 1 << level


def fit_sizes(requests: list[tuple[int, int, int, float]], region: int) -> dict[int, int]:
    """Map sides that fit a ``region`` x ``region`` square: each request (key, maps, side,
    coverage) keeps its side where the areas fit; else the largest sides are halved, those of
    the least coverage (then the last listed) first, down to :data:`MIN_TILE`. Where even
    that does not fit, the sides are the smallest and the planner leaves lights out."""
    sides = {key: min(side, region) for key, _, side, _ in requests}
    order = {key: (coverage, -index)
             for index, (key, _, _, coverage) in enumerate(requests)}
    count = {key: maps for key, maps, _, _ in requests}
    area = sum(count[key] * side * side for key, side in sides.items())
    while area > region * region:
        shrinkable = [key for key, side in sides.items() if side > MIN_TILE]
        if not shrinkable:
            break
        key = max(shrinkable, key=lambda k: (sides[k], -order[k][0], -order[k][1]))
        side = sides[key]
        sides[key] = side // 2
        area -= count[key] * (side * side - sides[key] * sides[key])
    return sides
