"""The light lists of the tiled and clustered paths (:mod:`deferred.lighting.paths`): their grid
of tiles (and depth slices), their GPU storage and its limits, and how many lights a list can
hold.

The culling shaders write the lists for the shading in an RGBA32UI texture of a texel a slot,
the light's sphere (its radius a half float) and index (:meth:`LightLists.entries`); the list
loops read one texel a listed light, plus the colour of each light reaching the pixel from
the light buffer (``lighting/light_lists.glsl``). A storage buffer holds each list's count,
then (tiled) the coarse tiles' lists of light indices, a count and ``coarse_capacity`` slots
each. A list's capacity is the most volume lights the side planes of any of its tiles can hold
(the 8x8 list tiles, the coarse tiles; clustered: any tile and depth slice), counted on the
CPU (:func:`list_capacity`), so no list overflows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import moderngl
import numpy as np

from deferred.errors import InputError, RenderError
from deferred.lighting.buffer import fullscreen_overflow
from deferred.lighting.dispatch import FULLSCREEN_LIGHT_CAPACITY
from deferred.names import LIST_PATHS, LightPath, LightVolume

if TYPE_CHECKING:
    from deferred.gl.uniforms import ProgramUniforms

LIGHT_LISTS = "light_lists"  # its name on a frame's blackboard
# A path named for one pipeline, in the other: forward has no volumes or clusters.
TILE = 16  # pixels per culling tile side (tiled, Forward+): an invocation of the culling each
# The tiled lists are those of LIST_SPLIT x LIST_SPLIT sub-tiles of a culling tile (8x8 pixels):
# the culling tests a light against a sub-tile only where it touches the tile.
LIST_SPLIT = 2
CLUSTER_TILE = 32  # pixels per cluster side
CLUSTER_SLICES = 16  # exponential depth slices between the near and far planes
# Invocations per culling work group, an invocation per tile. llvmpipe gives each CPU thread
# whole groups, so smaller groups share the tiles out over more threads (at 640x360: 920 tiles,
# 29 groups; 240 cluster tiles, 8 groups); 16 cost more than 32 or 64 in the groups' own
# overhead (benchmarks/README.md).
CULL_GROUP_SIZE = 32
# The tiled culling runs twice: over coarse tiles of COARSE_RATIO x COARSE_RATIO tiles against
# every light, then over the tiles against their coarse tile's lights only.
COARSE_RATIO = 4
MAX_LIST_BYTES = 512 * 1024 * 1024
LIST_ROW_SHIFT = 14  # texels per row of the shading's lists texture, a power of two
LIST_TEXTURE_WIDTH = 1 << LIST_ROW_SHIFT  # 16384: every GL 4.3 context (compute) allows it
SLOT_TEXELS = 1  # RGBA32UI texels a slot of the shading's lists: the sphere and the index
LIST_ROW_BYTES = 16 * LIST_TEXTURE_WIDTH
LIST_IMAGE_UNIT = 2  # the culling writes the shading's lists texture through this image unit
# A listed light's texel holds its index (in the light buffer, full-screen lights first) in 16
# bits, beside its radius as a half float.
MAX_LISTED_LIGHTS = 1 << 16


@dataclass(frozen=True)
class ListGrid:
    """The lists of one frame: tiles across and down, depth slices, pixels per tile."""

    columns: int
    rows: int
    slices: int
    tile: int

    @property
    def count(self) -> int:
        return self.columns * self.rows * self.slices


def list_bytes(grid: ListGrid) -> int:
    """Bytes of the lists' counts in the storage buffer (their lights are in the shading's
    texture only)."""
    return 4 * grid.count


def texture_rows(grid: ListGrid, capacity: int) -> int:
    """Rows of the shading's lists texture: SLOT_TEXELS texels for a list's count and for each
    of its ``capacity`` slots."""
    return -(-SLOT_TEXELS * grid.count * (1 + max(capacity, 1)) // LIST_TEXTURE_WIDTH)


def coarse_grid(grid: ListGrid) -> ListGrid:
    """The coarse tiles of the tiled culling's first dispatch (COARSE_RATIO tiles a side)."""
    ratio = COARSE_RATIO * LIST_SPLIT  # list tiles a coarse tile side
    return ListGrid(math.ceil(grid.columns / ratio), math.ceil(grid.rows / ratio), 1,
                    grid.tile * ratio)


