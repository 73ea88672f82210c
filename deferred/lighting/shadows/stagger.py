"""Cascades updated in turn (``[shadows] cascade_updates = "staggered"``): while the camera
moves, a directional light's nearest cascade is fitted and drawn every frame and the farther
ones take turns, one a frame; a far cascade's map between its turns is the one drawn before,
read through the matrices it was drawn with (its record keeps its own light view and
projection; only the camera's view -> world in front of them is this frame's), so lookups stay
where the map's texels are.

A far cascade drawn while the camera moves is fitted to a sphere :data:`STAGGER_WIDEN` times
its slice's, so the map still holds the slice's sphere a frame or two later. Before a kept map
is used, its square is checked to hold this frame's sphere (and the filter's reach beyond it)
and its depth range the sphere and every caster toward the light; one that does not (the
camera moved or turned farther than the margin) is fitted and drawn again that frame. With the
camera still (its view as the last frame's), every cascade is fitted as with
``"every_frame"``: a still frame is that mode's image once the maps are drawn again.

Which frames' maps a frame reads depends on the frames before it: not for renders whose frames
must not depend on each other (``deferred render`` and the farm default to ``"every_frame"``;
the viewer to ``"staggered"``).
"""

from __future__ import annotations

import numpy as np

from deferred.errors import InputError
from deferred.interfaces.light import Light
from deferred.lighting.shadows.frusta import (
    CascadeSlice,
    cascade_frustum,
    filter_margin,
    near_far,
)
from deferred.names import CascadeUpdates

# a far cascade's sphere, widened while the camera moves: its slice's sphere may move by a
# tenth of its radius (a turn of about 5 degrees for the farthest) before the kept map is
# drawn again
STAGGER_WIDEN = 1.1

__all__ = ["STAGGER_WIDEN", "StaggeredCascades", "check_cascade_updates", "covers"]


def check_cascade_updates(value: str | None, where: str) -> CascadeUpdates | None:
    """``value`` as a :class:`~deferred.names.CascadeUpdates` (None stays None), or one line
    naming ``where``."""
    if value is None:
        return None
    try:
        return CascadeUpdates(value)
    except ValueError:
        choices = " or ".join(mode.value for mode in CascadeUpdates)
        raise InputError(f"must be {choices} (got {value!r})", where) from None


def covers(frustum: tuple, cascade: CascadeSlice, margin_texels: float) -> bool:
    """Whether the map of ``frustum`` (an orthographic cascade's, in the light's view
    ``cascade.light_view``) holds ``cascade``'s sphere with ``margin_texels`` of its texels
    beyond it on each side, and its depth range the sphere and the scene's casters toward the
    light."""
    _, light_view, projection, texel, _, _ = frustum
    if not np.array_equal(light_view, cascade.light_view):
        return False
    centre, radius = cascade.centre, cascade.radius
    reach = radius + margin_texels * texel
    for axis in (0, 1):
        # x_ndc = p[a, a] x + p[a, 3]: the map's side along the axis
        scale, offset = float(projection[axis, axis]), float(projection[axis, 3])
        low, high = (-1.0 - offset) / scale, (1.0 - offset) / scale
        if centre[axis] - reach < low or centre[axis] + reach > high:
            return False
    near, far = near_far(projection)
    return near <= -max(centre[2] + radius, cascade.top) and far >= -(centre[2] - radius)


class StaggeredCascades:
    """Which cascades are fitted again each frame, and the frustum each light's cascade was
    last fitted to, with its square of the atlas (a cascade planned onto another square is
    drawn there afresh)."""

    def __init__(self) -> None:
        # (id(light), cascade) -> (its square (x, y, size), its frustum)
        self.kept: dict[tuple[int, int], tuple[tuple[int, int, int], tuple]] = {}
        self._view: np.ndarray | None = None
        self.moving = False  # the camera's view differs from the last frame's
        self._moving_frames = 0

    def start_frame(self, view: np.ndarray) -> None:
        """This frame's camera (world -> view): whether it moved since the last frame."""
        self.moving = self._view is not None and not np.array_equal(view, self._view)
        self._view = np.array(view, np.float64)
        if self.moving:
            self._moving_frames += 1

    def turn(self, cascades: int) -> int:
        """The far cascade fitted again this moving frame: 1, 2, .., ``cascades`` - 1 in turn
        (with two cascades, the second every other frame)."""
        return 1 + self._moving_frames % max(cascades - 1, 2)

    def frusta(self, light: Light, slices: list[CascadeSlice],
               squares: list[tuple[int, int, int]], mode: str) -> list[tuple]:
        """The frusta of ``light``'s cascades this frame (``squares``: theirs in the atlas):
        fitted to this frame's slices, or, staggered while the camera moves, kept where a
        far cascade's turn has not come and its map still covers its slice."""
        resolution = squares[0][2]
        staggered = mode == CascadeUpdates.STAGGERED and self.moving
        turn = self.turn(len(slices))
        margin = filter_margin(light.params)
        out = []
        for index, (cascade, square) in enumerate(zip(slices, squares, strict=True)):
            kept_square, kept = self.kept.get((id(light), index), (None, None))
            if kept_square != square:
                kept = None
            if not staggered or index == 0:
                frustum = cascade_frustum(cascade, resolution)
            elif index != turn and kept is not None and covers(kept, cascade, margin):
                frustum = kept
            else:
                frustum = cascade_frustum(cascade, resolution, STAGGER_WIDEN)
            self.kept[(id(light), index)] = (square, frustum)
            out.append(frustum)
        return out
