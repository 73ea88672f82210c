"""The bench's scene variants: extra point lights placed where the camera sees them, each
with a radius covering a fixed share of the view at its depth, a shell count set on every
object whose material has one (``revie_fur``), and a fur self-shadowing density likewise."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from pydantic import ValidationError

from deferred.errors import InputError
from deferred.interfaces import registry
from deferred.interfaces.light import Light
from deferred.scene.objects import SceneObject
from deferred.scene.scene import Scene

MAX_LIGHTS = 16384  # the GL 3.3 path keeps one light per row of a texture
LIGHT_SEED = 0
# A light's radius is this share of the half-height of the view at its depth: on screen each
# sphere spans about 15% of the image height, in any scene at any scale.
LIGHT_VIEW_SHARE = 0.3
LIGHT_INTENSITY = 2.0
SHELLS = "shells"
MIN_SHELLS = "min_shells"
SELF_SHADOW_DENSITY = "self_shadow_density"


def world_bounds(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned world bounds of every object (the camera target +-1 in an empty scene)."""
    if not scene.objects:
        target = np.asarray(scene.camera.target, dtype=np.float64)
        return target - 1.0, target + 1.0
    corners = []
    for obj in scene.objects:
        low, high = obj.mesh.bounds()
        box = np.array([[x, y, z, 1.0] for x in (low[0], high[0]) for y in (low[1], high[1])
                        for z in (low[2], high[2])])
        # the world matrix at t = 0: an object in a group (a glTF file's nodes) is placed by
        # its parents too
        corners.append((box @ scene.world_at(obj, 0.0).T)[:, :3])
    points = np.concatenate(corners)
    return points.min(axis=0), points.max(axis=0)


def extra_point_lights(scene: Scene, count: int, aspect: float,
                       seed: int = LIGHT_SEED) -> list[Light]:
    """``count`` point lights around and above the objects, centres on screen.

    Candidates come from one seeded stream in fixed batches, so the lights of a smaller count are
    a prefix of a larger count's. Where the camera sees too little of the bounds, the remaining
    lights are taken off screen rather than not at all.
    """
    if count == 0:
        return []
    low, high = world_bounds(scene)
    # "Above": a quarter of the objects' height over them (a tenth of their width when flat),
    # not more, or lights would float clear of every surface.
    height = max(float(high[1] - low[1]), 0.1 * float(np.max(high - low)), 1e-3)
    high = high + np.array([0.0, 0.25 * height, 0.0])
    camera = scene.camera
    view = camera.view()
    projection = camera.projection(aspect)
    half_height = math.tan(math.radians(camera.fov) / 2.0)
    rng = np.random.default_rng(seed)
    accepted: list[tuple[np.ndarray, float]] = []
    rejected: list[tuple[np.ndarray, float]] = []
    for _ in range(64):
        points = rng.uniform(low, high, size=(256, 3))
        homogeneous = np.c_[points, np.ones(len(points))]
        eye = homogeneous @ view.T
        clip = eye @ projection.T
        depth = -eye[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            ndc = clip[:, :2] / clip[:, 3:4]
        visible = (depth > camera.near) & np.all(np.abs(ndc) <= 1.0, axis=1)
        for point, distance, seen in zip(points, depth, visible, strict=True):
            radius = LIGHT_VIEW_SHARE * half_height * max(abs(float(distance)), camera.near)
            (accepted if seen else rejected).append((point, radius))
        if len(accepted) >= count:
            break
    chosen = (accepted + rejected)[:count]
    colors = np.random.default_rng(seed + 1).uniform(0.25, 1.0, size=(count, 3))
    point_light = registry.lights.get("point")
    return [point_light.from_dict({"position": tuple(float(v) for v in point),
                                   "radius": radius,
                                   "color": tuple(float(v) for v in color),
                                   "intensity": LIGHT_INTENSITY})
            for (point, radius), color in zip(chosen, colors, strict=True)]


def with_extra_lights(scene: Scene, count: int, aspect: float, seed: int = LIGHT_SEED) -> Scene:
    """A copy of ``scene`` with ``count`` more point lights (the scene itself is unchanged)."""
    return replace(scene, lights=[*scene.lights, *extra_point_lights(scene, count, aspect, seed)])


class LightSweep:
    """``scene`` with each count of extra point lights up to ``largest``: the largest count's
    lights made once and each smaller count given its first ones (what
    :func:`with_extra_lights` gives it), so a sweep of many counts does not make their lights
    again for each."""

    def __init__(self, scene: Scene, largest: int, aspect: float, seed: int = LIGHT_SEED):
        self.scene = scene
        self.extra = extra_point_lights(scene, largest, aspect, seed)

    def at(self, count: int) -> Scene:
        return replace(self.scene, lights=[*self.scene.lights, *self.extra[:count]])


def has_shells(obj: SceneObject) -> bool:
    return SHELLS in type(obj.material.params).model_fields


def shell_objects(scene: Scene) -> list[SceneObject]:
    """Objects whose material has a ``shells`` parameter."""
    return [obj for obj in scene.objects if has_shells(obj)]


def with_shells(scene: Scene, shells: int, where: str = "--shells") -> Scene:
    """A copy of ``scene`` with ``shells`` on every object whose material has that parameter,
    drawn whatever the distance (``min_shells`` too, where the material has it)."""
    objects = []
    for obj in scene.objects:
        if has_shells(obj):
            material = obj.material
            params = material.params
            try:
                # Validated, not model_copy(update=...): each material's range applies.
                # The sweep fixes the count: a level of detail's minimum (if any) goes with it.
                overrides = {SHELLS: shells}
                if MIN_SHELLS in type(params).model_fields and shells > 0:
                    overrides[MIN_SHELLS] = shells
                new_params = type(params).model_validate({**params.model_dump(), **overrides})
            except ValidationError as exc:
                problem = exc.errors()[0]["msg"]
                raise InputError(f"{problem} for {obj.label} ({material.name}), got {shells}",
                                 where) from None
            # the count holds at every time of the object's timeline, if it has one
            obj = obj.with_material(type(material)(new_params, material.base_dir), overrides)
        objects.append(obj)
    return replace(scene, objects=objects)


def set_self_shadow_density(scene: Scene, density: float) -> Scene:
    """``scene`` with ``self_shadow_density`` set (validated, in place) on every object whose
    material has that parameter: the fur's deep opacity maps, 0 for gamma(h) alone."""
    for obj in scene.objects:
        if SELF_SHADOW_DENSITY in type(obj.material.params).model_fields:
            obj.set_params(**{SELF_SHADOW_DENSITY: density})
    return scene
