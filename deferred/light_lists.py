"""Light paths: how lights reach the pixels (Olsson and Assarsson 2011, "Tiled Shading";
Olsson, Billeter and Assarsson 2012, "Clustered Deferred and Forward Shading").

Deferred:

- ``volumes``: one instanced pass per light type, each light drawn as its bounding sphere (or a
  full-screen triangle), re-reading the G-buffer and blending into the light accumulation for
  every pixel it covers. Needs GL 3.3 only.
- ``tiled``: a compute pass culls the volume lights per 16x16 tile against the tile's frustum,
  depth bounds and the view-space box of its points (``lights/cull_tiles.comp``), in two
  dispatches: coarse tiles of 4x4 tiles against every light, then each tile against its
  coarse tile's lights; one full-screen pass then reads the G-buffer once per pixel and loops
  the full-screen lights and its tile's list (``lights/list_shading.frag``).
- ``clustered``: the same shading, from lists of view-space clusters (32x32 tiles x 16
  exponential depth slices) filled tile by tile (``lights/cull_clusters.comp``).

Forward:

- ``naive``: every fragment loops every light.
- ``tiled`` (Forward+): a depth pre-pass, the tiled culling (depth bounds from the near plane, so
  blended surfaces in front of the opaque ones are covered), and the lit passes loop their
  tile's list (``common/forward_lighting.glsl``).

The lists live in one storage buffer (``lights/light_lists.glsl``): a count per list, then
``capacity`` slots per list, then (tiled) the coarse tiles' lists in the same layout. Capacity
is the frame's volume light count, so no list overflows.
The culling shaders write the buffer; it is then copied into an R32UI texture, which the shading
passes read: llvmpipe reads a texel several times as fast as a storage buffer's word, and the
list loops read one per light (the tiled shading pass 15-23% faster at 256-1024 lights). The
lists are held twice, buffer and texture.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import moderngl
import numpy as np

from .errors import InputError, RenderError
from .gbuffer import LINEAR_DEPTH
from .light import FULLSCREEN_LIGHT_CAPACITY
from .lightbuffer import fullscreen_overflow
from .passes import FullscreenPass, Order, Phase, RenderPass

if TYPE_CHECKING:
    from .context import Features
    from .frame import Frame
    from .uniforms import ProgramUniforms

DEFERRED_PATHS = ("volumes", "tiled", "clustered")
FORWARD_PATHS = ("naive", "tiled")
# A path named for one pipeline, in the other: forward has no volumes or clusters.
FORWARD_EQUIVALENT = {"volumes": "naive", "clustered": "tiled"}
DEFERRED_EQUIVALENT = {"naive": "volumes"}
TILE = 16  # pixels per tile side (tiled, Forward+)
CLUSTER_TILE = 32  # pixels per cluster side
CLUSTER_SLICES = 16  # exponential depth slices between the near and far planes
# Invocations per culling work group, an invocation per tile. llvmpipe gives each CPU thread
# whole groups, so smaller groups share the tiles out over more threads (at 640x360: 920 tiles,
# 29 groups; 240 cluster tiles, 8 groups); 16 cost more than 32 or 64 in the groups' own
# overhead (the tiled culling 4.2-6.1 ms at 1024 lights with 64 or 32, 8.0-8.6 with 16).
CULL_GROUP_SIZE = 32
# The tiled culling runs twice: over coarse tiles of COARSE_RATIO x COARSE_RATIO tiles against
# every light, then over the tiles against their coarse tile's lights only.
COARSE_RATIO = 4
MAX_LIST_BYTES = 512 * 1024 * 1024
LIST_ROW_SHIFT = 14  # words per row of the lists' texture, as a power of two (u_list_row_shift)
LIST_TEXTURE_WIDTH = 1 << LIST_ROW_SHIFT  # 16384: every GL 4.3 context (compute) allows it
LIST_ROW_BYTES = 4 * LIST_TEXTURE_WIDTH


def resolve_light_path(pipeline: str, requested: str | None, features: Features,
                       where: str = "--light-path") -> str:
    """The light path a pipeline runs: ``requested`` (either pipeline's name of it), or the
    fastest this context allows (tiled when compute shaders exist; volumes and naive on GL 3.3,
    where they are the only ones)."""
    if requested is None:
        return "tiled" if features.compute_shaders else \
            ("volumes" if pipeline == "deferred" else "naive")
    names = DEFERRED_PATHS + FORWARD_PATHS
    if requested not in names:
        raise InputError(f"unknown light path '{requested}' (choose from "
                         f"{', '.join(dict.fromkeys(names))})", where)
    path = FORWARD_EQUIVALENT.get(requested, requested) if pipeline == "forward" else \
        DEFERRED_EQUIVALENT.get(requested, requested)
    if path in ("tiled", "clustered") and not features.compute_shaders:
        raise InputError(f"light path '{requested}' needs compute shaders (GL 4.3); this context "
                         "has the GL 3.3 paths only (volumes, naive)", where)
    return path


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


def list_bytes(grid: ListGrid, capacity: int) -> int:
    """Bytes of the lists' storage buffer: a count and ``capacity`` slots per list, in whole
    rows of the lists' texture."""
    return -(-4 * grid.count * (1 + max(capacity, 1)) // LIST_ROW_BYTES) * LIST_ROW_BYTES


def coarse_grid(grid: ListGrid) -> ListGrid:
    """The coarse tiles of the tiled culling's first dispatch (COARSE_RATIO tiles a side)."""
    return ListGrid(math.ceil(grid.columns / COARSE_RATIO), math.ceil(grid.rows / COARSE_RATIO),
                    1, grid.tile * COARSE_RATIO)


def coarse_list_bytes(grid: ListGrid, capacity: int) -> int:
    """Bytes of the coarse lists, kept in the storage buffer after the lists (tiled only)."""
    if grid.slices > 1:
        return 0
    return 4 * coarse_grid(grid).count * (1 + max(capacity, 1))


def list_byte_limit(max_texture_size: int) -> int:
    """The most bytes of lists: MAX_LIST_BYTES, and the rows the lists' texture may have."""
    return min(MAX_LIST_BYTES, max_texture_size * LIST_ROW_BYTES)


def list_overflow(grid: ListGrid, capacity: int, max_texture_size: int
                  ) -> tuple[int, int] | None:
    """(bytes needed, limit) where the lists do not fit: the shading's lists in the texture's
    rows (:func:`list_byte_limit`), and the storage buffer, which also holds the coarse lists,
    in MAX_LIST_BYTES; None where they fit."""
    lists = list_bytes(grid, capacity)
    texture_limit = list_byte_limit(max_texture_size)
    if lists > texture_limit:
        return lists, texture_limit
    total = lists + coarse_list_bytes(grid, capacity)
    return (total, MAX_LIST_BYTES) if total > MAX_LIST_BYTES else None


def _too_many_for_lists(lights: int, grid: ListGrid, size: int, limit: int) -> str:
    return (f"{lights} lights need {size >> 20} MiB of light lists at this size "
            f"({grid.count} lists); the limit is {limit >> 20} MiB: use fewer lights "
            "or the volumes path")


def check_light_limits(light_path: str, size: tuple[int, int], volume_lights: int,
                       lights: int, max_texture_size: int) -> None:
    """Refuse, before any frame, a light count the light path cannot hold: the lists' storage
    (tiled, clustered: a slot per volume light in every list) and the light buffer's texture
    (a row per light) and the full-screen lights' uniform array (any path: forward reads it)."""
    if lights - volume_lights > FULLSCREEN_LIGHT_CAPACITY:
        raise InputError(fullscreen_overflow(lights - volume_lights), "light")
    if light_path in ("tiled", "clustered"):
        grid = list_grid(*size, light_path == "clustered")
        overflow = list_overflow(grid, volume_lights, max_texture_size)
        if overflow is not None:
            raise InputError(_too_many_for_lists(volume_lights, grid, *overflow), "light")
    if lights > max_texture_size:
        raise InputError(f"{lights} lights; lights are kept in a texture of at most "
                         f"{max_texture_size} rows (GL_MAX_TEXTURE_SIZE)", "light")


def list_grid(width: int, height: int, clustered: bool) -> ListGrid:
    tile = CLUSTER_TILE if clustered else TILE
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
        self.coarse_base = 0
        self.rows = 0
        self.clustered = False
        self.depth_scale = (1.0, 1.0)

    def prepare(self, grid: ListGrid, capacity: int, near: float, far: float) -> None:
        self.grid = grid
        self.capacity = max(capacity, 1)
        self.clustered = grid.slices > 1
        self.depth_scale = (near, grid.slices / math.log(far / near))
        self._uniforms = {"u_list_count": grid.count, "u_list_capacity": self.capacity,
                          "u_list_base": 0,
                          "u_list_row_shift": LIST_ROW_SHIFT,
                          "u_list_grid": (grid.columns, grid.rows, grid.slices),
                          "u_list_tile": grid.tile, "u_list_depth": self.depth_scale}
        lists = list_bytes(grid, self.capacity)  # what the shading reads, in the texture
        size = lists + coarse_list_bytes(grid, self.capacity)
        self.coarse_base = lists // 4  # the word where the coarse lists begin
        overflow = list_overflow(grid, self.capacity, self.max_texture_size)
        if overflow is not None:  # checked before the first frame (check_light_limits)
            raise RenderError(_too_many_for_lists(capacity, grid, *overflow))
        rows = self.rows = lists // LIST_ROW_BYTES  # of the texture the shading reads
        if self.buffer is None or self.texture is None or self.buffer.size < size or \
                self.texture.height < rows:
            self.release()
            buffer = self.ctx.buffer(reserve=size)
            try:
                texture = self.ctx.texture((LIST_TEXTURE_WIDTH, rows), 1, dtype="u4")
            except BaseException:
                buffer.release()
                raise
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self.buffer, self.texture = buffer, texture
        self.buffer.bind_to_storage_buffer(1)

    def publish(self) -> None:
        """Copy the lists the culling wrote into the texture the shading reads (after a memory
        barrier)."""
        assert self.buffer is not None and self.texture is not None and self.grid is not None
        self.texture.write(self.buffer, viewport=(0, 0, LIST_TEXTURE_WIDTH, self.rows))

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
                 "u_list_grid": (coarse.columns, coarse.rows, 1), "u_list_tile": coarse.tile}
        second = {**self._uniforms, "u_candidate_base": self.coarse_base,
                  "u_candidate_count": coarse.count, "u_candidate_columns": coarse.columns,
                  "u_candidate_ratio": COARSE_RATIO}
        return {"first": first, "second": second}

    def bind(self, uniforms: ProgramUniforms, texture_unit: int) -> None:
        """Set the list uniforms, bind the buffer (culling) and the texture (shading, at
        ``texture_unit``) for a program using the lists."""
        if self.buffer is None or "u_list_count" not in uniforms.members:
            return
        self.buffer.bind_to_storage_buffer(1)
        if "u_light_list_texture" in uniforms.members:
            self.texture.use(location=texture_unit)
            uniforms.set_one("u_light_list_texture", texture_unit)
        uniforms.set_shared("light_lists", self.uniforms())

    def counts(self) -> np.ndarray:
        """The list lengths of the last frame (host copy; tests and statistics)."""
        assert self.buffer is not None and self.grid is not None
        data = np.frombuffer(self.buffer.read(size=4 * self.grid.count), dtype=np.uint32)
        return np.minimum(data, self.capacity)

    def release(self) -> None:
        if self.buffer is not None:
            self.buffer.release()
            self.buffer = None
        if self.texture is not None:
            self.texture.release()
            self.texture = None


class LightCullPass(RenderPass):
    """Fill the light lists with a compute shader (tiles or clusters)."""

    def __init__(self, name: str, phase: Phase, clustered: bool, from_near: bool = False):
        self.name = name
        self.phase = phase
        self.clustered = clustered
        self.from_near = from_near
        self.order = Order.FIRST
        # tiles read the depth bounds; clusters need no depth
        self.reads = () if clustered else (LINEAR_DEPTH,)
        self.samples = self.reads

    def execute(self, frame: Frame) -> None:
        lights = frame.light_buffer
        grid = list_grid(frame.width, frame.height, self.clustered)
        camera = frame.scene.camera
        frame.light_lists.prepare(grid, lights.local_count, camera.near, camera.far)
        defines = {"CULL_GROUP_SIZE": str(CULL_GROUP_SIZE)}
        if self.from_near:
            defines["CULL_FROM_NEAR"] = "1"
        if self.clustered:
            defines["LIGHT_LISTS_CLUSTERED"] = "1"
            defines["LIST_SLICES"] = str(grid.slices)
            shader = frame.shaders.compute("lights/cull_clusters.comp", defines)
        else:
            shader = frame.shaders.compute("lights/cull_tiles.comp",
                                           {**defines, "CULL_CANDIDATES": "1"})
        counts = {"u_light_count": lights.count, "u_global_light_count": lights.global_count}
        textures = {"u_lights": lights.texture}
        if self.clustered:
            dispatches = [(shader, {**frame.light_lists.uniforms(), **counts}, grid)]
        else:
            textures["u_linear_depth"] = frame.target(LINEAR_DEPTH)
            counts["u_pixel_to_view"] = pixel_to_view(frame.projection, frame.width,
                                                      frame.height)
            # coarse tiles against every light, then the tiles against their coarse tile's
            coarse = frame.light_lists.coarse_uniforms()
            first = frame.shaders.compute("lights/cull_tiles.comp",
                                          {**defines, "CULL_COARSE": "1"})
            dispatches = [(first, {**coarse["first"], **counts}, coarse_grid(grid)),
                          (shader, {**coarse["second"], **counts}, grid)]
        for index, (program, uniforms, tiles) in enumerate(dispatches):
            if index:
                frame.ctx.memory_barrier()
            frame.bind_compute(program, uniforms, textures)
            groups = math.ceil(tiles.columns * tiles.rows / CULL_GROUP_SIZE)  # a tile each
            frame.gl_call(lambda program=program, groups=groups: program.run(groups, 1, 1))
        frame.ctx.memory_barrier()
        frame.gl_call(frame.light_lists.publish)  # a copy of the lists: GL work
        frame.count_draw()


def pixel_to_view(projection: np.ndarray, width: int, height: int) -> tuple[float, ...]:
    """(scale.xy, offset.xy) with view-space xy / linear depth = pixel * scale + offset for a
    perspective ``projection`` (math order, column vectors): the culling's view positions of
    pixels, one multiply-add where the inverse projection takes a matrix product."""
    p = projection
    scale = (2.0 / (width * p[0, 0]), 2.0 / (height * p[1, 1]))
    offset = ((p[0, 2] - 1.0) / p[0, 0], (p[1, 2] - 1.0) / p[1, 1])
    return (*(float(v) for v in scale), *(float(v) for v in offset))


def list_shading_pass(name: str, clustered: bool, gbuffer: tuple[str, ...],
                      occlusion: str | None, composite: bool = False) -> FullscreenPass:
    """The deferred lighting of every light from the lists: one full-screen pass, which creates
    the light accumulation (the scene's background where the G-buffer holds no surface, alpha
    0; the lights' sum on surfaces, alpha 1), so no pass has to lay the background down first.
    With ``composite`` it creates the composition buffer too, the same values (a frame with
    no material pass: the copy between them would be all the material phase did)."""
    from .targets import COMPOSITE, COMPOSITE_SPEC, LIGHT_ACCUMULATION, LIGHT_ACCUMULATION_SPEC

    inputs = {f"u_{target}": target for target in gbuffer}
    defines = {}
    if occlusion:
        inputs["u_ssao"] = occlusion
        defines["HAS_SSAO"] = "1"
    if clustered:
        defines["LIGHT_LISTS_CLUSTERED"] = "1"
    outputs = (LIGHT_ACCUMULATION,)
    creates = {LIGHT_ACCUMULATION: LIGHT_ACCUMULATION_SPEC}
    if composite:
        outputs += (COMPOSITE,)
        creates[COMPOSITE] = COMPOSITE_SPEC
        defines["WRITE_COMPOSITE"] = "1"
    return FullscreenPass(name, Phase.LIGHTING, "lights/list_shading.frag", inputs, outputs,
                          defines=defines, creates=creates,
                          uniforms=lambda frame: {"u_background": frame.scene.background},
                          order=Order.FIRST)
