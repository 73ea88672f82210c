"""Concentric shells (Revie 2.3.1): a mesh drawn N times, each pushed further out, blended.

Shell ``k`` of ``N`` sits at depth ``(k + 1) / N`` of the fur layer (so the last one is the
outermost shell, where the stipple samples live); the vertex shader offsets it with
``shell_offset`` (``techniques/shells.glsl``, Listing 2.1).
"""

from __future__ import annotations

from typing import Any

from deferred.gbuffer import DEPTH
from deferred.passes import ObjectPass, Order


def shell_depths(count: int) -> list[float]:
    return [(k + 1) / count for k in range(count)]


class ShellPass(ObjectPass):
    """Draw ``count`` shells of the object, innermost first, alpha-blended over the target."""

    depth = DEPTH
    depth_test = True
    depth_func = "lequal"
    depth_write = False
    blend = "alpha"
    order = Order.VOLUME
    count = 16

    def draws(self, frame) -> int:
        return self.count

    def draw_uniforms(self, frame, index: int, count: int) -> dict[str, Any]:
        return {"u_shell_depth": (index + 1) / count}
