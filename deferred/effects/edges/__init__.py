"""Edges: outlines from G-buffer discontinuities (the cartoon material's outlines, Costigan's
Sobel + dilation), detected over the clean G-buffer in the screen phase and composited over the
tone-mapped frame in post (``effects/edges/edges.frag``).

What is outlined (Costigan 4.3.7: the silhouette and the boundaries of flat colours, never the
lighting's bands): silhouettes and surfaces against other surfaces (ids, depth breaks), and
creases, where the normal turns by more than ``crease_angle`` in one pixel step with no
comparable turn beside it, so a smooth surface's curvature, however tight (a thin tube's rim),
never fires. Where the scene's materials write the datum ``strand_id`` (cartoon_hair: the
strand and its clump), clumps over clumps are outlined, not every strand.

The line is ``width`` pixels wide, or, with ``world_width``, that many view-space units wide at
its surface's depth (so it thins with distance), at most ``width`` pixels and at least 1."""

from __future__ import annotations

import math

from pydantic import Field

from deferred.api import (
    FINAL,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    Albedo,
    Effect,
    FullscreenPass,
    GBufferEffectParams,
    Order,
    Phase,
    Pipeline,
    RenderPass,
    Scene,
    TargetSpec,
    effects,
)

EDGES_RAW = "edges_raw"
EDGES = "edges"
EDGES_SPEC = TargetSpec(1, "f1", "edge mask (1 = line)")
EDGES_RAW_SPEC = TargetSpec(1, "f2", "edge pixels: the line's half width there in pixels (0 none)")
STRAND_ID = "strand_id"  # G-buffer datum: a strand's id where materials declare it
EDGE_ROW_OFFSETS = "edge_row_offsets"
EDGE_ROW_OFFSETS_SPEC = TargetSpec(1, "f2", "least squared offset to an edge along the row")


class EdgesParams(GBufferEffectParams):
    width: int = Field(1, ge=1, le=16, description="line width in pixels (dilation); with "
                                                   "world_width, the widest a line gets")
    world_width: float | None = Field(None, gt=0.0, le=1000.0,
                                      description="line width in view-space units at the "
                                                  "line's depth (thins with distance), within "
                                                  "[1, width] pixels; none: width pixels")
    color: Albedo = Field((0.0, 0.0, 0.0), description="linear RGB, each in [0, 1]")
    opacity: float = Field(1.0, ge=0.0, le=1.0, description="line opacity")
    depth_threshold: float = Field(0.05, gt=0.0, le=10.0,
                                   description="depth break: relative inverse-depth jump")
    crease_angle: float = Field(30.0, gt=0.0, le=180.0,
                                description="crease: degrees the normal turns in one pixel "
                                            "step (a smooth surface's curvature never fires)")
    ids: bool = Field(True, description="lines where the surface id changes")


@effects.register
class Edges(Effect):
    name = "edges"
    Params = EdgesParams
    pipelines = (Pipeline.DEFERRED,)  # and the forward pipeline with forward = true
    reads_gbuffer = True
    uniform_overrides = {"forward": None}  # where it runs, not a uniform

    def passes(self, scene: Scene, pipeline: str) -> list[RenderPass]:
        inputs = {"u_linear_depth": LINEAR_DEPTH, "u_normal_exponent_id": NORMAL_EXPONENT_ID}
        defines = {}
        radii = {"EDGE_RADII": "1"} if self.params.world_width is not None else {}
        if STRAND_ID in scene.gbuffer_layout().data:
            # clumps of one object (cartoon_hair) are told apart by the datum strand_id, so
            # overlapping clumps of one colour are outlined too (Costigan 4.3.7)
            inputs["u_strand_id"] = STRAND_ID
            defines["STRAND_IDS"] = "1"
        return [
            FullscreenPass("screen.edges", Phase.SCREEN, "effects/edges/edges.frag", inputs,
                           (EDGES_RAW,), creates={EDGES_RAW: EDGES_RAW_SPEC},
                           defines={**defines, **radii}, uniforms=self._edge_uniforms),
            # the disc of the line's width in two passes, a row then a column: the cost grows
            # with the width, not its square
            FullscreenPass("screen.edges_dilate_rows", Phase.SCREEN,
                           "effects/edges/edges_dilate_rows.frag", {"u_edges_raw": EDGES_RAW},
                           (EDGE_ROW_OFFSETS,), creates={EDGE_ROW_OFFSETS: EDGE_ROW_OFFSETS_SPEC},
                           defines=radii, uniforms=lambda frame: {"u_width": self.params.width}),
            FullscreenPass("screen.edges_dilate_columns", Phase.SCREEN,
                           "effects/edges/edges_dilate_columns.frag",
                           {"u_row_offsets": EDGE_ROW_OFFSETS}, (EDGES,),
                           creates={EDGES: EDGES_SPEC}, defines=radii,
                           uniforms=lambda frame: {"u_width": self.params.width}),
            FullscreenPass("post.edges", Phase.POST, "effects/edges/edges_composite.frag",
                           {"u_edges": EDGES}, (FINAL,), blend="alpha", order=Order.TRANSPARENT,
                           uniforms=lambda frame: {"u_color": self.params.color,
                                                   "u_opacity": self.params.opacity}),
        ]

    def _edge_uniforms(self, frame) -> dict:
        p = self.params
        uniforms = {"u_depth_threshold": p.depth_threshold,
                    "u_crease_cosine": math.cos(math.radians(p.crease_angle)),
                    "u_ids": p.ids}
        if p.world_width is not None:
            uniforms.update(u_world_width=p.world_width, u_max_radius=0.5 * p.width)
        return uniforms
