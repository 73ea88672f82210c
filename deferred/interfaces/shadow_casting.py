"""How a material's objects cast shadows: a :class:`ShadowCaster`, the material's ``shadow``.

The shadow pass (``deferred.lighting.shadows``) asks each object's material's caster to draw
the object into a shadow map (:meth:`ShadowCaster.draw`, the mesh's depth by default), for a
volume that shadows itself (fur) into the deep opacity maps
(:meth:`ShadowCaster.draw_opacity`) and, for a surface that lets coloured light through
(glass), into the transmittance maps (:meth:`ShadowCaster.draw_transmittance`). A material
whose look is not its mesh gives a caster of its own; one that casts nothing gives
:class:`NoShadow`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from collections.abc import Hashable

    from deferred.core.frame import Frame
    from deferred.core.protocols import SceneObjectLike

SHADOW_CASTER_VERTEX = "shadows/caster.vert"
SHADOW_CASTER_FRAGMENT = "shadows/caster.frag"


# A vertex shader of the camera (``u_view``, ``u_projection``) compiled with these defines
# draws from the light instead, reading :attr:`ShadowView.camera_uniforms`: how a material's
# own vertex stage (fur shells, displaced strands) becomes its shadow caster's.
SHADOW_CASTER_DEFINES = {"u_view": "u_shadow_view", "u_projection": "u_shadow_projection",
                         "SHADOW_CASTER": "1"}


@dataclass(frozen=True)
class ShadowView:
    """One shadow map being drawn (:meth:`ShadowCaster.draw`): the light's world -> view
    and view -> clip matrices, where the light is (a world position, or ``None`` for a
    directional light) and the direction it shines (world, unit), for casters that shape
    themselves to it. ``opacity_maps``: the light has deep opacity maps this frame, which
    every caster with :meth:`~ShadowCaster.opacity_shadows` draws its object into
    (:meth:`ShadowCaster.draw_opacity`) and through which the other surfaces take its shadow
    (``lighting/shadows.glsl``): such a volume may leave its translucent part out of the depth
    map."""

    view: np.ndarray
    projection: np.ndarray
    position: np.ndarray | None
    direction: np.ndarray
    opacity_maps: bool = False

    @property
    def uniforms(self) -> dict[str, Any]:
        """``u_shadow_view_projection``: what ``shadows/caster.vert`` reads."""
        return {"u_shadow_view_projection": self.projection @ self.view}

    @property
    def camera_uniforms(self) -> dict[str, Any]:
        """The light as the camera of a vertex shader compiled with
        :data:`SHADOW_CASTER_DEFINES`."""
        return {"u_shadow_view": self.view, "u_shadow_projection": self.projection}


class ShadowCaster:
    """How the objects of a material cast shadows (``Material.shadow``): by default the mesh,
    depth only, through ``shadows/caster.vert``.

    A volume that shadows itself (fur; ``deferred.lighting.shadows``) answers
    :meth:`opacity_shadows` for an object, draws itself into the deep opacity maps
    (:meth:`draw_opacity`) and its receivers compile with ``OPACITY_RECEIVER``; with
    ``deferred_opacity`` its deferred passes read the maps too (the forward passes of such a
    material always do). Every method receives the object as the frame has it (``obj``: its
    state, ``obj.material`` the material with the parameters at the frame's time)."""

    deferred_opacity: bool = False

    def draw(self, frame: Frame, obj: SceneObjectLike, view: ShadowView) -> None:
        """Draw ``obj``'s depth into the shadow map ``view`` (the framework has bound that
        tile of the shadow atlas, cleared it and set depth-only state: depth test, no culling,
        a slope-scaled depth offset). A caster whose look is not its mesh (fur shells,
        displaced strands) draws that, with ``view.uniforms`` and a vertex stage of its own."""
        program = frame.shaders.program(SHADOW_CASTER_VERTEX, SHADOW_CASTER_FRAGMENT)
        frame.bind(program, view.uniforms, offered=frame.object_uniforms(obj))
        frame.draw_mesh(obj.mesh, program)

    def cache_key(self, frame: Frame, obj: SceneObjectLike) -> Hashable:
        """What :meth:`draw` and :meth:`draw_opacity` of ``obj`` depend on this frame beyond
        the object's state and the map (the framework keys a map's depths on its light,
        square and each caster's ``ObjectState.version``, and keeps them while those hold):
        a caster drawing what the camera decides (a level of detail) returns it. By default
        nothing."""
        return ()

    def opacity_shadows(self, obj: SceneObjectLike) -> bool:
        """Whether ``obj`` is a volume drawn into the deep opacity maps."""
        return False

    def opacity_layer(self, obj: SceneObjectLike) -> float:
        """World thickness of ``obj``'s volume (the opacity layers span a few of the
        thickest)."""
        return 0.0

    def draw_opacity(self, frame: Frame, obj: SceneObjectLike, view: ShadowView,
                     stage: str) -> None:
        """Draw ``obj``'s volume into the deep opacity maps of ``view`` (where
        :meth:`opacity_shadows`): ``stage`` "first", the light-view depth of its outer
        surface (which every point it draws lies inside) as (depth, -depth, 0, 0) into an
        RG32F target with min blending, no depth test: its front and its back along each
        texel; "density", its optical depth times the volume's density factor (what lies behind
        it keeps exp(-the layers' sum) of the light), added into the four layers behind that
        front (``u_opacity_first``, ``u_opacity_layers``), blended additively."""


    def draw_with(self, frame: Frame, obj: SceneObjectLike, view: ShadowView,
                  fragment: str) -> None:
        """Draw ``obj``'s mesh from the light with the fragment shader ``fragment``, which
        reads the material's uniforms and textures (a transmittance of the material's
        colour): ``shadows/caster.vert`` and ``view.uniforms``."""
        program = frame.shaders.program(SHADOW_CASTER_VERTEX, fragment)
        frame.bind(program, view.uniforms, offered=frame.object_uniforms(obj),
                   material=frame.material_inputs(obj.material))
        frame.draw_mesh(obj.mesh, program)

    def transmits(self, obj: SceneObjectLike) -> bool:
        """Whether ``obj`` lets light through, coloured (glass): it then draws no depth
        (:meth:`draw` draws nothing for it) and draws its transmittance instead
        (:meth:`draw_transmittance`)."""
        return False

    def draw_transmittance(self, frame: Frame, obj: SceneObjectLike, view: ShadowView) -> None:
        """Draw ``obj`` into the transmittance maps of ``view`` (where :meth:`transmits`):
        two outputs, its transmittance (RGB; multiplied into what the texel holds) and its
        depth along the light (``gl_FragCoord.z``; the nearest kept), depth-tested against
        the opaque casters. The framework has bound the maps' tile, cleared it and set that
        state (``deferred.lighting.shadows.transmittance``); :meth:`draw_with` draws the mesh
        with a fragment shader of the caster's."""


class NoShadow(ShadowCaster):
    """A material whose objects cast no shadow."""

    def draw(self, frame: Frame, obj: SceneObjectLike, view: ShadowView) -> None:
        pass
