"""The view and projection of each map of a shadowed light, with its texel size and reach:
a directional light's cascades (practical splits, a bounding sphere a slice, snapped to whole
texels), a spot light's perspective map, a point light's six cube faces.

A map's frustum is ``(far, light_view, projection, texel, perspective_texel, reach)``: the
cascade's far view depth (0 for other maps), the light's world -> view and its projection, the
world size of a texel (per unit depth where ``perspective_texel``), and the light's reach
(centre, radius) for culling casters, or None.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pyrr

from deferred.interfaces.light import Light
from deferred.scene.scene import Scene

# cube faces: the direction each looks along and its up (the lookup's major-axis order)
CUBE_FACES = (((1, 0, 0), (0, -1, 0)), ((-1, 0, 0), (0, -1, 0)), ((0, 1, 0), (0, 0, 1)),
              ((0, -1, 0), (0, 0, -1)), ((0, 0, 1), (0, -1, 0)), ((0, 0, -1), (0, -1, 0)))


def near_far(projection: np.ndarray) -> tuple[float, float]:
    """The near and far distances of a GL projection matrix (orthographic or perspective)."""
    p22, p23 = float(projection[2, 2]), float(projection[2, 3])
    if abs(float(projection[3, 3]) - 1.0) < 1e-9:  # orthographic
        span = -2.0 / p22
        total = -p23 * span
        return (total - span) / 2.0, (total + span) / 2.0
    return p23 / (p22 - 1.0), p23 / (p22 + 1.0)


def practical_splits(near: float, far: float, count: int, lam: float) -> np.ndarray:
    """The far view depth of each of ``count`` cascades over [near, far]: the practical split
    scheme, ``lam`` x logarithmic + (1 - ``lam``) x uniform (Zhang et al. 2006, Eq. 3)."""
    i = np.arange(1, count + 1) / count
    return lam * near * (far / near) ** i + (1.0 - lam) * (near + (far - near) * i)


def look_at(eye: np.ndarray, direction: np.ndarray, up: np.ndarray) -> np.ndarray:
    eye = np.asarray(eye, np.float64)
    return pyrr.matrix44.create_look_at(eye, eye + np.asarray(direction, np.float64),
                                        np.asarray(up, np.float64)).T


def orthographic(left: float, right: float, bottom: float, top: float, near: float,
                 far: float) -> np.ndarray:
    return pyrr.matrix44.create_orthogonal_projection(left, right, bottom, top, near, far,
                                                      dtype=np.float64).T


def perspective(tan_half: float, near: float, far: float) -> np.ndarray:
    return pyrr.matrix44.create_perspective_projection(
        2.0 * math.degrees(math.atan(tan_half)), 1.0, near, far, dtype=np.float64).T


def filter_margin(params: Any) -> float:
    """Texels a lookup's filter reaches from its centre (PCF: a texel, plus bilinear)."""
    return 2.0 if params.shadow_filter in ("pcf", "pcss") else \
        math.ceil(params.shadow_softness) + 1.0


def light_up(direction: np.ndarray) -> np.ndarray:
    """An up vector for a light looking along ``direction`` (world +Y unless nearly along)."""
    return np.array([0.0, 0.0, 1.0]) if abs(direction[1]) > 0.99 else np.array([0.0, 1.0, 0.0])


def unit(v) -> np.ndarray:
    v = np.asarray(v, np.float64)
    return v / max(float(np.linalg.norm(v)), 1e-12)


@dataclass(frozen=True)
class CascadeSlice:
    """A cascade's slice of the view: its far view depth, the light's world -> view, the
    slice's bounding sphere in the light's view (``centre``, ``radius``) and ``top``, the
    light-view z of the scene's bounds nearest the light (casters up to there draw)."""

    far: float
    light_view: np.ndarray
    centre: np.ndarray
    radius: float
    top: float


