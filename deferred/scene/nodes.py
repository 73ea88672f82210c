"""Nodes of the scene graph: a label, a local placement, a parent, keyframe tracks.

A :class:`SceneNode` is placed relative to its ``parent`` (another node, given itself or by its
label; ``None``: the world). Scene objects (:class:`deferred.scene.objects.SceneObject`) are
nodes with a mesh and a material; a bare node (``Scene.add_group``, a scene file's
``[[group]]``) only carries its children. Lights and the camera name a parent too
(``deferred.scene.graph``). Nodes are the user's: the renderer never writes to them; each frame
evaluates them (``deferred.scene.timeline``) into the frame state.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from deferred.errors import InputError
from deferred.params import validate_params
from deferred.revision import Revisioned
from deferred.scene.transform import IDENTITY, Transform, decompose, read_only

PLACEMENT = ("position", "rotation", "rotation_order", "quaternion", "scale")


class SceneNode(Revisioned):
    """A labelled placement in the scene graph.

    ``transform`` is the local :class:`~deferred.scene.transform.Transform`; ``model`` its
    matrix (read-only; assigning a matrix places the node by it, exactly, and tracks then
    animate its decomposition). ``position``, ``rotation``, ``rotation_order``, ``quaternion``
    and ``scale`` read and set one part of the placement, validated as a scene file's are.
    ``parent`` is a node or a node's label (``None``: the world); ``tracks`` move the local
    placement over time (``Scene.add_track``); ``where`` names the node in errors.
    """

    def __init__(self, label: str, transform: Transform | None = None,
                 parent: SceneNode | str | None = None, where: str | None = None,
                 tracks: tuple = (), model: np.ndarray | None = None):
        self._matrix: np.ndarray | None = None
        self._transform = IDENTITY
        self.label = label
        self.where = where
        self.parent = parent
        self.tracks = tuple(tracks)
        if transform is not None:
            self.transform = transform
        elif model is not None:
            self.model = model

    @property
    def node(self) -> SceneNode:
        """The node itself: what frame states are keyed by (an object's state has the same
        attribute)."""
        return self

    # -- placement -----------------------------------------------------------------------------
    @property
    def transform(self) -> Transform:
        return self._transform

    @transform.setter
    def transform(self, value: Transform) -> None:
        if not isinstance(value, Transform):
            raise InputError(f"expected a Transform, got {type(value).__name__}", "transform")
        self._transform = value
        self._matrix = None

    @property
    def model(self) -> np.ndarray:
        """The local matrix (T R S; the world's where the node has no parent), read-only."""
        if self._matrix is None:
            self._matrix = read_only(self._transform.matrix())
        return self._matrix

    @model.setter
    def model(self, matrix: np.ndarray) -> None:
        matrix = np.asarray(matrix, dtype=np.float64)
        if matrix.shape != (4, 4) or not np.all(np.isfinite(matrix)):
            raise InputError(f"expected a finite 4x4 matrix, got shape {matrix.shape}", "model")
        position, rotation, scale = decompose(matrix)
        self._transform = Transform.model_construct(position=position, rotation=rotation,
                                                    rotation_order="XYZ", quaternion=None,
                                                    scale=scale)
        self._matrix = read_only(matrix)

    def local_at(self, time: float) -> np.ndarray:
        """The local matrix at ``time`` (seconds): the placement with the tracks' values at
        ``time`` over it; :attr:`model` itself for a node without tracks. The world matrix is
        the scene's to give (``Scene.world_at``: the parents' too)."""
        if not self.tracks:
            return self.model
        values: dict[str, Any] = {}
        for track in self.tracks:
            values.update(track.at(time))
        return self._transform.with_values(values).matrix()

    def place(self, **values: Any) -> Transform:
        """Set parts of the placement (``position``, ``rotation``, ``rotation_order``,
        ``quaternion``, ``scale``), validated as a scene file's are (``InputError`` naming
        the node and the key); a ``rotation`` replaces a ``quaternion`` and the other way
        round. Returns the new transform."""
        unknown = [key for key in values if key not in PLACEMENT]
        if unknown:
            raise InputError(f"a placement has no {unknown[0]!r} (it has "
                             f"{', '.join(PLACEMENT)})", self._where(unknown[0]))
        merged = self._transform.model_dump()
        if "quaternion" in values and values["quaternion"] is not None:
            merged["rotation"] = (0.0, 0.0, 0.0)
        if "rotation" in values:
            merged["quaternion"] = None
        self.transform = validate_params(Transform, {**merged, **values}, self._where(None))
        return self._transform

    def _where(self, key: str | None) -> str:
        base = self.where or self.label
        return f"{base}.{key}" if key else base

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.label!r}>"


def _placement_property(key: str) -> property:
    def get(self: SceneNode) -> Any:
        return getattr(self.transform, key)

    def set_(self: SceneNode, value: Any) -> None:
        self.place(**{key: value})

    return property(get, set_, doc=f"The local placement's {key} (see :meth:`SceneNode.place`).")


for _key in PLACEMENT:
    setattr(SceneNode, _key, _placement_property(_key))
