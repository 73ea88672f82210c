"""The bounds of what a scene's objects draw (their meshes grown by what their materials draw
beyond them): an object's box and sphere, the whole scene's world box."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from deferred.scene.objects import SceneObject
from deferred.scene.scene import Scene


def object_box(obj: SceneObject) -> tuple[np.ndarray, np.ndarray]:
    """The object-space box of what the object draws: its mesh's, grown by how far its
    material draws beyond the mesh (fur shells, hair: ``Material.motion``)."""
    low, high = obj.mesh.bounds()
    extent = float(obj.material.motion.extent(obj))
    return low - extent, high + extent


def world_bounds(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """The world box of every object (corners of each object's box through its model
    matrix)."""
    lows, highs = [], []
    for obj in scene.objects:
        low, high = object_box(obj)
        corners = np.array([[x, y, z, 1.0] for x in (low[0], high[0]) for y in (low[1], high[1])
                            for z in (low[2], high[2])])
        world = (np.asarray(obj.model, np.float64) @ corners.T).T[:, :3]
        lows.append(world.min(axis=0))
        highs.append(world.max(axis=0))
    if not lows:
        return np.zeros(3), np.zeros(3)
    return np.min(lows, axis=0), np.max(highs, axis=0)


def object_sphere(obj: SceneObject) -> tuple[np.ndarray, float]:
    low, high = object_box(obj)
    model = np.asarray(obj.model, np.float64)
    centre = (model @ np.append((low + high) / 2.0, 1.0))[:3]
    scale = float(np.max(np.linalg.norm(model[:3, :3], axis=0)))
    return centre, float(np.linalg.norm(high - low)) / 2.0 * scale

