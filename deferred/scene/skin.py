"""Skins: a mesh deformed by joints of the scene graph (linear blend skinning).

A :class:`Skin` names the joints (nodes of the scene) and their inverse bind matrices; a skinned
object's mesh carries four joints and weights a vertex (``MeshData.joints``, ``weights``). Each
frame's state holds the object's joint matrices at the frame's time (:meth:`Skin.matrices`),
relative to the object's own world matrix, so that what draws the object still applies its
model matrix: ``world(object) @ M_i = world(joint_i) @ inverse_bind_i``, the glTF rule.
The GPU blends them (``deferred.render.skinning``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from deferred.scene.transform import read_only

if TYPE_CHECKING:
    from deferred.scene.nodes import SceneNode

MAX_JOINTS = 1024  # rows of the joint texture one object reads


@dataclass(frozen=True, eq=False)
class Skin:
    """``joints`` the scene graph's nodes the mesh follows, ``inverse_binds`` (J, 4, 4) the
    matrices taking the mesh's space to each joint's at the bind pose; ``name`` for messages."""

    joints: tuple[SceneNode, ...]
    inverse_binds: np.ndarray
    name: str = "skin"

    def __post_init__(self) -> None:
        binds = np.asarray(self.inverse_binds, np.float64)
        if binds.shape != (len(self.joints), 4, 4) or not np.all(np.isfinite(binds)):
            raise ValueError(f"{self.name}: {len(self.joints)} joints need as many finite 4x4 "
                             f"inverse bind matrices, got shape {binds.shape}")
        if len(self.joints) > MAX_JOINTS:
            raise ValueError(f"{self.name}: {len(self.joints)} joints; at most {MAX_JOINTS}")
        object.__setattr__(self, "inverse_binds", read_only(binds))

    def matrices(self, object_world: np.ndarray, joint_worlds: list[np.ndarray]) -> np.ndarray:
        """(J, 4, 4) joint matrices in the object's space: ``inverse(object_world) @
        joint_world @ inverse_bind`` for each joint."""
        inverse = np.linalg.inv(object_world)
        return read_only(inverse @ np.asarray(joint_worlds) @ self.inverse_binds)


def skin_positions(positions: np.ndarray, joints: np.ndarray, weights: np.ndarray,
                   matrices: np.ndarray) -> np.ndarray:
    """numpy twin of the GPU's skinning (tests, bounds): each vertex by the weighted sum of
    its joints' matrices."""
    blended = np.einsum("vk,vkij->vij", weights.astype(np.float64),
                        matrices[joints.astype(np.int64)])
    homogeneous = np.hstack([positions, np.ones((len(positions), 1))])
    return np.einsum("vij,vj->vi", blended, homogeneous)[:, :3]
