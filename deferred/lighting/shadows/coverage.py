"""Shadow map sizes by screen coverage (the ``[shadows]`` table's ``allocation = "coverage"``).

A spot or point light's maps are sized by how much of the view its shadowed region covers: the
bounding sphere of its cone (spot) or of its reach (point), projected to the screen as the
rectangle of its tangent planes (exact for a sphere in front of the eye), clipped to the view.
The map's side is its ``shadow_resolution`` times the square root of the covered fraction of the
screen (texels per pixel across the region held near what the full resolution gives a light
filling the view), rounded up to a power of two, at least :data:`MIN_TILE` and at most the
``shadow_resolution``. A light whose sphere lies outside the view gets no map; cascades cover the
view and keep their resolution.

Every size is a function of the frame alone (the camera and the light at its time), so a frame
of ``deferred render`` or a farm's worker is the same whatever came before. The live viewer
asks for hysteresis (:func:`map_size`'s ``previous``): a map grows as soon as its light needs
more texels and shrinks only once the light covers half the area its smaller size stands for,
so a camera moving back and forth about a size's edge does not redraw the map every frame.

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


def shadowed_sphere(light: Light, bounds: tuple[np.ndarray, np.ndarray] | None = None
                    ) -> tuple[np.ndarray, float]:
    """The world bounding sphere (centre, radius) of what a spot or point light shadows: a
    spot's cone of its ``radius`` and outer angle, cut where it leaves the world box
    ``bounds`` of the scene's objects (nothing beyond receives its light), bounded by the
    cone's circumsphere where the angle is at most 45 degrees, else the sphere around its base
    disc; a point light's reach."""
    params = light.params
    position = np.asarray(params.position, np.float64)
    length = float(params.radius)
    if light.shadow_projection != ShadowProjection.PERSPECTIVE:
        return position, length
    direction = np.asarray(params.direction, np.float64)
    direction = direction / max(float(np.linalg.norm(direction)), 1e-12)
    if bounds is not None:  # the farthest corner of the box along the axis
        low, high = bounds
        reach = float(np.sum(np.maximum(direction * (low - position),
                                        direction * (high - position))))
        length = min(length, max(reach, 1e-6))
    angle = math.radians(params.outer_angle)
    if angle <= math.pi / 4.0:
        radius = length / (2.0 * math.cos(angle))
        return position + direction * radius, radius
    return position + direction * length * math.cos(angle), length * math.sin(angle)


def _extent(centre: float, depth: float, radius: float, scale: float) -> tuple[float, float]:
    """The NDC interval along one axis of a sphere at (``centre``, ``depth`` > ``radius``) in
    that axis's plane with the view axis: the slopes of the two lines from the eye tangent to
    it, times the projection's ``scale`` (P00 or P11)."""
    d2 = depth * depth - radius * radius
    root = radius * math.sqrt(max(centre * centre + d2, 0.0))
    low, high = (centre * depth - root) / d2, (centre * depth + root) / d2
    return max(scale * low, -1.0), min(scale * high, 1.0)


def screen_coverage(centre: np.ndarray, radius: float, view: np.ndarray,
                    projection: np.ndarray,
                    bounds: tuple[np.ndarray, np.ndarray] | None = None) -> float:
    """The fraction of the screen covered by the world sphere (``centre``, ``radius``) where it
    meets the world box ``bounds`` of what can receive its shadow: the rectangle bounding the
    sphere under ``view`` and the perspective ``projection`` (Mara and McGuire 2013, "2D
    Polyhedral Bounds of a Clipped, Perspective-Projected 3D Sphere": the planes through each
    screen axis tangent to it), cut to the rectangle of the box's part within the sphere's
    box where that lies wholly in front of the eye, and to the view. 1 where the sphere
    reaches the eye's plane. Sub-pixel offsets of the projection (jitter) are left out."""
    x, y, z = (float(v) for v in (view @ np.append(centre, 1.0))[:3])
    depth = -z
    if depth <= radius:
        return 1.0
    scale = (float(projection[0, 0]), float(projection[1, 1]))
    x0, x1 = _extent(x, depth, radius, scale[0])
    y0, y1 = _extent(y, depth, radius, scale[1])
    if bounds is not None:
        low = np.maximum(bounds[0], centre - radius)
        high = np.minimum(bounds[1], centre + radius)
        if np.any(low > high):
            return 0.0
        corners = np.array([[cx, cy, cz, 1.0] for cx in (low[0], high[0])
                            for cy in (low[1], high[1]) for cz in (low[2], high[2])])
        seen = (view @ corners.T)[:3]
        if np.all(seen[2] < -1e-6):
            sx, sy = scale[0] * seen[0] / -seen[2], scale[1] * seen[1] / -seen[2]
            x0, x1 = max(x0, float(sx.min())), min(x1, float(sx.max()))
            y0, y1 = max(y0, float(sy.min())), min(y1, float(sy.max()))
    if x1 <= x0 or y1 <= y0:
        return 0.0
    return (x1 - x0) * (y1 - y0) / 4.0


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
