"""The scene graph: who is whose parent, checked, and world matrices through it.

Objects, groups, lights and the camera name a ``parent``: a node of the scene (an object or a
group) given itself or by its label. :func:`hierarchy` resolves every parent of a scene once
(an unknown label, a node that is not in the scene, or a cycle is one ``InputError`` naming
the child and its parent) and :func:`world_matrix` composes a node's world matrix, parent
first: ``world(child) = world(parent) @ local(child)``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

import numpy as np

from deferred.errors import InputError
from deferred.validation import closest

if TYPE_CHECKING:
    from deferred.scene.nodes import SceneNode

LocalMatrix = Callable[["SceneNode"], np.ndarray]


class Hierarchy:
    """The parent of every node of a scene (by the node), resolved and checked; the nodes by
    label."""

    def __init__(self, nodes: Iterable[SceneNode], where: str = "scene"):
        self.nodes = list(nodes)
        self.by_label: dict[str, SceneNode] = {}
        for node in self.nodes:
            self.by_label.setdefault(node.label, node)
        self._members = set(self.nodes)  # nodes hash by identity
        self.parents: dict[SceneNode, SceneNode] = {}
        for node in self.nodes:
            parent = self.resolve(node.parent, self._where(node, where))
            if parent is not None:
                self.parents[node] = parent
        rooted: set[SceneNode] = set()  # nodes whose ancestors are known to end at the world
        for node in self.nodes:
            self._check_acyclic(node, where, rooted)

    @staticmethod
    def _where(item: Any, where: str) -> str:
        named = getattr(item, "where", None) or getattr(item, "label", None) or where
        return f"{named}.parent"

    def resolve(self, parent: SceneNode | str | None, where: str) -> SceneNode | None:
        """The node ``parent`` names: itself where it is in the scene, else the scene's node
        of its label; ``None`` for the world."""
        if parent is None:
            return None
        if isinstance(parent, str):
            found = self.by_label.get(parent)
            if found is None:
                match = closest(parent, list(self.by_label))
                hint = f"did you mean '{match[:80]}'? " if match is not None else ""
                names = ", ".join(label[:40] for label in list(self.by_label)[:10]) or "none"
                raise InputError(f"no object or group named {parent[:80]!r} to be the parent "
                                 f"({hint}nodes: {names})", where)
            return found
        if parent in self._members:
            return parent
        label = getattr(parent, "label", None)
        if isinstance(label, str) and label in self.by_label:
            return self.by_label[label]  # a copy of the node (a debug view's scene)
        raise InputError(f"the parent {label or parent!r:.80} is not in the scene", where)

    def _check_acyclic(self, node: SceneNode, where: str, rooted: set[SceneNode]) -> None:
        """``InputError`` where ``node`` is its own ancestor; a chain that reaches a node of
        ``rooted`` (or the world) is added to it, so each link is walked about once."""
        seen = [node]
        parent = self.parents.get(node)
        while parent is not None and parent not in rooted:
            if parent is node:
                labels = [n.label[:40] for n in [*seen, node]]
                if len(labels) > 8:  # one readable line, however long the cycle
                    labels = [*labels[:4], f"... ({len(seen)} nodes) ...", *labels[-3:]]
                chain = " -> ".join(labels)
                raise InputError(f"the parents form a cycle ({chain}): a node cannot be its "
                                 "own ancestor", self._where(node, where))
            seen.append(parent)
            if len(seen) > len(self.nodes) + 1:
                return  # a cycle above this node: reported for its own members
            parent = self.parents.get(parent)
        rooted.update(seen)

    def parent_of(self, node: SceneNode) -> SceneNode | None:
        return self.parents.get(node)

    def ancestors(self, node: SceneNode) -> list[SceneNode]:
        """The node's parent, its parent's, ... up to the root."""
        chain = []
        parent = self.parents.get(node)
        while parent is not None:
            chain.append(parent)
            parent = self.parents.get(parent)
        return chain


def world_matrix(node: SceneNode, hierarchy: Hierarchy, local: LocalMatrix,
                 worlds: dict[SceneNode, np.ndarray] | None = None) -> np.ndarray:
    """``node``'s world matrix: its ancestors' local matrices (``local``) times its own, root
    first. ``worlds`` keeps each node's as it is made (a scene's worlds made in one pass).
    Made walking up, then down: a hierarchy of any depth takes no recursion."""
    worlds = {} if worlds is None else worlds
    chain = []  # the node and its ancestors whose worlds are not known yet, nearest first
    current: SceneNode | None = node
    while current is not None and current not in worlds:
        chain.append(current)
        current = hierarchy.parent_of(current)
    world = None if current is None else worlds[current]
    for each in reversed(chain):
        own = local(each)
        world = own if world is None else world @ own
        worlds[each] = world
    return worlds[node]


def place_point(matrix: np.ndarray | None, point: Any) -> tuple[float, float, float]:
    """A point of a parent's space in the world (``matrix`` its world matrix)."""
    if matrix is None:
        return tuple(float(v) for v in point)
    moved = matrix @ np.append(np.asarray(point, dtype=np.float64), 1.0)
    return tuple(float(v) for v in moved[:3])


def place_direction(matrix: np.ndarray | None, direction: Any) -> tuple[float, float, float]:
    """A direction of a parent's space in the world: turned (not scaled: normalised to the
    length it had)."""
    if matrix is None:
        return tuple(float(v) for v in direction)
    given = np.asarray(direction, dtype=np.float64)
    turned = matrix[:3, :3] @ given
    length = float(np.linalg.norm(turned))
    if length > 0.0:
        turned *= float(np.linalg.norm(given)) / length
    return tuple(float(v) for v in turned)
