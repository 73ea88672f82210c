"""Concentric shells (Revie 2.3.1; Lengyel et al. 2001): a mesh drawn n times, each pushed further
out, blended. The count follows the level of detail of the fur technique (``fur.shell_count``):
shell ``k`` sits at depth ``k / n`` of the fur layer (the first at the root), the outermost fades
with the fraction of ``n``; the vertex shader offsets it with ``shell_offset``
(``techniques/shells.glsl``, Listing 2.1).
"""

from __future__ import annotations

from typing import Any

from deferred.gbuffer import DEPTH
from deferred.passes import ObjectPass, Order

from .fur import shell_count, shell_layout
from .fur_volume import VOLUME_LAYERS


class ShellPass(ObjectPass):
    """Draw the object's shells, innermost first, alpha-blended over the target. The object's
    material parameters are a ``FurParams``."""

    depth = DEPTH
    depth_test = True
    depth_func = "lequal"
    depth_write = False
    blend = "alpha"
    order = Order.VOLUME
    # The root shell lies on the base mesh: pulled toward the eye it wins the depth test even
    # where obliteration restored a neighbour's depth.
    depth_offset = (-1.0, -2.0)

    def draws(self, frame) -> int:
        params = self.obj.material.params
        self._count = shell_count(frame, self.obj, params)
        self._layout = shell_layout(self._count, params.shell_range, params.debug)
        return len(self._layout)

    def draw_uniforms(self, frame, index: int, count: int) -> dict[str, Any] | None:
        shell = self._layout[index]
        if shell is None:
            return None
        depth, fade = shell
        params = self.obj.material.params
        return {"u_shell_depth": depth, "u_shell_fade": fade, "u_root_shell": index == 0,
                "u_shell_weight": VOLUME_LAYERS / self._count,
                "u_shell_count": self._count / max(params.shells, 1)}
