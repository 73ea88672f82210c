"""Edges: outlines from G-buffer discontinuities (the cartoon material's outlines, Costigan's
Sobel + dilation), detected over the clean G-buffer in the screen phase and composited over the
tone-mapped frame in post (``effects/edges/edges.frag``)."""

from __future__ import annotations

from pydantic import Field

from deferred.api import (
    FINAL,
    LINEAR_DEPTH,
    NORMAL_EXPONENT_ID,
    Albedo,
    Effect,
    EffectParams,
    FullscreenPass,
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
STRAND_ID = "strand_id"  # G-buffer datum: a strand's id where materials declare it
EDGE_ROW_OFFSETS = "edge_row_offsets"
EDGE_ROW_OFFSETS_SPEC = TargetSpec(1, "f2", "least squared offset to an edge along the row")


class EdgesParams(EffectParams):
    width: int = Field(1, ge=1, le=16, description="line width in pixels (dilation)")
    color: Albedo = Field((0.0, 0.0, 0.0), description="linear RGB, each in [0, 1]")
    opacity: float = Field(1.0, ge=0.0, le=1.0, description="line opacity")
    depth_threshold: float = Field(0.05, gt=0.0, le=10.0,
                                   description="depth break: relative inverse-depth jump")
    normal_threshold: float = Field(0.35, gt=0.0, le=2.0,
                                    description="crease: normal change across a pixel")
    ids: bool = Field(True, description="lines where the surface id changes")


@effects.register
class Edges(Effect):
    name = "edges"
    Params = EdgesParams
    pipelines = (Pipeline.DEFERRED,)  # reads the G-buffer

    def passes(self, scene: Scene, pipeline: str) -> list[RenderPass]:
        inputs = {"u_linear_depth": LINEAR_DEPTH, "u_normal_exponent_id": NORMAL_EXPONENT_ID}
        defines = {}
        if STRAND_ID in scene.gbuffer_layout().data:
            # strands of one object (cartoon_hair) are told apart by the datum strand_id, so
            # overlapping strands of one colour are outlined too (Costigan 4.3.7)
            inputs["u_strand_id"] = STRAND_ID
            defines["STRAND_IDS"] = "1"
        return [
            FullscreenPass("screen.edges", Phase.SCREEN, "effects/edges/edges.frag", inputs,
                           (EDGES_RAW,), creates={EDGES_RAW: EDGES_SPEC}, defines=defines,
                           uniforms=lambda frame: {
                               "u_depth_threshold": self.params.depth_threshold,
                               "u_normal_threshold": self.params.normal_threshold,
                               "u_ids": self.params.ids}),
            # the disc of the line's width in two passes, a row then a column: the cost grows
            # with the width, not its square
            FullscreenPass("screen.edges_dilate_rows", Phase.SCREEN,
                           "effects/edges/edges_dilate_rows.frag", {"u_edges_raw": EDGES_RAW},
                           (EDGE_ROW_OFFSETS,), creates={EDGE_ROW_OFFSETS: EDGE_ROW_OFFSETS_SPEC},
                           uniforms=lambda frame: {"u_width": self.params.width}),
            FullscreenPass("screen.edges_dilate_columns", Phase.SCREEN,
                           "effects/edges/edges_dilate_columns.frag",
                           {"u_row_offsets": EDGE_ROW_OFFSETS}, (EDGES,),
                           creates={EDGES: EDGES_SPEC},
                           uniforms=lambda frame: {"u_width": self.params.width}),
            FullscreenPass("post.edges", Phase.POST, "effects/edges/edges_composite.frag",
                           {"u_edges": EDGES}, (FINAL,), blend="alpha", order=Order.TRANSPARENT,
                           uniforms=lambda frame: {"u_color": self.params.color,
                                                   "u_opacity": self.params.opacity}),
        ]
