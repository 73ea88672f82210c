"""The passes of the light-list paths: the compute pass that culls the volume lights into the
lists (tiles or clusters), and the full-screen pass that shades every surface pixel from its
list (:mod:`deferred.lighting.paths`)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from deferred.core.passes import FullscreenPass, Order, Phase, RenderPass
from deferred.errors import RenderError
from deferred.gbuffer.layout import LINEAR_DEPTH
from deferred.gl.targets import (
    COMPOSITE,
    COMPOSITE_SPEC,
    DIFFUSE_LIGHT,
    DIFFUSE_LIGHT_SPEC,
    LIGHT_ACCUMULATION,
    LIGHT_ACCUMULATION_SPEC,
)
from deferred.lighting import lists
from deferred.lighting.buffer import LIGHT_BUFFER
from deferred.lighting.lists import (
    CULL_GROUP_SIZE,
    LIGHT_LISTS,
    LIST_IMAGE_UNIT,
    coarse_grid,
    culling_tiles,
    list_grid,
)
from deferred.lighting.volumes import surface_pass

if TYPE_CHECKING:
    from deferred.core.frame import Frame
    from deferred.gl.target_spec import TargetSpec

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
        split = lists.LIST_SPLIT  # read here: tests change it
        if split not in (1, 2):  # the culling writes 16x16 lists or their quadrants
            raise RenderError(f"LIST_SPLIT is {split}; the tiled culling splits a tile "
                              "into 1 or 2 lists a side")
        lights = frame.blackboard[LIGHT_BUFFER]
        light_lists = frame.blackboard[LIGHT_LISTS]
        grid = list_grid(frame.width, frame.height, self.clustered)
        camera = frame.scene.camera
        # every list is a subset of its tile's side-plane set (and slice), every coarse list
        # of its coarse tile's
        slices = (camera.near, camera.far, grid.slices) if self.clustered else None

        def capacity(tile: int, slices: tuple | None = None) -> int:
            return light_lists.capacity_for(lights.volume_spheres, frame.inverse_projection,
                                            frame.width, frame.height, tile, slices)

        coarse_capacity = 1 if self.clustered else capacity(coarse_grid(grid).tile)
        light_lists.prepare(grid, capacity(grid.tile, slices), camera.near, camera.far,
                            coarse_capacity)
        defines = {"CULL_GROUP_SIZE": str(CULL_GROUP_SIZE), "LIST_IMAGE_UNIT": str(LIST_IMAGE_UNIT)}
        if self.from_near:
            defines["CULL_FROM_NEAR"] = "1"
        if self.clustered:
            defines["LIGHT_LISTS_CLUSTERED"] = "1"
            defines["LIST_SLICES"] = str(grid.slices)
            shader = frame.shaders.compute("lighting/cull_clusters.comp", defines)
        else:
            shader = frame.shaders.compute("lighting/cull_tiles.comp",
                                           {**defines, "CULL_CANDIDATES": "1",
                                            **({"LIST_QUADRANTS": "1"} if split == 2
                                               else {})})
        counts = {"u_light_count": lights.count, "u_global_light_count": lights.global_count}
        textures = {"u_lights": lights.texture}
        if self.clustered:
            dispatches = [(shader, {**light_lists.uniforms(), **counts},
                           grid.count // grid.slices)]
        else:
            textures["u_linear_depth"] = frame.target(LINEAR_DEPTH)
            counts["u_pixel_to_view"] = pixel_to_view(frame.projection, frame.width,
                                                      frame.height)
            # coarse tiles against every light, then the tiles against their coarse tile's
            coarse = light_lists.coarse_uniforms()
            first = frame.shaders.compute("lighting/cull_tiles.comp",
                                          {**defines, "CULL_COARSE": "1"})
            dispatches = [(first, {**coarse["first"], **counts}, coarse_grid(grid).count),
                          (shader, {**coarse["second"], **counts}, culling_tiles(grid))]
        for index, (program, uniforms, tiles) in enumerate(dispatches):
            if index:
                frame.barrier()
            frame.bind_compute(program, uniforms, textures)
            light_lists.bind_image(frame.shaders.uniforms(program))
            groups = math.ceil(tiles / CULL_GROUP_SIZE)  # an invocation a tile
            frame.dispatch(program, (groups, 1, 1))
        frame.barrier()
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
                      occlusion: str | None, background: tuple[float, float, float],
                      composite: bool = False, split: bool = False,
                      snapshots: dict[str, TargetSpec] | None = None) -> FullscreenPass:
    """The deferred lighting of every light from the lists: one full-screen pass, which creates
    the light accumulation (the scene's background where the G-buffer holds no surface, alpha
    0; the lights' sum on surfaces, alpha 1), so no pass has to lay the background down first.
    With ``composite`` it creates the composition buffer too, the same values (the copy the
    material phase would start with: one full-screen pass fewer); ``snapshots`` (at most one
    target) are copies of the composition the material phase takes before anything writes
    it, made here as a third output instead of a pass of their own; with ``split`` (the scene
    splits its light) the diffuse light beside it.

    It runs on surfaces only (:func:`deferred.lighting.volumes.surface_pass`; measured in
    benchmarks/README.md)."""
    inputs = {f"u_{target}": target for target in gbuffer}
    defines = {}
    if occlusion:
        inputs["u_ssao"] = occlusion
        defines["HAS_SSAO"] = "1"
    if clustered:
        defines["LIGHT_LISTS_CLUSTERED"] = "1"
    creates = {LIGHT_ACCUMULATION: LIGHT_ACCUMULATION_SPEC}
    if composite:
        creates[COMPOSITE] = COMPOSITE_SPEC
        defines["WRITE_COMPOSITE"] = "1"
    if split:
        creates[DIFFUSE_LIGHT] = DIFFUSE_LIGHT_SPEC
    if snapshots:
        if not composite or len(snapshots) != 1:
            raise ValueError("the list shading makes one snapshot, with the composition")
        creates.update(snapshots)
        defines["WRITE_SNAPSHOT"] = "1"
    return surface_pass(name, "lighting/list_shading.frag", inputs, creates, background, defines)
