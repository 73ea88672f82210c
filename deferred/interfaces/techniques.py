"""Techniques: the passes a material contributes, composed (``Material.techniques``).

A technique gives passes per object and phase (:meth:`Technique.passes`) and, once per scene,
scene-wide ones (:meth:`Technique.scene_passes`). A material's passes are its techniques', in
their order: :class:`SurfacePasses` (its surface into the G-buffer, and lit in the forward
pipeline: every material's by default), then what it adds (stipple, shells, strokes...).
:class:`PhasePasses` adds the passes a function makes in one phase.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from deferred.core.passes import ObjectPass, PassInput, Phase, RenderPass, Shape
from deferred.gbuffer.layout import DEPTH
from deferred.gl.targets import COMPOSITE
from deferred.interfaces.effect import AMBIENT_OCCLUSION

if TYPE_CHECKING:
    from deferred.core.protocols import SceneObjectLike

# The material asking for passes (a deferred.interfaces.material.Material, which is made of
# techniques: this module cannot import it)
Material = Any


class GBufferPass(ObjectPass):
    """Geometry phase: the material's surface written into the G-buffer: the core targets and
    the G-buffer data the material declares (``Material.gbuffer_targets``)."""

    fragment = "gbuffer/geometry.frag"
    depth = DEPTH

    def __init__(self, name: str, phase: Phase, obj: SceneObjectLike, **options: Any):
        options.setdefault("colors", obj.material.gbuffer_targets())
        super().__init__(name, phase, obj, **options)


class ForwardLitPass(ObjectPass):
    """Forward pipeline: the material's surface lit by every light in one pass (``lequal``:
    Forward+ lays the same depth down in its pre-pass first)."""

    fragment = "forward/lit.frag"
    colors = (COMPOSITE,)
    depth = DEPTH
    depth_func = "lequal"

    def read_occlusion(self) -> None:
        """Take the ambient occlusion a screen effect found for the surface at each pixel (the
        target ``ssao``, sampled as ``u_ssao`` by ``common/forward_lighting.glsl`` with
        ``SCREEN_OCCLUSION``): the forward pipeline's, where it writes the G-buffer first, for
        its opaque lit passes (the surfaces the occlusion was found for). Called before the
        pass graph is checked."""
        self.extra_reads = (*self.extra_reads, AMBIENT_OCCLUSION)
        self.extra_defines = {**(self.extra_defines or {}), "SCREEN_OCCLUSION": "1"}
        self.samples = tuple(dict.fromkeys([*self.samples, AMBIENT_OCCLUSION]))
        self.reads = tuple(dict.fromkeys([*self.reads, AMBIENT_OCCLUSION]))
        self._plain = False


class Technique:
    """Passes a material contributes. ``material`` is the material asking (its ``params``
    say what to draw: a timeline's check asks a changed material about an object that does not
    have it yet); ``obj`` the object the passes are for (its ``label`` names them)."""

    def passes(self, material: Material, phase: Phase,
               obj: SceneObjectLike) -> list[RenderPass]:
        """The passes for ``obj`` in ``phase`` (none by default)."""
        return []

    def scene_passes(self, objects: Sequence[SceneObjectLike],
                     phase: Phase) -> list[RenderPass]:
        """Passes once per scene, not per object, in ``phase`` (scene-wide setup, a screen or
        post pass of the technique's own); ``objects`` are the scene's objects of the
        material. Passes of one name from several materials run once."""
        return []


Constants = Callable[["SceneObjectLike"], dict[str, Any]]


class SurfacePasses(Technique):
    """The material's surface: a :class:`GBufferPass` (geometry phase, ``<label>.gbuffer``)
    and a :class:`ForwardLitPass` (forward pipeline, ``<label>.forward``). Options go to both:
    ``vertex`` (a vertex stage of the material's own), ``inputs`` and ``shape`` (see
    ``ObjectPass``), ``constants`` (a function of the object: uniforms fixed when the passes
    are made), ``extra_defines``; ``name`` names both passes ``<label>.<name>`` (a second
    surface of the object, as the hair's tubes are); ``gbuffer`` and ``forward`` are the pass
    classes (subclasses of the two, for a pass with hooks of its own)."""

    def __init__(self, *, vertex: str | None = None, inputs: Sequence[PassInput] = (),
                 shape: Shape | None = None, constants: Constants | None = None,
                 extra_defines: dict[str, str] | None = None, name: str | None = None,
                 gbuffer: type[GBufferPass] = GBufferPass,
                 forward: type[ForwardLitPass] = ForwardLitPass):
        self.kinds = {Phase.GEOMETRY: (gbuffer, "gbuffer"), Phase.FORWARD: (forward, "forward")}
        self.options: dict[str, Any] = {}
        if vertex is not None:
            self.options["vertex"] = vertex
        if inputs:
            self.options["inputs"] = tuple(inputs)
        if shape is not None:
            self.options["shape"] = shape
        if extra_defines:
            self.options["extra_defines"] = dict(extra_defines)
        self.constants = constants
        self.name = name

    def passes(self, material: Material, phase: Phase,
               obj: SceneObjectLike) -> list[RenderPass]:
        if phase not in self.kinds:
            return []
        kind, suffix = self.kinds[phase]
        options = dict(self.options)
        if self.constants is not None:
            options["constants"] = self.constants(obj)
        return [kind(f"{obj.label}.{self.name or suffix}", phase, obj, **options)]


PassBuilder = Callable[[Material, "SceneObjectLike"], list[RenderPass]]


class PhasePasses(Technique):
    """The passes ``build(material, obj)`` makes, in ``phase`` only: a material's pass of its
    own, ``PhasePasses(Phase.MATERIAL, tint_pass)``."""

    def __init__(self, phase: Phase, build: PassBuilder):
        self.phase = phase
        self.build = build

    def passes(self, material: Material, phase: Phase,
               obj: SceneObjectLike) -> list[RenderPass]:
        return list(self.build(material, obj)) if phase == self.phase else []