def culling_tiles(grid: ListGrid) -> int:
    """The tiled culling's second dispatch: an invocation per TILE x TILE tile, for its
    LIST_SPLIT x LIST_SPLIT lists."""
    return math.ceil(grid.columns / LIST_SPLIT) * math.ceil(grid.rows / LIST_SPLIT)


def coarse_list_bytes(grid: ListGrid, capacity: int) -> int:
    """Bytes of the coarse lists, kept in the storage buffer after the lists (tiled only)."""
    if grid.slices > 1:
        return 0
    return 4 * coarse_grid(grid).count * (1 + max(capacity, 1))


def list_overflow(grid: ListGrid, coarse_capacity: int) -> tuple[int, int] | None:
    """(bytes needed, limit) where the storage buffer (the lists' counts and, tiled, the coarse
    lists) exceeds MAX_LIST_BYTES at ``coarse_capacity`` slots a coarse list; None where it
    fits."""
    total = list_bytes(grid) + coarse_list_bytes(grid, coarse_capacity)
    return (total, MAX_LIST_BYTES) if total > MAX_LIST_BYTES else None


def texture_overflow(grid: ListGrid, capacity: int, max_texture_size: int
                     ) -> tuple[int, int] | None:
    """(bytes needed, limit) where the shading's lists texture does not fit at ``capacity``
    slots a list: in MAX_LIST_BYTES, and in the rows the driver allows; None where it fits."""
    rows = texture_rows(grid, capacity)
    limit = min(MAX_LIST_BYTES, max_texture_size * LIST_ROW_BYTES)
    return (rows * LIST_ROW_BYTES, limit) if rows * LIST_ROW_BYTES > limit else None


def _lists_too_big(what: str, grid: ListGrid, size: int, limit: int) -> str:
    """The refusal of lists past a limit (before the first frame, or in one), ``what`` saying
    which lights asked for them."""
    return (f"{what}: the light lists need {size >> 20} MiB at this size ({grid.count} "
            f"lists); the limit is {limit >> 20} MiB: use fewer lights or the volumes path")


def check_light_limits(light_path: str, size: tuple[int, int], volume_lights: int,
                       lights: int, max_texture_size: int, where: str = "light") -> None:
    """Refuse, before any frame, a light count the light path cannot hold: the lists' storage
    buffer (tiled: the coarse lists, a slot per volume light in each; the shading's texture of
    the lists is sized to the frame's lights, :meth:`LightLists.prepare`), the light buffer's
    texture (a row per light) and the full-screen lights' uniform array (any path: forward
    reads it)."""
    if lights - volume_lights > FULLSCREEN_LIGHT_CAPACITY:
        raise InputError(fullscreen_overflow(lights - volume_lights), where)
    if light_path in LIST_PATHS:
        grid = list_grid(*size, light_path == LightPath.CLUSTERED)
        overflow = list_overflow(grid, volume_lights)  # every light in one list: the most
        if overflow is not None:
            raise InputError(_lists_too_big(f"{volume_lights} lights", grid, *overflow),
                             where)
        if lights > MAX_LISTED_LIGHTS:  # a listed light's index in the light buffer
            raise InputError(f"{lights} lights; the light lists index at most "
                             f"{MAX_LISTED_LIGHTS}", where)
    if lights > max_texture_size:
        raise InputError(f"{lights} lights; lights are kept in a texture of at most "
                         f"{max_texture_size} rows (GL_MAX_TEXTURE_SIZE)", where)


MAX_LISTED_RADIUS = 65504.0  # the largest half float: a listed light's radius is one


def check_light_radii(light_path: str, lights: list, where: str = "light") -> None:
    """Refuse, before any frame, a volume light whose radius the light lists cannot hold,
    naming it (``where[index].radius``); the record's ``position.w`` is a volume light's
    radius (``deferred.interfaces.light``), whatever its parameters call it."""
    if light_path not in LIST_PATHS:
        return
    for index, light in enumerate(lights):
        if light.volume == LightVolume.FULLSCREEN:
            continue
        radius = float(np.asarray(type(light).records([light], np.eye(4)), np.float64)[0, 1, 3])
        if radius > MAX_LISTED_RADIUS:
            raise InputError(f"a radius of {radius:g} is more than the light lists hold "
                             f"({MAX_LISTED_RADIUS:g}, a half float): use the volumes path",
                             f"{where}[{index}].radius")


