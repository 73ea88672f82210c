"""Fins (Lengyel et al. 2001): strips extruded from silhouette edges along the fur direction and
textured with the fur volume, so fur seen edge-on reads as strands rather than the stacked rims
of shells. ``materials/techniques/fins.geom`` builds them from each edge and its two faces; this
module finds the edges (:func:`edge_adjacency`) and draws them (:class:`FinPass`).
"""

from __future__ import annotations

from typing import Any

import moderngl
import numpy as np

from deferred.api import DEPTH, GpuMesh, MeshData, MeshPrimitives, ObjectPass, Order

from .topology import weld

NO_FINS = ("comb", "shell_count", "single_shell", "wetness")  # debug views showing no fins


def edge_adjacency(mesh: MeshData, tolerance: float = 1e-6) -> np.ndarray:
    """(E, 4) uint32 ``[c1, a, b, c2]`` per interior edge: its endpoints as triangle 1 winds
    them and the vertices opposite the edge in its two triangles (lines_adjacency order).
    Vertices split at UV seams are welded by position, so seams are interior edges too; edges
    with one face, or more than two, get no fin; zero-area faces are left out."""
    positions = np.asarray(mesh.positions, dtype=np.float64)
    welded = weld(positions, tolerance)
    faces = np.asarray(mesh.indices, dtype=np.int64).reshape(-1, 3)
    # zero-area triangles (the poles of a UV sphere) border nothing: they would make their
    # edges look shared by three faces
    corners = positions[faces]
    area = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                          axis=-1)
    welded_faces = welded[faces]
    faces = faces[(area > tolerance * tolerance) &
                  (welded_faces[:, 0] != welded_faces[:, 1]) &
                  (welded_faces[:, 1] != welded_faces[:, 2]) &
                  (welded_faces[:, 2] != welded_faces[:, 0])]
    # every directed edge (a -> b) of every face, with the vertex opposite it
    a = faces.reshape(-1)
    b = faces[:, [1, 2, 0]].reshape(-1)
    opposite = faces[:, [2, 0, 1]].reshape(-1)
    wa, wb = welded[a], welded[b]
    low, high = np.minimum(wa, wb), np.maximum(wa, wb)
    key = low * (welded.max() + 1) + high
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    starts = np.flatnonzero(np.r_[True, sorted_key[1:] != sorted_key[:-1]])
    counts = np.diff(np.r_[starts, len(sorted_key)])
    pairs = starts[counts == 2]
    first, second = order[pairs], order[pairs + 1]
    keep = wa[first] == wb[second]  # consistent winding: the second face runs b -> a
    first, second = first[keep], second[keep]
    return np.stack([opposite[first], a[first], b[first], opposite[second]],
                    axis=1).astype(np.uint32)


def fin_geometry(ctx: moderngl.Context, gpu_mesh: GpuMesh,
                 edges: np.ndarray) -> MeshPrimitives:
    """The edges of a mesh as lines-with-adjacency over the mesh's own vertex buffer."""
    return MeshPrimitives(ctx, gpu_mesh, edges, moderngl.LINES_ADJACENCY)


FIN_GEOMETRY = "materials/techniques/fins.geom"


def draw_fins(frame, mesh: MeshData, program: moderngl.Program) -> None:
    """The fins of ``mesh`` through ``program`` (compiled with :data:`FIN_GEOMETRY`): its edges,
    found once a mesh and kept with the frame's resources (the camera's and the lights')."""
    geometry = frame.resources.cached(
        ("fins", id(mesh)),
        lambda ctx: fin_geometry(ctx, frame.resources.gpu_mesh(mesh), edge_adjacency(mesh)))
    if geometry.count:  # a mesh with no interior edge has no fins
        frame.gl_call(lambda: geometry.render(program))
        frame.count_draw()


class FinPass(ObjectPass):
    """Fins of an object: ``geometry = "materials/techniques/fins.geom"`` over the material's fur
    vertex shader compiled with ``FUR_FINS``; blended like shells, never culled."""

    geometry = FIN_GEOMETRY
    depth = DEPTH
    depth_test = True
    depth_func = "lequal"
    depth_write = False
    cull = None
    blend = "alpha"
    order = Order.VOLUME

    def defines(self, frame) -> dict[str, str]:
        return {**super().defines(frame), "FUR_FINS": "1"}

    def uniforms(self, frame) -> dict[str, Any]:
        params = self.object(frame).params
        return {"u_fin_band": params.fin_band, "u_shell_fade": 1.0, "u_shell_depth": 0.0,
                "u_root_shell": False, "u_shell_weight": 1.0, "u_shell_count": 1.0}

    def draws(self, frame) -> int:
        # debug views of the skin, its wetness or one shell show no fins
        return 0 if self.object(frame).params.debug in NO_FINS else 1

    def draw(self, frame, program: moderngl.Program) -> None:
        draw_fins(frame, self.mesh, program)
