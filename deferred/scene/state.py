"""The frame state: the scene evaluated at one time, immutable.

:class:`FrameState` is what a frame reads (``Frame.scene``): the camera, every object's world
matrix and material parameters after events and tracks, the lights in the world, the effects
and the scene's settings, at ``time``. It is made by :class:`deferred.scene.timeline.
SceneEvaluator` and never changed; the user's :class:`~deferred.scene.scene.Scene` is never
written by a frame.

An :class:`ObjectState` has the attributes a pass and a material read of an object (``label``,
``mesh``, ``material`` with the parameters at the frame's time, ``model`` the world matrix),
``node`` the user's object it was evaluated from (what passes and caches key on), and
``version``: a number that changes whenever any of those does, so a cache may keep what it
made from a state while the version holds. Simulations read the object at other times through
:meth:`ObjectState.params_at` and :meth:`ObjectState.model_at`, which evaluate the same scene.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from deferred.interfaces import registry
from deferred.interfaces.material import compose_layout

if TYPE_CHECKING:
    from deferred.gbuffer.layout import GBufferLayout
    from deferred.gl.meshes import MeshData
    from deferred.interfaces.effect import Effect
    from deferred.interfaces.light import Light
    from deferred.interfaces.material import Material, MaterialParams
    from deferred.interfaces.shading import ShadingModel
    from deferred.scene.camera import Camera
    from deferred.scene.objects import SceneObject
    from deferred.scene.shadow_budget import ShadowBudget


class SceneContents:
    """What a scene's objects and lights need compiled, asked alike of the user's scene and of
    a frame's state (both have ``objects``, each with a ``material``, and ``lights``)."""

    objects: Any
    lights: Any

    def gbuffer_layout(self) -> GBufferLayout:
        """The G-buffer of this scene: the core plus the data its materials declare."""
        return compose_layout(obj.material for obj in self.objects)

    def shading_models(self) -> list[type[ShadingModel]]:
        """The shading models the scene's materials use, by id (only these are compiled)."""
        found = {registry.shading_models.get(obj.material.shading_model)
                 for obj in self.objects}
        return sorted(found, key=lambda cls: cls.type_id)

    def light_types(self) -> list[type[Light]]:
        """The light types of the scene, by id (only these are compiled)."""
        return sorted({type(light) for light in self.lights}, key=lambda cls: cls.type_id)


@dataclass(frozen=True, eq=False)
class ObjectState:
    """One object at the frame's time (see the module documentation)."""

    node: SceneObject
    label: str
    mesh: MeshData
    material: Material
    model: np.ndarray  # world, float64, read-only
    version: int
    # the world matrix at any time (the scene graph and the tracks): simulations step with it
    world_at: Callable[[float], np.ndarray] = field(repr=False)
    # the tracks that move the world matrix: the object's own and its ancestors'
    tracks: tuple = ()
    # a skinned object's joint matrices (J, 4, 4) in its own space (deferred.scene.skin)
    skin_matrices: np.ndarray | None = field(default=None, repr=False)

    @property
    def params(self) -> MaterialParams:
        """The material's parameters at the frame's time."""
        return self.material.params

    @property
    def base_params(self) -> MaterialParams:
        return self.node.base_params

    @property
    def events(self) -> tuple:
        return self.node.events

    @property
    def where(self) -> str | None:
        return self.node.where

    @property
    def event_times(self) -> tuple[float, ...]:
        return self.node.event_times

    def params_at(self, time: float) -> MaterialParams:
        """The material's parameters at ``time`` (the object's events over its base)."""
        return self.node.params_at(time)

    def model_at(self, time: float) -> np.ndarray:
        """The world matrix at ``time`` (its tracks and its parents')."""
        return self.world_at(time)


@dataclass(frozen=True, eq=False)
class FrameState(SceneContents):
    """The scene at ``time`` (see the module documentation). ``scene`` is the user's scene it
    was evaluated from, ``revision`` the scene's revision then."""

    time: float
    camera: Camera
    objects: tuple[ObjectState, ...]
    lights: tuple[Light, ...]
    effects: tuple[Effect, ...]
    size: tuple[int, int]
    background: tuple[float, float, float] | str  # a colour, or "environment"
    exposure: float
    tonemap: str
    light_path: str | None
    shadow_budget: ShadowBudget
    source: str
    scene: Any = field(repr=False)  # the user's Scene (deferred.scene.scene)
    revision: int = 0
    # by the user's object (nodes hash by identity: which object, not what it holds)
    _by_node: dict[SceneObject, ObjectState] = field(default_factory=dict, init=False,
                                                     repr=False)

    def __post_init__(self) -> None:
        self._by_node.update((state.node, state) for state in self.objects)

    def object_state(self, node: Any) -> ObjectState:
        """The state of the object ``node`` (a :class:`SceneObject`, or a state of it)."""
        return self._by_node[getattr(node, "node", node)]

    def has_object(self, node: Any) -> bool:
        return getattr(node, "node", node) in self._by_node
