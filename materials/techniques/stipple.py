"""Stippled rendering (Revie 2.3.4, Listing 2.6) and stipple obliteration (2.4.4).

A stipple pass writes a mesh into the G-buffer at one pixel in two or four; the lighting phase
lights those samples like any other; a material-phase pass then reads them back and erases them
from the composition buffer. ``STIPPLE_PATTERN`` (2 or 4) selects the pattern in
``materials/techniques/stipple.glsl``.

Obliteration restores what the composition holds, not the raw light: after every material's own
opaque pass (``Order.OPAQUE``), one scene-wide pass snapshots the composition
(:func:`stipple_scene_passes`, shared by every stipple user) and each obliteration copies the
neighbouring pixel from that snapshot, so a material that altered its pixels keeps its look
under another's stipple samples.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from deferred.api import (
    COMPOSITE,
    COMPOSITE_SPEC,
    DEPTH,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    GBufferPass,
    ObjectPass,
    Order,
    PassInput,
    Phase,
    RenderPass,
    Technique,
    copy_pass,
)

if TYPE_CHECKING:
    from deferred.api import Material, SceneObject

PATTERNS = (2, 4)
COMPOSITE_SNAPSHOT = "composite_snapshot"


def stipple_scene_passes(phase: Phase) -> list[RenderPass]:
    """The once-per-scene pass obliteration needs: in the material phase, the composition as
    materials' opaque passes left it (every stipple user returns it; it runs once)."""
    if phase != Phase.MATERIAL:
        return []
    return [copy_pass("material.stipple_snapshot", Phase.MATERIAL, COMPOSITE,
                      COMPOSITE_SNAPSHOT, COMPOSITE_SPEC, order=Order.RESTORE)]


def pattern_defines(pattern: int, parity: tuple[int, int] = (0, 0)) -> dict[str, str]:
    """Defines of ``materials/techniques/stipple.glsl``: the pattern (1 in 2 or 1 in 4) and the
    parity class of the user (Revie 2.3.4: different users interleave instead of overwriting each
    other's samples; fur takes (0, 0), glass (1, 1) or the odd checkerboard)."""
    if pattern not in PATTERNS:
        raise ValueError(f"stipple pattern must be one of {PATTERNS}, got {pattern}")
    return {"STIPPLE_PATTERN": str(pattern),
            "STIPPLE_PARITY": f"ivec2({parity[0] % 2}, {parity[1] % 2})"}


class StipplePass(GBufferPass):
    """Stipple phase: a mesh into the G-buffer at the pattern's pixels only (fragment shader
    decides, via ``stipple_sample``)."""


class StippleObliterationPass(ObjectPass):
    """Material phase: where this mesh's stipple samples sit in the composition buffer, copy the
    neighbouring pixel's composition (from the snapshot) and depth over them
    (``materials/techniques/stipple_obliterate.frag``).

    Drawn with the same vertex shader and uniforms as the stipple pass; a pixel is treated as a
    stipple sample only if the G-buffer there holds this material at this fragment's depth.
    """

    fragment = "materials/techniques/stipple_obliterate.frag"
    colors = (COMPOSITE,)
    depth = DEPTH
    depth_test = True
    depth_func = "always"  # the pass writes depth (gl_FragDepth) wherever it keeps a fragment
    order = Order.RESTORE
    extra_reads = (COMPOSITE_SNAPSHOT, LINEAR_DEPTH, NORMAL_EXPONENT_ID)


class Stipple(Technique):
    """A material's stippled surface: in the stipple phase ``<label>.stipple``, a
    :class:`StipplePass` through ``fragment`` (a stipple pattern writer); in the material phase
    ``<label>.stipple_obliteration``, its samples erased; once per scene the composition's
    snapshot obliteration copies from (:func:`stipple_scene_passes`). Both passes draw through
    ``vertex`` with ``inputs``; ``constants(obj)`` gives uniforms fixed when they are made;
    ``when(material)`` whether the material stipples (always, by default)."""

    def __init__(self, fragment: str, *, vertex: str | None = None,
                 inputs: Sequence[PassInput] = (),
                 constants: Callable[[SceneObject], dict[str, Any]] | None = None,
                 when: Callable[[Material], bool] | None = None):
        self.fragment = fragment
        self.options: dict[str, Any] = {"inputs": tuple(inputs)}
        if vertex is not None:
            self.options["vertex"] = vertex
        self.constants = constants
        self.when = when

    def passes(self, material: Material, phase: Phase, obj: SceneObject) -> list[RenderPass]:
        if phase not in (Phase.STIPPLE, Phase.MATERIAL) or \
                (self.when is not None and not self.when(material)):
            return []
        options = dict(self.options)
        if self.constants is not None:
            options["constants"] = self.constants(obj)
        if phase == Phase.STIPPLE:
            return [StipplePass(f"{obj.label}.stipple", phase, obj, fragment=self.fragment,
                                **options)]
        return [StippleObliterationPass(f"{obj.label}.stipple_obliteration", phase, obj,
                                        **options)]

    def scene_passes(self, objects: Sequence[SceneObject], phase: Phase) -> list[RenderPass]:
        stippled = self.when is None or any(self.when(obj.material) for obj in objects)
        return stipple_scene_passes(phase) if stippled else []
