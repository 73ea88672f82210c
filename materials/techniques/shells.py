"""Concentric shells (Revie 2.3.1; Lengyel et al. 2001): a mesh drawn n times, each pushed further
out, blended. The count follows the level of detail of the fur technique (``fur.shell_count``):
the first shell lies on the root, the others at the middles of the slabs of the layer
(``fur.shell_depth``), the outermost fades with the fraction of ``n``; the vertex shader offsets
them with ``shell_offset`` (``techniques/shells.glsl``, Listing 2.1).
"""

from __future__ import annotations

from typing import Any

from deferred.api import DEPTH, ObjectPass, Order

from .fur import FurParams, shell_count, shell_layout
from .fur_volume import VOLUME_LAYERS

ROOT_OFFSET = (-1.0, -2.0)  # glPolygonOffset (factor, units) of the root shell


class ShellPass(ObjectPass):
    """Draw the object's shells, innermost first, alpha-blended over the target. The object's
    material parameters are a ``FurParams``."""

    depth = DEPTH
    depth_test = True
    depth_func = "lequal"
    depth_write = False
    blend = "alpha"
    order = Order.VOLUME

    def layout(self, count: float, params: FurParams) -> list[tuple[float, float] | None]:
        """(depth, fade) of each draw for a continuous shell count, the root shell first (None:
        not drawn)."""
        return shell_layout(count, params.shell_range, params.debug)

    def slabs(self, count: float) -> float:
        """How many slabs the fur volume is cut into for ``count`` shells: each shell above
        the opaque root stands for one, its slices (``u_shell_weight``) the volume's share."""
        return count - 1.0

    def draws(self, frame) -> int:
        params = self.obj.material.params
        self._count = shell_count(frame, self.obj, params)
        self._layout = self.layout(self._count, params)
        return len(self._layout)

    def draw_uniforms(self, frame, index: int, count: int) -> dict[str, Any] | None:
        shell = self._layout[index]
        if shell is None:
            return None
        depth, fade = shell
        params = self.obj.material.params
        self._root = index == 0
        return {"u_shell_depth": depth, "u_shell_fade": fade, "u_root_shell": self._root,
                "u_shell_weight": VOLUME_LAYERS / max(self.slabs(self._count), 1e-6),
                "u_shell_count": self._count / max(params.shells, 1)}

    def draw(self, frame, program) -> None:
        # The root shell lies on the base mesh: pulled toward the eye it wins the depth test
        # even where obliteration restored a neighbour's depth. Only it: an offset on the
        # outer shells would pull them through occluders at grazing angles.
        frame.set_depth_offset(ROOT_OFFSET if self._root else (0.0, 0.0))
        super().draw(frame, program)
        frame.set_depth_offset((0.0, 0.0))
