"""The shadow atlas: one depth texture holding every shadowed light's maps, the records (a
uniform block) of each slot's matrices (``lighting/shadows.glsl`` documents its layout) and,
where the scene draws them, the deep opacity maps; this frame's tiles. A binding source of the
frame."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import moderngl
import numpy as np

from deferred.errors import InputError
from deferred.interfaces.light import Light
from deferred.interfaces.shadow_casting import ShadowView
from deferred.lighting.buffer import visible_spheres
from deferred.lighting.shadows.bounds import world_bounds
from deferred.lighting.shadows.coverage import (
    fit_sizes,
    map_size,
    screen_coverage,
    shadowed_spheres,
)
from deferred.lighting.shadows.frusta import (
    cascade_slices,
    cube_frusta,
    near_far,
    spot_frustum,
    unit,
)
from deferred.lighting.shadows.opacity import OPACITY_FAR, OPACITY_LAYERS
from deferred.lighting.shadows.plan import left_out_warning, plan_atlas, tile_counts
from deferred.lighting.shadows.stagger import StaggeredCascades
from deferred.lighting.shadows.transmittance import TRANSMITTANCE_BYTES
from deferred.names import CascadeUpdates, ShadowAllocation, ShadowProjection

if TYPE_CHECKING:
    from deferred.gl.uniforms import ProgramUniforms
from deferred.scene.scene import Scene

SHADOW_ATLAS = "shadow_atlas"  # its name on a frame's blackboard
SHADOWS_DEFINE = "SHADOWS"
PCSS_DEFINE = "SHADOW_PCSS"  # a light of the scene filters its shadows by its size
FILTER_IDS = {"pcf": 0.0, "soft": 1.0, "pcss": 2.0}  # lighting/shadows.glsl's header.z
RECORD_TEXELS = 40  # vec4s a slot's row: 4 + 6 tiles x 6 (lighting/shadows.glsl)
# The records are a uniform block, not a texture: a light's lookup reads eight of its vec4s at
# every pixel it lights, and llvmpipe reads uniform memory several times faster than texels
# (benchmarks/README.md, "Shadow lookups"). Its size is fixed when the shaders are compiled.
RECORDS_BLOCK = "ShadowRecords"
RECORDS_BINDING = 1  # its uniform buffer binding point (the framework's only uniform block)


def records_defines(max_lights: int) -> dict[str, str]:
    """The defines sizing lighting/shadows.glsl's records block for ``max_lights`` slots."""
    return {"SHADOW_RECORD_ROWS": str(max_lights), "SHADOW_RECORD_TEXELS": str(RECORD_TEXELS)}


def check_records_fit(ctx: moderngl.Context, max_lights: int, where: str) -> None:
    """One line where the GL's uniform blocks cannot hold ``max_lights`` slots' records."""
    limit = int(ctx.info.get("GL_MAX_UNIFORM_BLOCK_SIZE", 0) or 0)
    need = RECORD_TEXELS * 16 * max_lights
    if limit and need > limit:
        raise InputError(f"max_shadowed_lights = {max_lights} needs {need} bytes of shadow "
                         f"records; this GL's uniform blocks hold {limit} (at most "
                         f"{limit // (RECORD_TEXELS * 16)} lights)", where)
CASCADE_BLEND = 0.1  # the fraction of a cascade blended into the next at its far end
PROJECTION_IDS = {ShadowProjection.CASCADES: 1, ShadowProjection.PERSPECTIVE: 2,
                  ShadowProjection.CUBE: 3}


