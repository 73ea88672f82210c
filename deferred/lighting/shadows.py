"""Shadow maps: one depth atlas for every shadowed light, its records, and the pass drawing the
casters into it.

A light casts shadows when its type names a ``shadow_projection`` and its params say
``shadows = true`` (:class:`deferred.interfaces.light.ShadowParams`). Each such light, in scene
order up to the scene's ``max_shadowed_lights``, is given a *slot* and square tiles of
``shadow_resolution`` texels in the atlas (a quadtree of power-of-two squares):

- ``cascades`` (directional): ``cascades`` orthographic maps over the camera's depth up to
  ``shadow_distance``, split by the practical split scheme (Zhang et al. 2006, "Parallel-Split
  Shadow Maps", Eq. 3: ``lambda`` between logarithmic and uniform splits). Each cascade bounds
  its slice of the view frustum by a sphere, whose size does not change as the camera turns,
  and its origin is snapped to whole texels, so a moving camera does not make the shadow's
  edges shimmer; lookups blend the last tenth of a cascade into the next.
- ``perspective`` (spot): one map along the cone's axis, wide enough for the outer angle.
- ``cube`` (point): six 90-degree maps (a little wider, so a filter near a face's edge reads
  the face's own texels), chosen by the major axis of the direction from the light.

The light's record carries its slot in ``extra.w`` (the light lists keep a light's index, so
every light path and both pipelines read the slot with the record); the slot's row of the
records texture holds its matrices from view space to the atlas (``lighting/shadows.glsl``
documents the layout). The atlas is one binding source of the frame, bound to every program
that reads it; programs only read it where the scene has a shadowed light (the define
``SHADOWS``), so a scene without shadows pays nothing.

**Deep opacity maps** (Yuksel and Keyser 2008), where an object's material draws a volume
(``Material.opacity_shadows``: fur; in the deferred pipeline ``deferred_opacity`` too): beside
the atlas, two textures over the square of the atlas the lights' maps take (from its corner,
:func:`opacity_extent`), at ``opacity_scale`` (a ``[shadows]`` key) of its resolution:
``opacity_first``, the light-view depths of the nearest and the farthest volume fragment each
texel sees (the volume's own front and back, not the depth atlas's casters; min blending of
(depth, -depth); grown by a texel where a texel's centre missed the volume,
``shadows/opacity_front.frag``), and ``opacity``, four layers (RGBA) of the volume's optical
depth (times its density factor) accumulated from that front up to ``OPACITY_LAYERS`` x the
thickest volume's layer (``Material.opacity_layer``). Each material draws both stages
(:meth:`~deferred.interfaces.material.Material.draw_opacity`) and leaves its translucent part
out of the depth atlas (``ShadowView.opacity_maps``): a receiver compiled with
``OPACITY_RECEIVER`` (the volume's own) multiplies a shadowed light by the transmittance at
its depth (``lighting/shadows.glsl``, ``opacity_transmittance``), any other surface by the
transmittance through the whole volume where it lies beyond the volume's back
(``opacity_beyond``). Programs see ``OPACITY_SHADOWS``, so a scene without such a volume
compiles neither lookup.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import moderngl
import numpy as np
import pyrr

from deferred.core.passes import Order, Phase, RenderPass
from deferred.interfaces.light import Light
from deferred.interfaces.material import ShadowView
from deferred.lighting.buffer import visible_spheres
from deferred.names import Pipeline, ShadowProjection

if TYPE_CHECKING:
    from deferred.core.frame import Frame
    from deferred.gl.uniforms import ProgramUniforms
    from deferred.scene.objects import SceneObject
from deferred.scene.scene import Scene

SHADOW_ATLAS = "shadow_atlas"  # its name on a frame's blackboard
SHADOWS_DEFINE = "SHADOWS"
OPACITY_SHADOWS_DEFINE = "OPACITY_SHADOWS"
# where the four opacity layers end, in units of the thickest volume's layer: finer near the
# volume's front, where light falls fastest (Yuksel and Keyser 2008, section 3: layer sizes)
OPACITY_LAYERS = (0.25, 0.5, 1.0, 2.0)
OPACITY_FAR = 3.0e38  # the first-depth map's clear value: no volume along the texel
# grows each tile's fronts by a texel where a texel's centre missed the volume
OPACITY_FRONT_FRAGMENT = "shadows/opacity_front.frag"
RECORD_TEXELS = 40  # texels a slot's row: 4 + 6 tiles x 6 (lighting/shadows.glsl)
MAX_TILES = 6
CASCADE_BLEND = 0.1  # the fraction of a cascade blended into the next at its far end
# the caster pass's slope-scaled depth offset (glPolygonOffset factor, units): with the
# lookup's normal offset and depth bias (texels), no acne down to grazing light
CASTER_DEPTH_OFFSET = (1.5, 2.0)
PROJECTION_IDS = {ShadowProjection.CASCADES: 1, ShadowProjection.PERSPECTIVE: 2,
                  ShadowProjection.CUBE: 3}
# cube faces: the direction each looks along and its up (the lookup's major-axis order)
CUBE_FACES = (((1, 0, 0), (0, -1, 0)), ((-1, 0, 0), (0, -1, 0)), ((0, 1, 0), (0, 0, 1)),
              ((0, -1, 0), (0, 0, -1)), ((0, 0, 1), (0, -1, 0)), ((0, 0, -1), (0, -1, 0)))


def scene_casts_shadows(lights: list[Light]) -> bool:
    return any(light.casts_shadows for light in lights)


def scene_has_opacity(scene: Scene, pipeline: str) -> bool:
    """Whether a shadowed scene draws deep opacity maps: an object's material asks for them
    (``opacity_shadows``) and reads them in this pipeline (every such material in the forward
    pipeline; in the deferred one only where ``deferred_opacity`` says its deferred passes
    do)."""
    return scene_casts_shadows(scene.lights) and any(
        obj.material.opacity_shadows and (pipeline == Pipeline.FORWARD
                                          or obj.material.deferred_opacity)
        for obj in scene.objects)


def opacity_extent(scene: Scene) -> int:
    """Texels on a side of the square, from the atlas's corner, that the maps of the scene's
    shadowed lights take (as :func:`plan_atlas` places them: largest first, from the corner):
    the part of the atlas the deep opacity maps cover."""
    budget = scene.shadow_budget
    plan, _ = plan_atlas(scene.lights, budget.atlas_size, budget.max_shadowed_lights)
    return max((max(x, y) + size for _, squares in plan.values() for x, y, size in squares),
               default=1)


def opacity_size(scene: Scene, pipeline: str) -> int:
    """Texels on a side of the scene's deep opacity maps (0: none drawn): the atlas's square
    its lights' maps take (:func:`opacity_extent`) at the budget's ``opacity_scale`` (the
    volume's shadow is soft: the opacity maps need fewer texels than the depth maps)."""
    if not scene_has_opacity(scene, pipeline):
        return 0
    return max(round(opacity_extent(scene) * scene.shadow_budget.opacity_scale), 1)


def atlas_memory(budget: Any, opacity_size: int = 0) -> dict[str, int]:
    """What the shadow atlas of a scene's budget holds, for the memory budget: its depths
    (4 bytes a texel) and its records; with an ``opacity_size`` (:func:`opacity_size`), the
    opacity maps (the front and back depths as drawn 8 + grown 8 + four half-float layers 8
    bytes a texel)."""
    size = budget.atlas_size
    held = {f"shadow atlas {size}^2": size * size * 4 +
            RECORD_TEXELS * 16 * budget.max_shadowed_lights}
    if opacity_size:
        held[f"opacity shadow maps {opacity_size}^2"] = opacity_size * opacity_size * 24
    return held


def near_far(projection: np.ndarray) -> tuple[float, float]:
    """The near and far distances of a GL projection matrix (orthographic or perspective)."""
    p22, p23 = float(projection[2, 2]), float(projection[2, 3])
    if abs(float(projection[3, 3]) - 1.0) < 1e-9:  # orthographic
        span = -2.0 / p22
        total = -p23 * span
        return (total - span) / 2.0, (total + span) / 2.0
    return p23 / (p22 - 1.0), p23 / (p22 + 1.0)


def practical_splits(near: float, far: float, count: int, lam: float) -> np.ndarray:
    """The far view depth of each of ``count`` cascades over [near, far]: the practical split
    scheme, ``lam`` x logarithmic + (1 - ``lam``) x uniform (Zhang et al. 2006, Eq. 3)."""
    i = np.arange(1, count + 1) / count
    return lam * near * (far / near) ** i + (1.0 - lam) * (near + (far - near) * i)


def look_at(eye: np.ndarray, direction: np.ndarray, up: np.ndarray) -> np.ndarray:
    eye = np.asarray(eye, np.float64)
    return pyrr.matrix44.create_look_at(eye, eye + np.asarray(direction, np.float64),
                                        np.asarray(up, np.float64)).T


def orthographic(left: float, right: float, bottom: float, top: float, near: float,
                 far: float) -> np.ndarray:
    return pyrr.matrix44.create_orthogonal_projection(left, right, bottom, top, near, far,
                                                      dtype=np.float64).T


def perspective(tan_half: float, near: float, far: float) -> np.ndarray:
    return pyrr.matrix44.create_perspective_projection(
        2.0 * math.degrees(math.atan(tan_half)), 1.0, near, far, dtype=np.float64).T


def filter_margin(params: Any) -> float:
    """Texels a lookup's filter reaches from its centre (PCF: a texel, plus bilinear)."""
    return 2.0 if params.shadow_filter == "pcf" else math.ceil(params.shadow_softness) + 1.0


def light_up(direction: np.ndarray) -> np.ndarray:
    """An up vector for a light looking along ``direction`` (world +Y unless nearly along)."""
    return np.array([0.0, 0.0, 1.0]) if abs(direction[1]) > 0.99 else np.array([0.0, 1.0, 0.0])


def unit(v) -> np.ndarray:
    v = np.asarray(v, np.float64)
    return v / max(float(np.linalg.norm(v)), 1e-12)


def tile_matrix(x: int, y: int, size: int, atlas: int) -> np.ndarray:
    """NDC of a map -> (u, v, depth) of its tile in the atlas."""
    half = size / (2.0 * atlas)
    return np.array([[half, 0.0, 0.0, x / atlas + half], [0.0, half, 0.0, y / atlas + half],
                     [0.0, 0.0, 0.5, 0.5], [0.0, 0.0, 0.0, 1.0]])


@dataclass
class ShadowTile:
    """One map of a light: its square of the atlas and the light's view and projection."""

    light: Light
    slot: int
    x: int
    y: int
    size: int
    view_projection: np.ndarray  # world -> clip (the caster pass)
    view: ShadowView
    # the light's reach (centre, radius) for culling casters; None: every object
    reach: tuple[np.ndarray, float] | None = None


class QuadtreeAllocator:
    """Power-of-two squares in a power-of-two atlas: each request takes the smallest free
    square that holds it, split down to its size (largest requests first)."""

    def __init__(self, size: int):
        self.free: list[tuple[int, int, int]] = [(0, 0, size)]

    def take(self, size: int) -> tuple[int, int] | None:
        fitting = [square for square in self.free if square[2] >= size]
        if not fitting:
            return None
        square = min(fitting, key=lambda sq: (sq[2], sq[1], sq[0]))
        self.free.remove(square)
        x, y, s = square
        while s > size:
            s //= 2
            self.free += [(x + s, y, s), (x, y + s, s), (x + s, y + s, s)]
        return x, y


def tile_counts(light: Light) -> int:
    kind = light.shadow_projection
    if kind == ShadowProjection.CASCADES:
        return int(light.params.cascades)
    return MAX_TILES if kind == ShadowProjection.CUBE else 1


def _place_tiles(lights: list[Light], atlas_size: int
                 ) -> tuple[dict[int, list[tuple[int, int, int]]], list[int]]:
    """The squares of each of ``lights`` whose maps all fit, largest maps first, and the
    lights whose maps did not (``id``), the first to run out of room first."""
    requests = sorted(((light.params.shadow_resolution, order, light)
                       for order, light in enumerate(lights) for _ in range(tile_counts(light))),
                      key=lambda item: (-item[0], item[1]))
    allocator = QuadtreeAllocator(atlas_size)
    tiles: dict[int, list[tuple[int, int, int]]] = {}
    failed: list[int] = []
    for size, _, light in requests:
        if id(light) in failed:
            continue
        place = allocator.take(size) if size <= atlas_size else None
        if place is None:
            failed.append(id(light))
            continue
        tiles.setdefault(id(light), []).append((*place, size))
    return {key: squares for key, squares in tiles.items() if key not in failed}, failed


def plan_atlas(lights: list[Light], atlas_size: int, max_lights: int
               ) -> tuple[dict[int, tuple[int, list[tuple[int, int, int]]]], list[str]]:
    """Slots and tiles for the shadowed ``lights`` (scene order): ``{id(light): (slot,
    [(x, y, size), ...])}``, and why each light left out is (for the warning)."""
    wanted = [light for light in lights if light.casts_shadows]
    left_out = [f"light {lights.index(light)} (max_shadowed_lights = {max_lights})"
                for light in wanted[max_lights:]]
    wanted = wanted[:max_lights]
    # Largest maps first packs best; the first light to run out of room is left out and the
    # rest planned again, so the squares it took are not lost to the lights after it.
    failed: set[int] = set()
    while True:
        tiles, missing = _place_tiles([light for light in wanted if id(light) not in failed],
                                      atlas_size)
        if not missing:
            break
        failed.add(missing[0])
    plan: dict[int, tuple[int, list[tuple[int, int, int]]]] = {}
    for light in wanted:
        if id(light) in failed:
            left_out.append(f"light {lights.index(light)} (its {tile_counts(light)} map(s) of "
                            f"{light.params.shadow_resolution}^2 do not fit the "
                            f"{atlas_size}^2 atlas)")
        else:
            plan[id(light)] = (len(plan) + 1, tiles[id(light)])
    return plan, left_out


def object_box(obj: SceneObject) -> tuple[np.ndarray, np.ndarray]:
    """The object-space box of what the object draws: its mesh's, grown by how far its
    material draws beyond the mesh (fur shells, hair: ``Material.motion_extent``)."""
    low, high = obj.mesh.bounds()
    extent = float(obj.material.motion_extent(obj))
    return low - extent, high + extent


def world_bounds(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """The world box of every object (corners of each object's box through its model
    matrix)."""
    lows, highs = [], []
    for obj in scene.objects:
        low, high = object_box(obj)
        corners = np.array([[x, y, z, 1.0] for x in (low[0], high[0]) for y in (low[1], high[1])
                            for z in (low[2], high[2])])
        world = (np.asarray(obj.model, np.float64) @ corners.T).T[:, :3]
        lows.append(world.min(axis=0))
        highs.append(world.max(axis=0))
    if not lows:
        return np.zeros(3), np.zeros(3)
    return np.min(lows, axis=0), np.max(highs, axis=0)


class ShadowAtlas:
    """The shadow atlas, its records texture and this frame's tiles (a binding source)."""

    def __init__(self, ctx: moderngl.Context, atlas_size: int, max_lights: int,
                 opacity_size: int = 0, opacity_extent: int = 0):
        """``opacity_size``: texels on a side of the deep opacity maps (0: none), covering the
        atlas's square of ``opacity_extent`` texels from its corner."""
        self.ctx = ctx
        self.size = atlas_size
        self.max_lights = max_lights
        self.texture = ctx.depth_texture((atlas_size, atlas_size))
        self.texture.compare_func = "<="
        self.texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.texture.repeat_x = self.texture.repeat_y = False
        self.framebuffer = ctx.framebuffer(depth_attachment=self.texture)
        self.framebuffer.clear(depth=1.0)  # tiles no light holds read as lit, and show so
        self.records = ctx.texture((RECORD_TEXELS, max_lights), 4, dtype="f4")
        self.records.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.tiles: list[ShadowTile] = []
        self.slots: dict[int, int] = {}  # id(light) -> slot (1-based)
        self.splits: dict[int, np.ndarray] = {}  # id(light) -> its cascades' far depths
        self._plan_key: tuple | None = None
        self._plan: dict = {}
        self._uniforms: dict[str, Any] = {}
        self.opacity = None
        self.opacity_layer = 0.0  # world units: the thickest opacity volume's layer
        self.opacity_extent = opacity_extent
        # opacity-map texels per atlas texel (the tiles' rectangles there: theirs times this)
        self.opacity_scale = opacity_size / opacity_extent if opacity_size else 0.0
        if opacity_size:
            side = opacity_size
            # the fronts (R) and minus the backs (G) as drawn, kept by min blending, and grown
            # by a texel into opacity_first (what is read)
            self.opacity_drawn = ctx.texture((side, side), 2, dtype="f4")
            self.opacity_first = ctx.texture((side, side), 2, dtype="f4")
            self.opacity = ctx.texture((side, side), 4, dtype="f2")
            self.opacity.filter = (moderngl.LINEAR, moderngl.LINEAR)
            for texture in (self.opacity_drawn, self.opacity_first, self.opacity):
                texture.repeat_x = texture.repeat_y = False
            for texture in (self.opacity_drawn, self.opacity_first):
                texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self.first_framebuffer = ctx.framebuffer([self.opacity_drawn])
            self.front_framebuffer = ctx.framebuffer([self.opacity_first])
            self.opacity_framebuffer = ctx.framebuffer([self.opacity])
            self.first_framebuffer.clear(OPACITY_FAR, OPACITY_FAR, 0.0, 0.0)
            self.front_framebuffer.clear(OPACITY_FAR, OPACITY_FAR, 0.0, 0.0)
            self.opacity_framebuffer.clear(0.0, 0.0, 0.0, 0.0)

    # -- per frame ---------------------------------------------------------------------------
    def update(self, scene: Scene, view: np.ndarray, aspect: float,
               projection: np.ndarray | None = None) -> dict[int, int]:
        """This frame's tiles and records for the scene's lights seen through ``view`` (the
        camera's world -> view); the slots by ``id(light)``. A spot or point light whose
        sphere lies outside the frustum of ``projection`` lights nothing in view (the light
        buffer drops it too): its maps are not drawn this frame."""
        # what the plan depends on (an animated light's params change every frame)
        key = tuple((id(light), light.casts_shadows,
                     getattr(light.params, "shadow_resolution", None),
                     getattr(light.params, "cascades", None)) for light in scene.lights)
        if key != self._plan_key:
            self._plan, left_out = plan_atlas(scene.lights, self.size, self.max_lights)
            self._plan_key = key
            if left_out:
                warnings.warn(f"{scene.source}: unshadowed, over the shadow budget: "
                              f"{'; '.join(left_out)}", stacklevel=2)
        view = np.asarray(view, np.float64)
        inverse_view = np.linalg.inv(view)
        records = np.zeros((self.max_lights, RECORD_TEXELS, 4), np.float32)
        self.tiles, self.slots, self.splits = [], {}, {}
        bounds = None
        for light in scene.lights:
            planned = self._plan.get(id(light))
            if planned is None:
                continue
            slot, squares = planned
            params = light.params
            kind = light.shadow_projection
            if kind != ShadowProjection.CASCADES and projection is not None:
                centre = view @ np.append(np.asarray(params.position, np.float64), 1.0)
                sphere = np.zeros((1, 4, 4), np.float32)
                sphere[0, 1] = (*centre[:3], params.radius)
                if not visible_spheres(sphere, projection)[0]:
                    continue
            row = records[slot - 1]
            row[0] = (PROJECTION_IDS[kind], len(squares),
                      0.0 if params.shadow_filter == "pcf" else 1.0, params.shadow_softness)
            row[1] = (params.shadow_bias, params.normal_bias, CASCADE_BLEND, 0.0)
            if kind == ShadowProjection.CASCADES:
                if bounds is None:
                    bounds = world_bounds(scene)
                frusta = self._cascades(light, scene, view, inverse_view, aspect, bounds,
                                        squares[0][2])
                splits = np.array([far for far, *_ in frusta])
                row[2, :len(splits)] = splits
                self.splits[id(light)] = splits
            elif kind == ShadowProjection.PERSPECTIVE:
                frusta = [self._spot(light, squares[0][2])]
            else:
                frusta = self._cube(light, squares[0][2])
            # light_projection: ``projection`` is the camera's, which the next light's
            # visibility test above still needs
            for index, ((x, y, size), (_, light_view, light_projection, texel,
                                       perspective_texel, reach)) in enumerate(
                    zip(squares, frusta, strict=True)):
                view_projection = light_projection @ light_view
                to_atlas = tile_matrix(x, y, size, self.size) @ view_projection @ inverse_view
                base = 4 + 6 * index
                row[base:base + 4] = to_atlas.T  # columns
                row[base + 4] = (x / self.size, y / self.size, (x + size) / self.size,
                                 (y + size) / self.size)
                row[base + 5] = (texel, 1.0 if perspective_texel else 0.0,
                                 *near_far(light_projection))
                position = None if kind == ShadowProjection.CASCADES else \
                    np.asarray(params.position, np.float64)
                direction = unit(-light_view[2, :3])
                self.tiles.append(ShadowTile(light, slot, x, y, size, view_projection,
                                             ShadowView(light_view, light_projection, position,
                                                        direction, self.opacity is not None),
                                             reach))
            self.slots[id(light)] = slot
        self.records.write(records.tobytes())
        self._uniforms = {"u_shadow_world_from_view": inverse_view[:3, :3].copy(),
                          "u_shadow_atlas_texel": 1.0 / self.size}
        if self.opacity is not None:
            self.opacity_layer = max((float(obj.material.opacity_layer(obj))
                                      for obj in scene.objects if obj.material.opacity_shadows),
                                     default=0.0)
            self._uniforms["u_opacity_layers"] = tuple(b * self.opacity_layer
                                                       for b in OPACITY_LAYERS)
            self._uniforms["u_opacity_from_atlas"] = self.size / self.opacity_extent
        return self.slots

    def _cascades(self, light: Light, scene: Scene, view: np.ndarray, inverse_view: np.ndarray,
                  aspect: float, bounds: tuple[np.ndarray, np.ndarray], resolution: int
                  ) -> list[tuple]:
        params = light.params
        camera = scene.camera
        near = camera.near
        far = min(camera.far, params.shadow_distance)
        splits = practical_splits(near, far, params.cascades, params.cascade_lambda)
        direction = unit(params.direction)
        light_view = look_at((0.0, 0.0, 0.0), direction, light_up(direction))
        tan_y = math.tan(math.radians(camera.fov) / 2.0)
        k2 = tan_y * tan_y * (1.0 + aspect * aspect)  # squared corner radius per unit depth
        low, high = bounds
        corners = np.array([[x, y, z, 1.0] for x in (low[0], high[0]) for y in (low[1], high[1])
                            for z in (low[2], high[2])])
        scene_z = (light_view @ corners.T)[2]
        eye = inverse_view[:3, 3]
        forward = -inverse_view[:3, 2]
        frusta = []
        start = near
        for end in splits:
            # the slice's bounding sphere: its centre on the view axis, equally far from the
            # near and far corners (at most the far corners' centre); it depends on the
            # slice's depths and the field of view only, not on where the camera looks
            centre_depth = min((end + start) * (1.0 + k2) / 2.0, end)
            radius = math.sqrt((end - centre_depth) ** 2 + end * end * k2)
            centre = (light_view @ np.append(eye + forward * centre_depth, 1.0))[:3]
            texel = 2.0 * radius / resolution
            # snapped to whole texels: the map moves in steps of a texel (stable edges)
            cx, cy = (np.floor(centre[:2] / texel) * texel)
            z_near = -max(centre[2] + radius, float(scene_z.max())) - texel
            z_far = -(centre[2] - radius) + texel
            projection = orthographic(cx - radius, cx + radius, cy - radius, cy + radius,
                                      z_near, z_far)
            frusta.append((end, light_view, projection, texel, False, None))
            start = end
        return frusta

    @staticmethod
    def _near(radius: float) -> float:
        return min(max(radius * 0.005, 0.01), 0.5)

    def _spot(self, light: Light, resolution: int) -> tuple:
        params = light.params
        position = np.asarray(params.position, np.float64)
        direction = unit(params.direction)
        margin = filter_margin(params)
        tan_half = math.tan(math.radians(params.outer_angle)) * resolution / \
            (resolution - 2.0 * margin)
        tan_half = min(tan_half, math.tan(math.radians(89.0)))
        light_view = look_at(position, direction, light_up(direction))
        projection = perspective(tan_half, self._near(params.radius), params.radius)
        return (0.0, light_view, projection, 2.0 * tan_half / resolution, True,
                (position, params.radius))

    def _cube(self, light: Light, resolution: int) -> list[tuple]:
        params = light.params
        position = np.asarray(params.position, np.float64)
        tan_half = resolution / (resolution - 2.0 * filter_margin(params))
        projection = perspective(tan_half, self._near(params.radius), params.radius)
        return [(0.0, look_at(position, direction, up), projection, 2.0 * tan_half / resolution,
                 True, (position, params.radius)) for direction, up in CUBE_FACES]

    # -- binding source ----------------------------------------------------------------------
    def bind(self, uniforms: ProgramUniforms, texture_unit: int) -> int:
        """The atlas and records where a program reads them (lighting/shadows.glsl), and the
        opacity maps where it reads those (the opacity stage reads the first depth only)."""
        if "u_shadow_records" in uniforms.members:
            uniforms.set_shared("shadows", self._uniforms)
            self.texture.use(location=texture_unit)
            uniforms.set_one("u_shadow_atlas", texture_unit)
            self.records.use(location=texture_unit + 1)
            uniforms.set_one("u_shadow_records", texture_unit + 1)
            texture_unit += 2
        if self.opacity is None:
            return texture_unit
        for name, texture in (("u_opacity_first", self.opacity_first),
                              ("u_opacity", self.opacity)):
            if name in uniforms.members:
                texture.use(location=texture_unit)
                uniforms.set_one(name, texture_unit)
                texture_unit += 1
        for name in ("u_opacity_layers", "u_opacity_from_atlas"):
            if name in uniforms.members:
                uniforms.set_one(name, self._uniforms[name])
        return texture_unit

    def read_depth(self) -> np.ndarray:
        """The atlas's depths, (size, size) float32, rows bottom-up (GL's)."""
        data = np.frombuffer(self.texture.read(alignment=1), dtype=np.float32)
        return data.reshape(self.size, self.size)

    def read_opacity(self) -> tuple[np.ndarray, np.ndarray]:
        """The opacity maps: the first light-view depth (side, side) and the four layers'
        optical depths (side, side, 4), float32, rows bottom-up; a tile's texels there are its
        atlas rectangle times ``opacity_scale``."""
        side = self.opacity.size[0]
        first = np.frombuffer(self.opacity_first.read(alignment=1), dtype=np.float32)
        layers = np.frombuffer(self.opacity.read(alignment=1), dtype=np.float16)
        return first.reshape(side, side, 2)[..., 0], \
            layers.reshape(side, side, 4).astype(np.float32)

    def read_opacity_back(self) -> np.ndarray:
        """The light-view depth of the volumes' back (side, side), float32, rows bottom-up
        (-OPACITY_FAR: no volume along the texel)."""
        side = self.opacity.size[0]
        first = np.frombuffer(self.opacity_first.read(alignment=1), dtype=np.float32)
        return -first.reshape(side, side, 2)[..., 1]

    def release(self) -> None:
        parts = [self.framebuffer, self.texture, self.records]
        if self.opacity is not None:
            parts += [self.first_framebuffer, self.front_framebuffer, self.opacity_framebuffer,
                      self.opacity_drawn, self.opacity_first, self.opacity]
        for part in parts:
            part.release()


def object_sphere(obj: SceneObject) -> tuple[np.ndarray, float]:
    low, high = object_box(obj)
    model = np.asarray(obj.model, np.float64)
    centre = (model @ np.append((low + high) / 2.0, 1.0))[:3]
    scale = float(np.max(np.linalg.norm(model[:3, :3], axis=0)))
    return centre, float(np.linalg.norm(high - low)) / 2.0 * scale


class ShadowPass(RenderPass):
    """Every shadowed light's maps: each tile of the atlas cleared and each object's depth
    drawn into it by its material (:meth:`~deferred.interfaces.material.Material.draw_shadow`).
    The atlas is not a frame target; the pass writes none (dumps read the atlas apart)."""

    order = Order.FIRST

    def __init__(self, phase: Phase):
        self.name = "shadows"
        self.phase = phase

    def execute(self, frame: Frame) -> None:
        atlas: ShadowAtlas = frame.blackboard[SHADOW_ATLAS]
        if not atlas.tiles:
            return
        fbo = atlas.framebuffer
        frame.gl_call(fbo.use)
        fbo.depth_mask = True
        frame.set_state(depth_test=True, depth_func="less", cull=None,
                        depth_offset=CASTER_DEPTH_OFFSET)
        objects = frame.scene.objects
        spheres = [object_sphere(obj) for obj in objects]

        def reached(tile: ShadowTile) -> list:
            return [obj for obj, (centre, radius) in zip(objects, spheres, strict=True)
                    if tile.reach is None or
                    np.linalg.norm(centre - tile.reach[0]) <= radius + tile.reach[1]]

        try:
            for tile in atlas.tiles:
                rect = (tile.x, tile.y, tile.size, tile.size)
                fbo.viewport = rect
                frame.gl_call(lambda rect=rect: fbo.clear(depth=1.0, viewport=rect))
                for obj in reached(tile):  # beyond the light's reach: casts nothing it lights
                    obj.material.draw_shadow(frame, obj, tile.view)
        finally:
            fbo.viewport = (0, 0, atlas.size, atlas.size)
        if atlas.opacity is not None:
            self._opacity(frame, atlas, reached)

    @staticmethod
    def _opacity(frame: Frame, atlas: ShadowAtlas, reached) -> None:
        """The deep opacity maps of each tile: the volume's first and last depths (min blending
        of the depth and its negative), grown by a texel (``shadows/opacity_front.frag``), then
        its optical depth added into the layers behind the first (Yuksel and Keyser 2008,
        3.1-3.2)."""
        scale = atlas.opacity_scale
        tiles = [(tile, tuple(round(v * scale) for v in (tile.x, tile.y, tile.size, tile.size)),
                  [obj for obj in reached(tile) if obj.material.opacity_shadows])
                 for tile in atlas.tiles]
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
                            obj.material.draw_opacity(frame, obj, tile.view, stage)
            finally:
                fbo.viewport = (0, 0, *atlas.opacity.size)
