"""What the core asks of the layers above it: the shapes of a scene, its objects and their
materials as passes see them, a resource that binds itself to every program, and the per-frame
source of an object's inputs. The layers above implement them (``deferred.scene``,
``deferred.interfaces``, ``deferred.lighting``, ``deferred.render``); the core names no class of
theirs.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

if TYPE_CHECKING:
    from deferred.gl.meshes import MeshData
    from deferred.gl.uniforms import ProgramUniforms


class CameraLike(Protocol):
    near: float
    far: float

    def view(self) -> np.ndarray: ...
    def projection(self, aspect: float) -> np.ndarray: ...
    def inverse_projection(self, aspect: float) -> np.ndarray: ...


class SceneObjectLike(Protocol):
    """An object as an object pass draws it (:class:`deferred.scene.ObjectState`: the object at
    the frame's time; a :class:`deferred.scene.SceneObject` has the same attributes). ``node``
    is the user's object, what the frame's state is keyed by."""

    node: Any
    label: str
    mesh: MeshData
    material: Any  # a Material (deferred.interfaces.material)
    model: np.ndarray


class SceneLike(Protocol):
    """A frame's scene as the core reads it (:class:`deferred.scene.FrameState`: the scene
    evaluated at the frame's time)."""

    camera: CameraLike
    objects: tuple

    def object_state(self, node: Any) -> SceneObjectLike: ...


class PassLike(Protocol):
    """A pass as the frame runs it (:class:`deferred.core.passes.RenderPass`)."""

    name: str
    creates: Mapping[str, Any]
    reads: tuple[str, ...]
    writes: tuple[str, ...]

    def execute(self, frame: Any) -> None: ...


class BindingSource(Protocol):
    """A per-frame resource every program may read (the light buffer, the light lists, the
    shading models' samplers): the frame offers it to each program it binds."""

    def bind(self, uniforms: ProgramUniforms, texture_unit: int) -> int:
        """Set this source's uniforms and samplers where the program has them, samplers from
        ``texture_unit`` on; the next free unit."""
        ...


class ObjectInputs(Protocol):
    """Where a frame finds an object's transforms and its material's inputs
    (:class:`deferred.render.caches.FrameInputs`); ``frame`` is set by the frame it serves."""

    frame: Any

    def object_uniforms(self, obj: Any) -> dict[str, Any]: ...
    def material_inputs(self, material: Any) -> Any: ...  # a MaterialInputs