def atlas_memory(budget: Any, opacity_size: int = 0,
                 transmittance_size: int = 0) -> dict[str, int]:
    """What the shadow atlas of a scene's budget holds, for the memory budget: its depths
    (4 bytes a texel) and its records; with an ``opacity_size``
    (:func:`~deferred.lighting.shadows.opacity.opacity_size`), the opacity maps (the front and
    back depths as drawn 8 + grown 8 + four half-float layers 8 bytes a texel); with a
    ``transmittance_size``, the transmittance maps (8 bytes a texel)."""
    size = budget.atlas_size
    held = {f"shadow atlas {size}^2": size * size * 4 +
            RECORD_TEXELS * 16 * budget.max_shadowed_lights}
    if opacity_size:
        held[f"opacity shadow maps {opacity_size}^2"] = opacity_size * opacity_size * 24
    if transmittance_size:
        held[f"transmittance shadow maps {transmittance_size}^2"] = \
            transmittance_size * transmittance_size * TRANSMITTANCE_BYTES
    return held


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

    def casts(self, centre: np.ndarray, radius: float) -> bool:
        """Whether a caster bounded by the sphere (``centre``, ``radius``: world) may draw into
        this map: within the light's reach and not wholly outside the side or far planes of
        the map's frustum (the near plane is not tested: a cascade's reaches back to the
        scene's casters, a spot's is a sliver at the light)."""
        if self.reach is not None and \
                np.linalg.norm(centre - self.reach[0]) > radius + self.reach[1]:
            return False
        point = np.append(centre, 1.0)
        for plane in frustum_planes(self.view_projection):
            if plane @ point < -radius:
                return False
        return True


def frustum_planes(view_projection: np.ndarray) -> np.ndarray:
    """The left, right, bottom, top and far planes of a clip transform (Gribb and Hartmann),
    each (a, b, c, d) with (a, b, c) of unit length, positive inside."""
    m = np.asarray(view_projection, np.float64)
    planes = np.array([m[3] + m[0], m[3] - m[0], m[3] + m[1], m[3] - m[1], m[3] - m[2]])
    return planes / np.linalg.norm(planes[:, :3], axis=1, keepdims=True)


