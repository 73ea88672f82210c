"""What a material's surface does over time: its motion beyond the object's (:class:`Motion`,
the material's ``motion``) and the state it simulates for each object (:class:`Simulation`,
its ``simulation``).

A simulation's state at time t depends only on the scene and t (it steps from t = 0, or from
where it was for a later time): frames may come in any order. The renderer brings every
object's state to the frame's time before the frame's passes run (:func:`advance_simulations`);
the passes, the shadow casters and the inputs read it through :meth:`Simulation.state`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from deferred.errors import DeferredError, RenderError, gl_error

if TYPE_CHECKING:
    import moderngl

    from deferred.core.frame import Frame
    from deferred.core.protocols import SceneObjectLike
    from deferred.gl.meshes import GpuMesh
    from deferred.interfaces.work import RenderWork, Work, WorkObject

SIMULATED = "simulated"  # a frame's blackboard: (key, node) -> the state brought to its time


@dataclass(frozen=True)
class MotionOffsets:
    """Where what a material draws at its reach moves on its own (a simulated strand tip in the
    wind): per-vertex object-space offsets, this frame's and the last frame's, in RGBA32F
    textures holding vertex i's at texel ``stride * i`` (rows of the texture's width)."""

    current: moderngl.Texture
    previous: moderngl.Texture
    stride: int = 1


class Motion:
    """How far, in object units along the mesh's normals, what a material draws for an object
    reaches beyond the mesh (fur shells and fins, hair): motion vectors are drawn over the mesh
    pushed out that far (``deferred.effects.taa``), so the pixels of those layers move with
    the object. By default nothing: the material draws its mesh. :meth:`offsets` adds where
    that reach moves by itself between frames (wind), else the layers move with the mesh;
    :meth:`surfaces` the meshes a material draws besides the object's that move on their own
    (hair tubes), drawn over it as they are."""

    def extent(self, obj: SceneObjectLike) -> float:
        return 0.0

    def offsets(self, frame: Frame, obj: SceneObjectLike) -> MotionOffsets | None:
        """This frame's and the last frame's offsets of the reach, or ``None``: none."""
        return None

    def surfaces(self, frame: Frame, obj: SceneObjectLike) -> tuple[GpuMesh, ...]:
        """Meshes the material draws for ``obj`` besides its mesh whose vertices move on their
        own (simulated hair's tubes), each a moving ``GpuMesh`` with ``keeps_previous``: its
        motion vectors are each vertex's way from the surface of the frame before
        (``previous_vbo``, placed by the last frame's model) to this frame's. By default
        none."""
        return ()


class ReachMotion(Motion):
    """The material draws up to its parameter ``parameter`` (object units) beyond the mesh:
    ``ReachMotion("fur_length")``."""

    def __init__(self, parameter: str):
        self.parameter = parameter

    def extent(self, obj: SceneObjectLike) -> float:
        return float(getattr(obj.material.params, self.parameter))


class Simulation(ABC):
    """A state a material keeps for each of its objects and brings to each frame's time: one per
    object and renderer, made by :meth:`start` the first time it is asked for, kept in the
    renderer's resources under ``(key, obj.node)`` (so it needs ``release()``) and released with
    them.

    :meth:`check_time` refuses, before any frame, a time the simulation cannot reach in bounded
    work; :meth:`held_memory` says what the state holds, counted against the memory budget with
    the render targets."""

    key: str = ""  # names the states among the renderer's resources (the material's, say)

    @abstractmethod
    def start(self, ctx: moderngl.Context, obj: SceneObjectLike) -> Any:
        """A new state for ``obj`` (the object as the first frame asking has it)."""

    @abstractmethod
    def advance(self, state: Any, frame: Frame, obj: SceneObjectLike) -> None:
        """Bring ``state`` to ``frame.time`` for ``obj`` as the frame has it (once a frame)."""

    def check_time(self, obj: SceneObjectLike, time: float,  # noqa: B027 - optional
                   where: str) -> None:
        """Refuse (``InputError`` naming ``where``) a frame ``time`` the simulation cannot
        reach for ``obj`` in bounded work (steps from 0, work growing with the mesh)."""

    def held_memory(self, obj: SceneObjectLike) -> dict[str, int]:
        """Bytes the state of ``obj`` will hold by what they are (see
        ``Material.held_memory``)."""
        return {}

    def work(self, obj: WorkObject, job: RenderWork) -> list[Work]:
        """The work of bringing ``obj``'s state to the latest time of ``job`` (steps from 0),
        as the cost model counts it (:mod:`deferred.interfaces.work`). By default none."""
        return []

    def state(self, frame: Frame, obj: SceneObjectLike) -> Any:
        """``obj``'s state at the frame's time: made the first time, advanced once a frame."""
        advanced = frame.blackboard.setdefault(SIMULATED, {})
        key = (self.key, obj.node)
        state = advanced.get(key)
        if state is None:
            state = frame.resources.cached(key, lambda ctx: self.start(ctx, obj))
            self.advance(state, frame, obj)
            advanced[key] = state
        return state


def advance_simulations(frame: Frame) -> None:
    """Bring every simulated object of the frame to its time, before any pass runs (so every
    pass, caster and input of an object sees one state); a failure names the object."""
    for obj in frame.scene.objects:
        simulation = obj.material.simulation
        if simulation is None:
            continue
        try:
            simulation.state(frame, obj)
        except DeferredError:
            raise
        except Exception as exc:  # noqa: BLE001 - a plugin's simulation: say whose
            raise RenderError(f"object {obj.label}: simulating {obj.material.name}: "
                              f"{type(exc).__name__}: {exc}") from exc
        error = frame.ctx.error  # a simulation's GL work (compute shaders) checked apart
        if error != "GL_NO_ERROR":
            raise gl_error(f"object {obj.label}: simulating {obj.material.name}", error,
                           (frame.width, frame.height))