def check_list_radii(spheres: np.ndarray) -> None:
    """Refuse a volume light whose radius the lists cannot hold (a half float, rounded up)."""
    if len(spheres) and float(spheres[:, 3].max()) > MAX_LISTED_RADIUS:
        raise InputError(f"a light's radius of {float(spheres[:, 3].max()):g} is more than the "
                         f"light lists hold ({MAX_LISTED_RADIUS:g}, a half float): use the "
                         "volumes path", "light")


def list_grid(width: int, height: int, clustered: bool) -> ListGrid:
    tile = CLUSTER_TILE if clustered else TILE // LIST_SPLIT
    return ListGrid(math.ceil(width / tile), math.ceil(height / tile),
                    CLUSTER_SLICES if clustered else 1, tile)


class LightLists:
    """The storage buffer of a frame's light lists and the texture the shading passes read them
    from, grown as needed."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.buffer: moderngl.Buffer | None = None
        self.texture: moderngl.Texture | None = None
        self.max_texture_size = int(ctx.info["GL_MAX_TEXTURE_SIZE"])
        self.grid: ListGrid | None = None
        self.capacity = 1
        self.coarse_capacity = 1
        self.coarse_base = 0
        self.clustered = False
        self.depth_scale = (1.0, 1.0)
        # the last capacity counted for each tile size: (spheres, key, capacity)
        self._capacities: dict[tuple, tuple[np.ndarray, tuple, int]] = {}

    def prepare(self, grid: ListGrid, capacity: int, near: float, far: float,
                coarse_capacity: int = 1) -> None:
        """Lay out this frame's lists: ``capacity`` slots each, and (tiled) the coarse lists'
        ``coarse_capacity`` (:func:`list_capacity`). The storage buffer's worst case was
        checked before the first frame; both are checked here, at this frame's capacities."""
        capacity = max(capacity, 1)
        coarse_capacity = max(coarse_capacity, 1)
        coarse_overflow = list_overflow(grid, coarse_capacity)
        overflow = coarse_overflow or texture_overflow(grid, capacity, self.max_texture_size)
        if overflow is not None:
            most = coarse_capacity if coarse_overflow else capacity
            raise RenderError(_lists_too_big(f"a tile's frustum holds {most} lights", grid,
                                             *overflow))
        self.grid = grid
        self.capacity = capacity
        self.coarse_capacity = coarse_capacity
        self.clustered = grid.slices > 1
        self.depth_scale = (near, grid.slices / math.log(far / near))
        self._uniforms = {"u_list_count": grid.count, "u_list_capacity": self.capacity,
                          "u_list_base": 0,
                          "u_list_row_shift": LIST_ROW_SHIFT,
                          "u_list_grid": (grid.columns, grid.rows, grid.slices),
                          "u_list_tile": grid.tile, "u_list_depth": self.depth_scale}
        lists = list_bytes(grid)
        size = lists + coarse_list_bytes(grid, coarse_capacity)
        self.coarse_base = lists // 4  # the word where the coarse lists begin
        rows = texture_rows(grid, self.capacity)
        if self.buffer is None or self.buffer.size < size:
            self._release_buffer()
            self.buffer = self.ctx.buffer(reserve=size)
        if self.texture is None or self.texture.height < rows:
            self._release_texture()
            self.texture = self.ctx.texture((LIST_TEXTURE_WIDTH, rows), 4, dtype="u4")
            self.texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.buffer.bind_to_storage_buffer(1)

    def capacity_for(self, spheres: np.ndarray, inverse_projection: np.ndarray, width: int,
                     height: int, tile: int, slices: tuple[float, float, int] | None = None
                     ) -> int:
        """:func:`list_capacity`, computed again only when its inputs change (the light buffer
        makes a new ``spheres`` array when it packs the lights again)."""
        key = (np.asarray(inverse_projection).tobytes(), width, height)
        counted = self._capacities.get((tile, slices))
        if counted is None or counted[0] is not spheres or counted[1] != key:
            check_list_radii(spheres)
            counted = (spheres, key, list_capacity(spheres, inverse_projection, width, height,
                                                   tile, slices))
            self._capacities[(tile, slices)] = counted
        return counted[2]

    def uniforms(self) -> dict[str, Any]:
        """The lists' uniforms this frame (one dict per :meth:`prepare`: programs skip it while
        they hold its values)."""
        assert self.grid is not None
        return self._uniforms

    def coarse_uniforms(self) -> dict[str, Any]:
        """The tiled culling's two dispatches: the first's lists (the coarse tiles') and the
        second's candidates (the same lists, read)."""
        assert self.grid is not None
        coarse = coarse_grid(self.grid)
        first = {**self._uniforms, "u_list_base": self.coarse_base, "u_list_count": coarse.count,
                 "u_list_capacity": self.coarse_capacity,
                 "u_list_grid": (coarse.columns, coarse.rows, 1), "u_list_tile": coarse.tile}
        second = {**self._uniforms, "u_candidate_base": self.coarse_base,
                  "u_candidate_count": coarse.count, "u_candidate_columns": coarse.columns,
                  "u_candidate_ratio": COARSE_RATIO,
                  "u_candidate_capacity": self.coarse_capacity}
        return {"first": first, "second": second}

    def bind(self, uniforms: ProgramUniforms, texture_unit: int) -> int:
        """Set the list uniforms, bind the buffer and the texture (at ``texture_unit``) for a
        shading program using the lists (a binding source of the frame; the culling binds the
        texture as its image: :meth:`bind_image`); the next free unit."""
        if self.buffer is None or "u_list_count" not in uniforms.members:
            return texture_unit
        self.buffer.bind_to_storage_buffer(1)
        uniforms.set_shared("light_lists", self.uniforms())
        if "u_light_list_texture" in uniforms.members:
            self.texture.use(location=texture_unit)
            uniforms.set_one("u_light_list_texture", texture_unit)
            return texture_unit + 1
        return texture_unit

    def bind_image(self, uniforms: ProgramUniforms) -> None:
        """Bind the shading's lists texture as the image a culling shader writes (at the unit
        its declaration names: ``LIST_IMAGE_UNIT``)."""
        if "u_light_list_image" in uniforms.members:
            self.texture.bind_to_image(LIST_IMAGE_UNIT, read=False, write=True)

    def counts(self) -> np.ndarray:
        """The list lengths of the last frame (host copy; tests and statistics)."""
        assert self.buffer is not None and self.grid is not None
        data = np.frombuffer(self.buffer.read(size=4 * self.grid.count), dtype=np.uint32)
        return np.minimum(data, self.capacity)

    def pixel_counts(self, width: int, height: int, depth: np.ndarray | None = None
                     ) -> np.ndarray:
        """The length of the list each pixel's shading loops over, (height, width) float32, GL's
        bottom row first (the numpy twin of ``light_list_of``). Clustered lists need the linear
        ``depth`` (same layout); pixels with no surface there (depth 0) read no list. Tiled: the
        tile's list, or 0 where ``depth`` shows no surface."""
        assert self.grid is not None
        grid = self.grid
        counts = self.counts().astype(np.float32)
        ys, xs = np.mgrid[0:height, 0:width]
        column = np.minimum(xs // grid.tile, grid.columns - 1)
        row = np.minimum(ys // grid.tile, grid.rows - 1)
        lists = row * grid.columns + column
        if self.clustered:
            if depth is None:
                raise ValueError("clustered lists need the linear depth")
            near, scale = self.depth_scale
            slice_ = depth_slice(depth, near, scale, grid.slices).astype(np.int64)
            lists = (slice_ * grid.rows + row) * grid.columns + column
        shown = counts[lists]
        return np.where(depth > 0.0, shown, 0.0).astype(np.float32) if depth is not None \
            else shown

    def entries(self) -> list[np.ndarray]:
        """Each list's light indices (into the light buffer), in list order, as the shading's
        copy holds them (tests and statistics)."""
        assert self.grid is not None
        indices = self.shading_slots()[1].astype(np.int64)
        counts = self.counts()
        first = self.grid.count  # the counts' slots, then capacity slots a list
        return [indices[first + i * self.capacity:][:counts[i]] for i in range(self.grid.count)]

    def shading_slots(self) -> tuple[np.ndarray, np.ndarray]:
        """The shading's copy of the lists as read back, decoded: each slot's sphere (slots, 4)
        float32 (a count slot holds its count's bits in x) and light index (slots,) uint32
        (tests)."""
        assert self.texture is not None and self.grid is not None
        slots = self.grid.count * (1 + self.capacity)
        texels = np.frombuffer(self.texture.read(), dtype=np.uint32).reshape(-1, 4)[:slots]
        spheres = np.empty((slots, 4), np.float32)
        spheres[:, :3] = texels[:, :3].view(np.float32)
        spheres[:, 3] = (texels[:, 3] & 0xFFFF).astype(np.uint16).view(np.float16)
        return spheres, texels[:, 3] >> 16

    def _release_buffer(self) -> None:
        if self.buffer is not None:
            self.buffer.release()
            self.buffer = None

    def _release_texture(self) -> None:
        if self.texture is not None:
            self.texture.release()
            self.texture = None

    def release(self) -> None:
        self._release_buffer()
        self._release_texture()


def depth_slice(depth: np.ndarray, near: float, scale: float, slices: int) -> np.ndarray:
    """The clustered lists' depth slice of each linear ``depth`` (float, whole numbers): the
    numpy twin of ``light_list_slice`` in lighting/light_lists.glsl, ``scale`` being slices /
    log(far / near)."""
    return np.clip(np.floor(np.log(np.maximum(depth, near) / near) * scale), 0, slices - 1)


def list_capacity(spheres: np.ndarray, inverse_projection: np.ndarray, width: int, height: int,
                  tile: int, slices: tuple[float, float, int] | None = None) -> int:
    """The most of ``spheres`` (view-space centre xyz, radius w; the frame's volume lights) that
    touch the four side planes of any tile of ``tile`` pixels: the lists' capacity. Every list
    holds only lights whose sphere touches its tile's side planes (the culling shaders test
    them: ``lighting/tile_frustum.glsl``, and each 8x8 quadrant's edge planes in
    ``lighting/cull_tiles.comp``), so counted over the lists' own tiles no list overflows; the
    coarse lists are counted over the coarse tiles. With ``slices`` (near, far,
    count: the clustered lists), the most in any tile and depth slice: a light goes to the
    slices its sphere's depth range covers (``lighting/cull_clusters.comp``).

    Planes through the eye along a column (row) edge of pixels are shared by the tiles above
    and below, so each sphere's columns and rows come from its signed distances to the edges'
    planes, all lights at once; the radius (and the depth range) is padded for the GPU's
    float32."""
    if len(spheres) == 0:
        return 1
    inverse = np.asarray(inverse_projection, np.float64)

    def rays(pixels: np.ndarray, axis: int, across: float) -> np.ndarray:
        """View rays through pixel coordinate ``pixels`` on ``axis``, at NDC ``across`` on the
        other axis (as ``view_ray`` in tile_frustum.glsl)."""
        ndc = np.zeros((len(pixels), 4))
        ndc[:, axis] = pixels / (width, height)[axis] * 2.0 - 1.0
        ndc[:, 1 - axis] = across
        ndc[:, 2:] = 1.0
        ray = ndc @ inverse.T
        return ray[:, :3] / ray[:, 3:]

    centres = np.asarray(spheres[:, :3], np.float64)
    radii = np.asarray(spheres[:, 3], np.float64)
    padded = radii * (1.0 + 1e-3) + 1e-4 * np.linalg.norm(centres, axis=1)
    touched = []
    for axis, extent in ((0, width), (1, height)):
        edges = np.minimum(np.arange(0, extent + tile, tile), extent).astype(np.float64)
        edges = np.unique(edges)
        normals = np.cross(rays(edges, axis, -1.0), rays(edges, axis, 1.0))
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        inward = rays(edges + 0.5, axis, 0.0)  # towards growing pixels
        normals *= np.sign(np.sum(normals * inward, axis=1))[:, None]
        distance = centres @ normals.T  # (lights, edges), positive past the edge
        touched.append((distance[:, :-1] >= -padded[:, None]) &
                       (distance[:, 1:] <= padded[:, None]))
    columns, rows = touched
    columns = columns.astype(np.float32)
    rows = rows.astype(np.float32)
    if slices is not None:
        near, far, count = slices
        depth = -centres[:, 2]
        pad = 1e-4 * np.abs(depth) + 1e-6
        low = np.maximum(depth - padded - pad, near)
        high = depth + padded + pad
        inside = (high >= near) & (depth - padded - pad <= far)
        scale = count / math.log(far / near)
        first = depth_slice(low, near, scale, count)
        last = depth_slice(high, near, scale, count)
        covered = (np.arange(count)[None, :] >= first[:, None]) & \
            (np.arange(count)[None, :] <= last[:, None]) & inside[:, None]
        # (columns, rows) a slice: float32 products (BLAS; exact, counts far below 2^24)
        most = max((columns.T @ (rows * covered[:, k:k + 1])).max() for k in range(count))
        return max(int(most), 1)
    per_tile = columns.T @ rows  # (columns, rows)
    return max(int(per_tile.max()), 1)