class ShadowAtlas:
    """The shadow atlas, its records and this frame's tiles (a binding source)."""

    def __init__(self, ctx: moderngl.Context, atlas_size: int, max_lights: int,
                 opacity_size: int = 0, opacity_extent: int = 0, transmittance_size: int = 0,
                 allocation: str = ShadowAllocation.COVERAGE):
        """``opacity_size``: texels on a side of the deep opacity maps (0: none), covering the
        atlas's square of ``opacity_extent`` texels from its corner; ``transmittance_size``:
        texels on a side of the transmittance maps (0: none), texel for texel with the atlas
        from its corner (``deferred.lighting.shadows.transmittance``); ``allocation``: how
        large the maps are (``deferred.lighting.shadows.coverage``)."""
        self.ctx = ctx
        self.size = atlas_size
        self.max_lights = max_lights
        self.allocation = ShadowAllocation(allocation)
        # by coverage the maps are packed where the opacity and transmittance maps reach
        self.region = opacity_extent if (opacity_size or transmittance_size) else atlas_size
        self.sizes: dict[int, int] = {}  # id(light) -> this frame's map side (by coverage)
        self._left_out: list[tuple[int, str]] = []  # the lights last warned of
        self.texture = ctx.depth_texture((atlas_size, atlas_size))
        self.texture.compare_func = "<="
        self.texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.texture.repeat_x = self.texture.repeat_y = False
        # the same depths read as numbers (PCSS's blocker search): a sampler without comparison
        self.depth_sampler = ctx.sampler(texture=self.texture, compare_func="",
                                         filter=(moderngl.NEAREST, moderngl.NEAREST),
                                         repeat_x=False, repeat_y=False)
        self.framebuffer = ctx.framebuffer(depth_attachment=self.texture)
        self.framebuffer.clear(depth=1.0)  # tiles no light holds read as lit, and show so
        self.records = ctx.buffer(reserve=RECORD_TEXELS * 16 * max_lights)
        self.tiles: list[ShadowTile] = []
        self.slots: dict[int, int] = {}  # id(light) -> slot (1-based)
        self.splits: dict[int, np.ndarray] = {}  # id(light) -> its cascades' far depths
        self._plan_key: tuple | None = None
        # (x, y, size) of a tile -> what it was last drawn with (deferred.lighting.shadows
        # .caster_pass): its depths stay in the atlas from frame to frame
        self.drawn: dict[tuple[int, int, int], tuple] = {}
        self.cascades = StaggeredCascades()  # which cascades are fitted again, those kept
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
        self.transmittance = None
        if transmittance_size:
            side = transmittance_size
            self.transmittance = ctx.texture((side, side), 4, dtype="f1")
            self.transparent_depth = ctx.texture((side, side), 1, dtype="f4")
            for texture in (self.transmittance, self.transparent_depth):
                texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
                texture.repeat_x = texture.repeat_y = False
            self.transmittance_framebuffer = ctx.framebuffer(
                [self.transmittance, self.transparent_depth])
            self.transmittance_framebuffer.clear(1.0, 1.0, 1.0, 1.0)


    # -- per frame ---------------------------------------------------------------------------
    def update(self, scene: Scene, view: np.ndarray, aspect: float,
               projection: np.ndarray | None = None, hold_sizes: bool = False,
               cascade_updates: str = CascadeUpdates.EVERY_FRAME) -> dict[int, int]:
        """This frame's tiles and records for the scene's lights seen through ``view`` (the
        camera's world -> view); the slots by ``id(light)``. A spot or point light whose
        sphere lies outside the frustum of ``projection`` lights nothing in view (the light
        buffer drops it too): its maps are not drawn this frame. By coverage, the maps'
        sizes follow this frame's view; ``hold_sizes`` (the live viewer) keeps the last
        frame's sizes within a margin (:func:`~deferred.lighting.shadows.coverage.map_size`),
        so a frame then depends on the frames before it. ``cascade_updates``: which cascades
        are fitted again while the camera moves (:mod:`~deferred.lighting.shadows.stagger`)."""
        view = np.asarray(view, np.float64)
        self.cascades.start_frame(view)
        seen = self._seen_lights(scene, view, projection)
        # what receives shadows, where cascades or coverage need it
        bounds = world_bounds(scene) if self.allocation == ShadowAllocation.COVERAGE or any(
            light.casts_shadows and light.shadow_projection == ShadowProjection.CASCADES
            for light in scene.lights) else None
        self._plan_lights(scene, self._coverage_sizes(scene, view, projection, seen, bounds,
                                                      hold_sizes))
        inverse_view = np.linalg.inv(view)
        records = np.zeros((self.max_lights, RECORD_TEXELS, 4), np.float32)
        self.tiles, self.slots, self.splits = [], {}, {}
        for light in scene.lights:
            planned = self._plan.get(id(light))
            if planned is None or not seen.get(id(light), True):
                continue
            slot, squares = planned
            params = light.params
            kind = light.shadow_projection
            row = records[slot - 1]
            pcss = params.shadow_filter == "pcss"
            # pcss: the normal offset's reach is pcf's (the plane's slope covers the rest)
            row[0] = (PROJECTION_IDS[kind], len(squares), FILTER_IDS[params.shadow_filter],
                      1.5 if pcss else params.shadow_softness)
            row[1] = (params.shadow_bias, params.normal_bias, CASCADE_BLEND,
                      light.emitter_radius() if pcss else 0.0)
            if kind == ShadowProjection.CASCADES:
                slices = cascade_slices(light, scene, inverse_view, aspect, bounds)
                frusta = self.cascades.frusta(light, slices, squares, cascade_updates)
                splits = np.array([cascade.far for cascade in slices])
                row[2, :len(splits)] = splits
                self.splits[id(light)] = splits
            elif kind == ShadowProjection.PERSPECTIVE:
                frusta = [spot_frustum(light, squares[0][2])]
            else:
                frusta = cube_frusta(light, squares[0][2])
            self._add_tiles(light, slot, squares, frusta, row, inverse_view)
            self.slots[id(light)] = slot
        self.records.write(records.tobytes())
        self._set_uniforms(scene, inverse_view)
        return self.slots

    @staticmethod
    def _seen_lights(scene: Scene, view: np.ndarray,
                     projection: np.ndarray | None) -> dict[int, bool]:
        """Whether each shadowed spot or point light's sphere touches the view frustum."""
        lights = [light for light in scene.lights if light.casts_shadows and
                  light.shadow_projection != ShadowProjection.CASCADES]
        if projection is None or not lights:
            return {}
        spheres = np.zeros((len(lights), 4, 4), np.float32)
        for row, light in zip(spheres, lights, strict=True):
            centre = view @ np.append(np.asarray(light.params.position, np.float64), 1.0)
            row[1] = (*centre[:3], light.params.radius)
        return {id(light): bool(seen) for light, seen
                in zip(lights, visible_spheres(spheres, projection), strict=True)}

    def _coverage_sizes(self, scene: Scene, view: np.ndarray, projection: np.ndarray | None,
                        seen: dict[int, bool], bounds: tuple[np.ndarray, np.ndarray] | None,
                        hold: bool) -> dict[int, int]:
        """By coverage, each spot and point light's map side this frame (0: out of view),
        fitted to the region the maps may take; fixed: none (each its resolution)."""
        if self.allocation != ShadowAllocation.COVERAGE or projection is None:
            return {}
        shadowed = [light for light in scene.lights if light.casts_shadows]
        local = [light for light in shadowed
                 if light.shadow_projection != ShadowProjection.CASCADES and
                 seen.get(id(light), True)]
        coverage = dict(zip(map(id, local), screen_coverage(
            *shadowed_spheres(local, bounds), view, projection, bounds).tolist(), strict=True))
        requests = []
        for light in shadowed:
            resolution = int(light.params.shadow_resolution)
            if light.shadow_projection == ShadowProjection.CASCADES:  # they cover the view
                requests.append((id(light), tile_counts(light), resolution, 1.0))
                continue
            covered = coverage.get(id(light), 0.0)
            previous = self.sizes.get(id(light)) if hold else None
            requests.append((id(light), tile_counts(light),
                             map_size(resolution, covered, previous), covered))
        # the lights given slots only: those past max_shadowed_lights take no room
        sides = fit_sizes([request for request in requests[:self.max_lights] if request[2]],
                          self.region)
        self.sizes = {key: sides.get(key, 0) for key, *_ in requests}
        return self.sizes

    def _plan_lights(self, scene: Scene, sizes: dict[int, int]) -> None:
        """The slots and squares of the scene's lights, planned again when what the plan
        depends on changed (an animated light's params change every frame; by coverage, a
        map's size). Tiles drawn before keep their depths where the new plan puts the same
        light's same map on the same square (the caster pass forgets a square drawn over)."""
        key = tuple((id(light), light.casts_shadows,
                     getattr(light.params, "shadow_resolution", None),
                     getattr(light.params, "cascades", None), sizes.get(id(light)))
                    for light in scene.lights)
        if key != self._plan_key:
            self._plan, left_out = plan_atlas(scene.lights, self.region, self.max_lights,
                                              sizes) \
                if sizes else plan_atlas(scene.lights, self.size, self.max_lights)
            self._plan_key = key
            if left_out and left_out != self._left_out:  # stacklevel: update's caller
                warnings.warn(left_out_warning(scene.source, left_out), stacklevel=3)
            self._left_out = left_out

    def mark_drawn(self, rect: tuple[int, int, int], key: tuple) -> None:
        """Note that the square ``rect`` (x, y, size) now holds what ``key`` draws: every
        other square it overlaps no longer holds what it was drawn with."""
        x, y, size = rect
        for other in [r for r in self.drawn if r != rect and r[0] < x + size and
                      x < r[0] + r[2] and r[1] < y + size and y < r[1] + r[2]]:
            del self.drawn[other]
        self.drawn[rect] = key

    def _add_tiles(self, light: Light, slot: int, squares: list[tuple[int, int, int]],
                   frusta: list[tuple], row: np.ndarray, inverse_view: np.ndarray) -> None:
        """A light's tiles, and their matrices and rectangles in its records ``row``."""
        position = None if light.shadow_projection == ShadowProjection.CASCADES else \
            np.asarray(light.params.position, np.float64)
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
            direction = unit(-light_view[2, :3])
            self.tiles.append(ShadowTile(light, slot, x, y, size, view_projection,
                                         ShadowView(light_view, light_projection, position,
                                                    direction, self.opacity is not None),
                                         reach))

    def _set_uniforms(self, scene: Scene, inverse_view: np.ndarray) -> None:
        self._uniforms = {"u_shadow_world_from_view": inverse_view[:3, :3].copy(),
                          "u_shadow_atlas_texel": 1.0 / self.size}
        if self.opacity is not None:
            self.opacity_layer = max((float(obj.material.shadow.opacity_layer(obj)) for obj
                                      in scene.objects if obj.material.shadow.opacity_shadows(obj)),
                                     default=0.0)
            self._uniforms["u_opacity_layers"] = tuple(b * self.opacity_layer
                                                       for b in OPACITY_LAYERS)
            self._uniforms["u_opacity_from_atlas"] = self.size / self.opacity_extent
        if self.transmittance is not None:
            self._uniforms["u_transmittance_from_atlas"] = \
                self.size / self.transmittance.size[0]

    # -- binding source ----------------------------------------------------------------------
    def bind(self, uniforms: ProgramUniforms, texture_unit: int) -> int:
        """The atlas and records where a program reads them (lighting/shadows.glsl), and the
        opacity maps where it reads those (the opacity stage reads the first depth only)."""
        if RECORDS_BLOCK in uniforms.members:
            uniforms.set_shared("shadows", self._uniforms)
            self.records.bind_to_uniform_block(RECORDS_BINDING)
            uniforms.set_one(RECORDS_BLOCK, RECORDS_BINDING)
            self.texture.use(location=texture_unit)
            uniforms.set_one("u_shadow_atlas", texture_unit)
            texture_unit += 1
            if "u_shadow_depths" in uniforms.members:
                self.depth_sampler.use(location=texture_unit)
                uniforms.set_one("u_shadow_depths", texture_unit)
                texture_unit += 1
        if self.transmittance is not None and "u_shadow_transmittance" in uniforms.members:
            for name, texture in (("u_shadow_transmittance", self.transmittance),
                                  ("u_shadow_transparent_depth", self.transparent_depth)):
                texture.use(location=texture_unit)
                uniforms.set_one(name, texture_unit)
                texture_unit += 1
            uniforms.set_one("u_transmittance_from_atlas",
                             self._uniforms["u_transmittance_from_atlas"])
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

    def read_transmittance(self) -> tuple[np.ndarray, np.ndarray]:
        """The transmittance maps: the transmittance (side, side, 3) and the nearest
        transparent caster's depth (side, side), float32, rows bottom-up."""
        side = self.transmittance.size[0]
        colour = np.frombuffer(self.transmittance.read(alignment=1), dtype=np.uint8)
        depth = np.frombuffer(self.transparent_depth.read(alignment=1), dtype=np.float32)
        return colour.reshape(side, side, 4)[..., :3] / 255.0, depth.reshape(side, side)

    def release(self) -> None:
        parts = [self.framebuffer, self.depth_sampler, self.texture, self.records]
        if self.transmittance is not None:
            parts = [self.transmittance_framebuffer, self.transmittance,
                     self.transparent_depth, *parts]
        if self.opacity is not None:
            parts += [self.first_framebuffer, self.front_framebuffer, self.opacity_framebuffer,
                      self.opacity_drawn, self.opacity_first, self.opacity]
        for part in parts:
            part.release()

