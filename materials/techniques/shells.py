"""Concentric shells (Revie 2.3.1; Lengyel et al. 2001): a mesh drawn n times, each pushed further
out, blended. The count follows the level of detail of the fur technique (``fur.shell_count``):
the first shell lies on the root, the others at the middles of the slabs of the layer
(``fur.shell_depth``), the outermost fades with the fraction of ``n``; the vertex shader offsets
them with ``shell_offset`` (``materials/techniques/shells.glsl``, Listing 2.1).
"""

from __future__ import annotations

from typing import Any

from deferred.api import DEPTH, ObjectPass, Order, halton

from .fur import FurParams, shell_count, shell_layout
from .fur_volume import VOLUME_LAYERS

ROOT_OFFSET = (-1.0, -2.0)  # glPolygonOffset (factor, units) of the root shell


def shell_dither(sample_index: int) -> float:
    """Where in its slab a shell is drawn for sample ``sample_index`` (Frame.sample_index), as a
    fraction of the slab from its middle: 0 for sample 0 (a single frame), then the Halton
    sequence in base 5 (not 2 or 3, the jitter's, nor the stipple's period of 4). Averaged over
    samples (render --samples, taa under a still camera) a shell's rim covers its whole slab,
    not one step of a staircase at grazing angles."""
    return (halton(sample_index, 5) + 0.5) % 1.0 - 0.5


class ShellPass(ObjectPass):
    """Draw the object's shells, innermost first, alpha-blended over the target. The object's
    material parameters are a ``FurParams``.

    With ``dither`` the vertex stage offsets each shell but the root by ``u_shell_dither`` (of
    the layer's depth) beyond its ``u_shell_depth``, which its shading keeps: the geometry
    moves within the slab from sample to sample (:func:`shell_dither`), not the strands' colour
    or coverage: where the level of detail leaves few shells, moving those too would change the
    fur's brightness from sample to sample instead of only where its rim lies."""

    depth = DEPTH
    depth_test = True
    depth_func = "lequal"
    depth_write = False
    blend = "alpha"
    order = Order.VOLUME
    dither = False

    def layout(self, count: float, params: FurParams) -> list[tuple[float, float] | None]:
        """(depth, fade) of each draw for a continuous shell count, the root shell first (None:
        not drawn)."""
        return shell_layout(count, params.shell_range, params.debug)

    def slabs(self, count: float) -> float:
        """How many slabs the fur volume is cut into for ``count`` shells: each shell above
        the opaque root stands for one, its slices (``u_shell_weight``) the volume's share."""
        return count - 1.0

    def draws(self, frame) -> int:
        obj = self.object(frame)
        params = obj.params
        self._count = shell_count(frame, obj, params)
        self._layout = self.layout(self._count, params)
        if self.dither:
            # Not while a temporal history follows a moving camera or object: it keeps only a
            # small share of each frame there, too little to average the dither out, which
            # then shimmers (benchmarks/crawl.py measures it).
            moving = frame.moved_since_last_frame(obj)
            self._dither = 0.0 if moving else \
                shell_dither(frame.sample_index) / max(self.slabs(self._count), 1.0)
        return len(self._layout)

    def draw_uniforms(self, frame, index: int, count: int) -> dict[str, Any] | None:
        shell = self._layout[index]
        if shell is None:
            return None
        depth, fade = shell
        params = self.object(frame).params
        self._root = index == 0
        uniforms = {"u_shell_depth": depth, "u_shell_fade": fade, "u_root_shell": self._root,
                    "u_shell_weight": VOLUME_LAYERS / max(self.slabs(self._count), 1e-6),
                    "u_shell_count": self._count / max(params.shells, 1)}
        if self.dither:
            uniforms["u_shell_dither"] = 0.0 if self._root else self._dither
        return uniforms

    def draw(self, frame, program) -> None:
        # The root shell lies on the base mesh: pulled toward the eye it wins the depth test
        # even where obliteration restored a neighbour's depth. Only it: an offset on the
        # outer shells would pull them through occluders at grazing angles.
        frame.set_depth_offset(ROOT_OFFSET if self._root else (0.0, 0.0))
        super().draw(frame, program)
        frame.set_depth_offset((0.0, 0.0))
