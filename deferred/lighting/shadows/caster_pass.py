"""The shadow pass: each shadowed light's tiles of the atlas cleared and the casters it reaches
drawn into them by their materials; then, where the scene has them, the transparent casters'
transmittance maps and the volumes' deep opacity maps. A tile drawn before with the same light,
square and casters, each as it was, is not drawn again (the atlas keeps its depths and
transmittances from frame to frame): a still light and still casters cost nothing after their
first frame, whatever the camera does (but for cascades, which follow it, each frame or in
turn: :mod:`~deferred.lighting.shadows.stagger`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from deferred.core.passes import Order, Phase, RenderPass
from deferred.lighting.shadows.atlas import SHADOW_ATLAS, ShadowAtlas, ShadowTile
from deferred.lighting.shadows.bounds import object_sphere
from deferred.lighting.shadows.opacity import OPACITY_FAR, OPACITY_FRONT_FRAGMENT
from deferred.lighting.shadows.transmittance import TRANSMITTANCE_BLEND

if TYPE_CHECKING:
    from deferred.core.frame import Frame


def caster_key(frame: Frame, obj) -> tuple:
    """What ``obj``'s drawing into a shadow map depends on besides the map: its state's
    version (mesh, material parameters, world matrix, joints), the frame's time where its
    material simulates (its state follows the time), and what its caster adds
    (:meth:`~deferred.interfaces.shadow_casting.ShadowCaster.cache_key`)."""
    material = obj.material
    return (obj.version, frame.time if material.simulation is not None else None,
            material.shadow.cache_key(frame, obj))


# the caster pass's slope-scaled depth offset (glPolygonOffset factor, units): with the
# lookup's normal offset and depth bias (texels), no acne down to grazing light
CASTER_DEPTH_OFFSET = (1.5, 2.0)


class ShadowPass(RenderPass):
    """Every shadowed light's maps: each tile of the atlas cleared and each object's depth
    drawn into it by its material's caster
    (:meth:`~deferred.interfaces.shadow_casting.ShadowCaster.draw`).
    The atlas is not a frame target; the pass writes none (dumps read the atlas apart)."""

    order = Order.FIRST

    def __init__(self, phase: Phase):
        self.name = "shadows"
        self.phase = phase

    def execute(self, frame: Frame) -> None:
        atlas: ShadowAtlas = frame.blackboard[SHADOW_ATLAS]
        if not atlas.tiles:
            return
        objects = frame.scene.objects
        spheres = [object_sphere(obj) for obj in objects]

        def reached(tile: ShadowTile) -> list:
            return [obj for obj, (centre, radius) in zip(objects, spheres, strict=True)
                    if tile.casts(centre, radius)]

        # a tile whose light, square and casters (each as it draws: caster_key) are those it
        # was last drawn with holds their depths still: it is not drawn again
        drawn = []
        for tile in atlas.tiles:
            casters = reached(tile)
            key = (tile.slot, tile.view_projection.tobytes(), atlas.opacity_layer,
                   tuple(caster_key(frame, obj) for obj in casters))
            rect = (tile.x, tile.y, tile.size)
            if atlas.drawn.get(rect) != key:
                atlas.mark_drawn(rect, key)
                drawn.append((tile, casters))
        if not drawn:
            return
        fbo = atlas.framebuffer
        frame.gl_call(fbo.use)
        fbo.depth_mask = True
        frame.set_state(depth_test=True, depth_func="less", cull=None,
                        depth_offset=CASTER_DEPTH_OFFSET)
        try:
            for tile, casters in drawn:
                rect = (tile.x, tile.y, tile.size, tile.size)
                fbo.viewport = rect
                frame.gl_call(lambda rect=rect: fbo.clear(depth=1.0, viewport=rect))
                for obj in casters:  # outside the map's frustum: casts nothing into it
                    obj.material.shadow.draw(frame, obj, tile.view)
        finally:
            fbo.viewport = (0, 0, atlas.size, atlas.size)
        if atlas.transmittance is not None:
            self._transmittance(frame, atlas, drawn)
        if atlas.opacity is not None:
            self._opacity(frame, atlas, drawn)

    @staticmethod
    def _transmittance(frame: Frame, atlas: ShadowAtlas,
                       drawn: list[tuple[ShadowTile, list]]) -> None:
        """The transmittance maps of each tile ``drawn`` (with its casters;
        ``deferred.lighting.shadows.transmittance``): the transparent casters' transmittance
        multiplied in and their nearest depth kept."""
        fbo = atlas.transmittance_framebuffer
        frame.gl_call(fbo.use)
        frame.set_state(depth_test=False, cull=None, blend=TRANSMITTANCE_BLEND,
                        depth_offset=CASTER_DEPTH_OFFSET)
        try:
            for tile, casters in drawn:
                rect = (tile.x, tile.y, tile.size, tile.size)
                fbo.viewport = rect
                frame.gl_call(lambda rect=rect: fbo.clear(1.0, 1.0, 1.0, 1.0, viewport=rect))
                for obj in casters:
                    if obj.material.shadow.transmits(obj):
                        obj.material.shadow.draw_transmittance(frame, obj, tile.view)
        finally:
            fbo.viewport = (0, 0, *atlas.transmittance.size)

    @staticmethod
    def _opacity(frame: Frame, atlas: ShadowAtlas,
                 drawn: list[tuple[ShadowTile, list]]) -> None:
        """The deep opacity maps of each tile ``drawn`` (with its casters): the volume's first
        and last depths (min blending of the depth and its negative), grown by a texel
        (``shadows/opacity_front.frag``), then its optical depth added into the layers behind
        the first (Yuksel and Keyser 2008, 3.1-3.2)."""
        scale = atlas.opacity_scale
        tiles = [(tile, tuple(round(v * scale) for v in (tile.x, tile.y, tile.size, tile.size)),
                  [obj for obj in casters if obj.material.shadow.opacity_shadows(obj)])
                 for tile, casters in drawn]
        stages = ((atlas.first_framebuffer, "first", dict(depth_test=False, blend="min")),
                  (atlas.front_framebuffer, "front", {}),
                  (atlas.opacity_framebuffer, "density", dict(depth_test=False, blend="add")))
        front = frame.shaders.program("post/fullscreen.vert", OPACITY_FRONT_FRAGMENT)
        for fbo, stage, state in stages:
            frame.gl_call(fbo.use)
            frame.set_state(cull=None, **state)
            try:
                for tile, rect, volumes in tiles:
                    fbo.viewport = rect
                    if stage == "front" and volumes:
                        x, y, size, _ = rect
                        frame.bind(front, {"u_tile": (x, y, x + size - 1, y + size - 1)},
                                   {"u_opacity_drawn": atlas.opacity_drawn})
                        frame.draw_fullscreen(front)
                        continue
                    if stage == "density":
                        frame.gl_call(lambda f=fbo, r=rect: f.clear(0.0, 0.0, 0.0, 0.0,
                                                                    viewport=r))
                    else:
                        frame.gl_call(lambda f=fbo, r=rect: f.clear(OPACITY_FAR, OPACITY_FAR,
                                                                    0.0, 0.0, viewport=r))
                    if stage != "front":
                        for obj in volumes:
                            obj.material.shadow.draw_opacity(frame, obj, tile.view, stage)
            finally:
                fbo.viewport = (0, 0, *atlas.opacity.size)