def cascade_slices(light: Light, scene: Scene, inverse_view: np.ndarray, aspect: float,
                   bounds: tuple[np.ndarray, np.ndarray]) -> list[CascadeSlice]:
    """A directional light's cascades' slices of the camera's depth up to
    ``shadow_distance``."""
    params = light.params
    camera = scene.camera
    near = camera.near
    # a shadow distance short of the near plane shadows nothing in view: the cascades end there
    far = max(min(camera.far, params.shadow_distance), near)
    splits = practical_splits(near, far, params.cascades, params.cascade_lambda)
    direction = unit(params.direction)
    light_view = look_at((0.0, 0.0, 0.0), direction, light_up(direction))
    tan_y = math.tan(math.radians(camera.fov) / 2.0)
    k2 = tan_y * tan_y * (1.0 + aspect * aspect)  # squared corner radius per unit depth
    low, high = bounds
    corners = np.array([[x, y, z, 1.0] for x in (low[0], high[0]) for y in (low[1], high[1])
                        for z in (low[2], high[2])])
    top = float((light_view @ corners.T)[2].max())
    eye = inverse_view[:3, 3]
    forward = -inverse_view[:3, 2]
    slices = []
    start = near
    for end in splits:
        # the slice's bounding sphere: its centre on the view axis, equally far from the
        # near and far corners (at most the far corners' centre); it depends on the
        # slice's depths and the field of view only, not on where the camera looks
        centre_depth = min((end + start) * (1.0 + k2) / 2.0, end)
        radius = math.sqrt((end - centre_depth) ** 2 + end * end * k2)
        centre = (light_view @ np.append(eye + forward * centre_depth, 1.0))[:3]
        slices.append(CascadeSlice(float(end), light_view, centre, radius, top))
        start = end
    return slices


def cascade_frustum(cascade: CascadeSlice, resolution: int, widen: float = 1.0) -> tuple:
    """A cascade's map over its slice's sphere, its radius times ``widen`` (a map kept for
    later frames covers the slice as the camera moves on:
    :mod:`~deferred.lighting.shadows.stagger`)."""
    radius = cascade.radius * widen
    texel = 2.0 * radius / resolution
    centre = cascade.centre
    # snapped to whole texels: the map moves in steps of a texel (stable edges)
    cx, cy = (np.floor(centre[:2] / texel) * texel)
    z_near = -max(centre[2] + radius, cascade.top) - texel
    z_far = -(centre[2] - radius) + texel
    projection = orthographic(cx - radius, cx + radius, cy - radius, cy + radius,
                              z_near, z_far)
    return (cascade.far, cascade.light_view, projection, texel, False, None)


def near_plane(radius: float) -> float:
    return min(max(radius * 0.005, 0.01), 0.5)


def spot_frustum(light: Light, resolution: int) -> tuple:
    """A spot light's map: along the cone's axis, wide enough for the outer angle."""
    params = light.params
    position = np.asarray(params.position, np.float64)
    direction = unit(params.direction)
    margin = filter_margin(params)
    tan_half = math.tan(math.radians(params.outer_angle)) * resolution / \
        (resolution - 2.0 * margin)
    tan_half = min(tan_half, math.tan(math.radians(89.0)))
    light_view = look_at(position, direction, light_up(direction))
    projection = perspective(tan_half, near_plane(params.radius), params.radius)
    return (0.0, light_view, projection, 2.0 * tan_half / resolution, True,
            (position, params.radius))


def cube_frusta(light: Light, resolution: int) -> list[tuple]:
    """A point light's six faces, a little wider than 90 degrees (a filter near a face's edge
    reads the face's own texels)."""
    params = light.params
    position = np.asarray(params.position, np.float64)
    tan_half = resolution / (resolution - 2.0 * filter_margin(params))
    projection = perspective(tan_half, near_plane(params.radius), params.radius)
    return [(0.0, look_at(position, direction, up), projection, 2.0 * tan_half / resolution,
             True, (position, params.radius)) for direction, up in CUBE_FACES]
