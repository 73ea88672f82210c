"""Costigan's diagrams of the method's steps, drawn from the code that makes the final image,
into docs/figures/cartoon_hair/:

- Fig. 4.4: the structural particles and springs on a styled strand (``structured_chain`` and
  the springs ``hair_dynamics`` solves), and the same strand in the simulation half-way
  through ``anchored_head.toml``'s sweep;
- Figs. 4.5-4.6: a tube's vertices in the order ``build_tubes`` makes them, and its triangles
  in ``tube_indices``' order;
- Figs. 4.14-4.16: a tube's front- and back-facing triangles and the silhouette edges the
  compute pass (``SilhouetteEdges``) finds between them; those edges on screen before
  stroking; the quads it extrudes from them; and the strokes' texture coordinates (along the
  strand, across the stroke);
- Fig. 4.18: a curl that overlaps itself, stroked in deferred (the thesis' ID-buffer rule: a
  stroke shows over its own strand whatever hides it, so the hidden half's silhouette shows
  through) and in forward (the depth test), then faded toward the root (Fig. 4.19).

Run from the repository root: python examples/cartoon_hair/step_figures.py (matplotlib:
pip install -e '.[plot]'; the silhouette figures need compute shaders, GL 4.3)
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402

from deferred.debug import preview  # noqa: E402
from deferred.gl.context import create_context  # noqa: E402
from deferred.gl.shaderlib import ShaderLibrary  # noqa: E402
from deferred.io.images import write_image  # noqa: E402
from deferred.materials.cartoon_hair.state import hair_physics  # noqa: E402
from deferred.materials.techniques.hair_dynamics import (  # noqa: E402
    HairSimulation,
    structured_chain,
)
from deferred.materials.techniques.hair_silhouettes import (  # noqa: E402
    SilhouetteEdges,
    edges_on_gpu,
)
from deferred.materials.techniques.hair_tubes import build_tubes  # noqa: E402
from deferred.render.renderer import Renderer  # noqa: E402
from deferred.scene.loader import load_scene, scene_from_dict  # noqa: E402

ROOT = Path(__file__).parents[2]
FIGURES = ROOT / "docs" / "figures" / "cartoon_hair"
# Fig. 4.4's colours: structural particles orange, bend springs blue, edge springs green,
# torsion springs red
SPRINGS = {"edge": "#2ca02c", "bend": "#1f77b4", "torsion": "#d62728"}
STRUCTURAL = "#ff7f0e"


def chain_springs(length: int) -> dict[str, list[tuple[int, int]]]:
    """The springs of a chain ``p_-1 q_-1 p_0 q_0 ... p_(P-1)`` of ``length`` particles, as
    ``hair_dynamics`` documents them: edge springs between particles 1 apart and along the
    strand (``p_i p_(i+1)``), bend springs ``q_i q_(i+1)`` and ``p_i p_(i+2)``, torsion springs
    between particles 3 apart."""
    edge = [(k, k + 1) for k in range(length - 1)] + \
        [(k, k + 2) for k in range(0, length - 2, 2)]
    bend = [(k, k + 2) for k in range(1, length - 2, 2)] + \
        [(k, k + 4) for k in range(0, length - 4, 2)]
    torsion = [(k, k + 3) for k in range(length - 3)]
    return {"edge": edge, "bend": bend, "torsion": torsion}


def plane_of(points: np.ndarray) -> np.ndarray:
    """``(3, 2)``: the two directions the points spread most along (their principal axes)."""
    centred = points - points.mean(axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    return axes[:2].T


def draw_chain(axes, chain: np.ndarray, strand: np.ndarray, plane: np.ndarray, title: str
               ) -> None:
    flat, line = chain @ plane, strand @ plane
    for kind, pairs in chain_springs(len(chain)).items():
        segments = [(flat[a], flat[b]) for a, b in pairs]
        axes.add_collection(LineCollection(segments, colors=SPRINGS[kind], linewidths=1.2,
                                           label=f"{kind} springs"))
    axes.plot(line[:, 0], line[:, 1], ":", color="k", linewidth=1.5, label="the strand")
    axes.scatter(flat[0::2, 0], flat[0::2, 1], s=22, color="k", zorder=3, label="strand particles")
    axes.scatter(flat[1::2, 0], flat[1::2, 1], s=22, color=STRUCTURAL, zorder=3,
                 label="structural particles")
    axes.scatter(flat[:3, 0], flat[:3, 1], s=60, facecolors="none", edgecolors="grey",
                 zorder=4, label="pinned")
    axes.set_title(title, fontsize=9)
    axes.set_aspect("equal")
    axes.axis("off")


def springs_figure() -> None:
    """Fig. 4.4 from anchored_head.toml's first strand: its rest chain (the springs attached to
    the styled strand), then the simulation's chain at 1 s (the right-hand pose)."""
    scene = load_scene(ROOT / "examples" / "cartoon_hair" / "anchored_head.toml")
    obj = scene.objects[0]
    material, params = obj.material, obj.material.params
    rest = material.rest_strands(obj)
    pick = int(np.argmax(np.linalg.norm(rest[:, -1] - rest[:, 0], axis=-1)))  # a long one
    simulation = HairSimulation(rest, hair_physics(params), material.spheres(obj),
                                material.keyframe_strands(rest.shape), params.key_times,
                                obj.model)
    simulation.advance(1.0, lambda t: obj.model)
    styled = structured_chain(rest[pick:pick + 1])[0]
    moved = simulation.particles[pick]
    plane = plane_of(np.vstack([styled, moved]))
    figure, axes = plt.subplots(1, 2, figsize=(9.0, 3.6), dpi=100)
    draw_chain(axes[0], styled, rest[pick], plane, "4.4 springs on the styled strand")
    draw_chain(axes[1], moved, simulation.strands[pick], plane, "in the simulation at 1 s")
    handles, labels = axes[0].get_legend_handles_labels()
    figure.legend(handles, labels, fontsize=8, loc="lower center", ncol=4, frameon=False)
    for a in axes:
        a.autoscale()
    save(figure, "fig4_4_springs.png")


def oblique(points: np.ndarray) -> np.ndarray:
    """A view of a tube along x from a little above and in front."""
    turn, tilt = np.radians(-50.0), np.radians(25.0)
    yaw = np.array([[np.cos(turn), 0.0, np.sin(turn)], [0.0, 1.0, 0.0],
                    [-np.sin(turn), 0.0, np.cos(turn)]])
    pitch = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(tilt), -np.sin(tilt)],
                      [0.0, np.sin(tilt), np.cos(tilt)]])
    return points @ (pitch @ yaw).T


def tube_figure() -> None:
    """Figs. 4.5-4.6: a hexagonal tube of 4 rings (the thesis' figures' shape) as build_tubes
    makes it: its vertices ring by ring (the caps' centres last), then its triangles in order.
    Faces turned away from the view are faint."""
    x = np.linspace(0.0, 1.0, 4)
    strand = np.stack([0.6 * x, 0.05 * np.sin(2.0 * x), np.zeros_like(x)], axis=-1)[None]
    tube = build_tubes(strand, samples=4, sides=6, radius=0.12, taper=(0.0, -0.5, 1.0))
    view = oblique(tube.positions.astype(np.float64))
    flat, faces = view[:, :2], tube.indices.astype(np.int64)
    a, b, c = (view[faces[:, k]] for k in range(3))
    front = np.cross(b - a, c - a)[:, 2] > 0.0
    figure, axes = plt.subplots(1, 2, figsize=(11.0, 4.2), dpi=100)
    for panel in axes:
        panel.add_collection(PolyCollection([flat[f] for f in faces[~front]], facecolors="none",
                                            edgecolors="#dddddd", linewidths=0.6))
        panel.add_collection(PolyCollection([flat[f] for f in faces[front]],
                                            facecolors="#fbf3e4", edgecolors="#555555",
                                            linewidths=0.8))
        panel.set_aspect("equal")
        panel.axis("off")
        panel.autoscale()
    seen = np.zeros(len(flat), bool)
    seen[faces[front].reshape(-1)] = True
    for index, (px, py) in enumerate(flat):
        axes[0].text(px, py, str(index), fontsize=7, ha="center", va="center",
                     color="k" if seen[index] else "#aaaaaa",
                     bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none",
                           "alpha": 0.8 if seen[index] else 0.0})
    axes[0].set_title("4.5 the vertices, ring by ring (caps' centres last)", fontsize=9)
    centres = flat[faces].mean(axis=1)
    for index in np.flatnonzero(front):
        axes[1].text(*centres[index], str(index), fontsize=7, ha="center", va="center")
    axes[1].set_title(f"4.6 the triangles in index order ({len(faces)}: "
                      f"{' '.join(map(str, faces[0]))}, {' '.join(map(str, faces[1]))}, ...)",
                      fontsize=9)
    save(figure, "fig4_5_4_6_tube_vertices_and_triangles.png")


SIZE = 480


def silhouette_figure() -> None:
    """Figs. 4.14-4.16 and the strokes' texture coordinates, from SilhouetteEdges (the compute
    pass the material runs) over one wavy tube: which triangles face the eye, the silhouette
    edges between front and back faces, those edges on screen, the quads extruded from them
    (8 pixels wide here, to be seen), and each quad's (along, across) coordinates."""
    gl = create_context()
    if not edges_on_gpu(gl):
        print("no compute shaders: Figs. 4.14-4.16 skipped")
        gl.release()
        return
    samples, sides, radius = 10, 8, 0.12
    t = np.linspace(0.0, 1.0, 6)
    strand = np.stack([1.6 * t - 0.8, 0.25 * np.sin(4.0 * t), 0.3 * np.cos(3.0 * t)], -1)[None]
    tube = build_tubes(strand, samples, sides, radius, taper=(0.0, -0.8, 1.0))
    model_view = np.eye(4)
    model_view[:3, 3] = (0.0, 0.0, -2.0)
    projection = np.array([[1.6, 0, 0, 0], [0, 1.6, 0, 0], [0, 0, -1.02, -0.2], [0, 0, -1, 0]])
    stroke = {"u_projection": tuple(projection.T.reshape(-1)),
              "u_resolution": (float(SIZE), float(SIZE)), "u_stroke_width": 8.0,
              "u_stroke_world_width": 0.0, "u_tube_radius": radius,
              "u_tube_taper": (0.0, -0.8, 1.0), "u_stroke_tolerance": 0.0}
    gl.make_current()
    vertices = gl.ctx.buffer(np.hstack([tube.positions, tube.normals]).astype(np.float32))
    edges = SilhouetteEdges(gl.ctx, 1, samples, sides)
    shaders = ShaderLibrary(gl.ctx, gl.features.glsl_version())
    try:
        edges.find(shaders, vertices, model_view, stroke)
        corners = edges.corners()
    finally:
        for thing in (edges, vertices, shaders):
            thing.release()
        gl.release()
    view = tube.positions.astype(np.float64) + model_view[:3, 3]
    clip = np.hstack([view, np.ones((len(view), 1))]) @ projection.T
    screen = pixels(clip[:, :2] / clip[:, 3:])
    faces = tube.indices.astype(np.int64)
    a, b, c = (view[faces[:, k]] for k in range(3))
    front = -(np.cross(b - a, c - a) * a).sum(-1) > 0.0
    quad = pixels(corners[..., :2])  # (strokes, 4, 2): end 0 -/+, end 1 -/+
    ends = 0.5 * (quad[:, 0::2] + quad[:, 1::2])  # each end's middle: the edge's vertices
    figure, axes = plt.subplots(1, 4, figsize=(16.0, 4.4), dpi=100)
    axes[0].add_collection(PolyCollection([screen[f] for f in faces[~front]],
                                          facecolors="#8c8c8c", edgecolors="#5a5a5a",
                                          linewidths=0.4))
    axes[0].add_collection(PolyCollection([screen[f] for f in faces[front]],
                                          facecolors=(0.98, 0.95, 0.89, 0.7),
                                          edgecolors="#b0a898",
                                          linewidths=0.4))
    axes[0].add_collection(LineCollection(ends, colors="#d62728", linewidths=2.0))
    axes[0].set_title("4.14 front faces (light, see-through) over back\n"
                      "faces (grey); silhouette edges (red)", fontsize=9)
    axes[1].add_collection(LineCollection(ends, colors="k", linewidths=1.2))
    axes[1].scatter(ends[..., 0].reshape(-1), ends[..., 1].reshape(-1), s=5, color="#d62728",
                    zorder=3)
    axes[1].set_title(f"4.15 the {len(ends)} silhouette edges on screen\n(unchained: each "
                      "stroked on its own)", fontsize=9)
    axes[2].add_collection(LineCollection(ends, colors="#aaaaaa", linewidths=0.8))
    axes[2].add_collection(PolyCollection(quad[:, [0, 1, 3, 2]], facecolors="none",
                                          edgecolors="k", linewidths=0.6))
    axes[2].set_title("4.16 quads extruded along the vertex normals\n(neighbours share "
                      "corners)", fontsize=9)
    triangles = np.arange(len(quad))[:, None, None] * 4 + np.array([[0, 1, 2], [2, 1, 3]])
    points = quad.reshape(-1, 2)
    along, across = corners[..., 4].reshape(-1), corners[..., 5].reshape(-1)
    shading = axes[3].tripcolor(points[:, 0], points[:, 1], triangles.reshape(-1, 3), along,
                                shading="gouraud", cmap="viridis")
    for side, color in ((0, "#ffffff"), (1, "#d62728")):
        axes[3].add_collection(LineCollection(quad[:, side::2], colors=color, linewidths=0.8))
    figure.colorbar(shading, ax=axes[3], fraction=0.04, pad=0.02, label="along (root 0, tip 1)")
    axes[3].set_title("the strokes' texture coordinates: along (colour),\nacross 0 (white) "
                      "to 1 (red)", fontsize=9)
    low, high = screen.min(axis=0) - 12.0, screen.max(axis=0) + 12.0
    for panel in axes:
        panel.set_xlim(low[0], high[0])
        panel.set_ylim(low[1], high[1])
        panel.set_aspect("equal")
        panel.axis("off")
    print(f"{len(quad)} strokes, {int(front.sum())} of {len(faces)} triangles facing the eye, "
          f"across {sorted(set(np.round(across, 3)))}")
    save(figure, "fig4_14_4_16_silhouette_edges_and_strokes.png")


def pixels(ndc: np.ndarray) -> np.ndarray:
    return (np.asarray(ndc, np.float64) * 0.5 + 0.5) * SIZE


def curl_strands() -> list[list[list[float]]]:
    """Three curls hanging from a small ball (object space, the ball's centre at the origin):
    helices about the vertical, seen from above, so each turn's far half crosses behind its
    near half."""
    strands = []
    for k, x in enumerate((-0.42, 0.0, 0.42)):
        angle = np.linspace(0.0, 4.0 * np.pi, 48) + 0.8 * k
        helix = np.stack([x + 0.15 * np.cos(angle), -0.2 - 0.045 * angle,
                          0.15 * np.sin(angle)], axis=-1)
        root = [0.15 * np.sign(x), -0.08, 0.0]
        strands.append(np.vstack([root, helix]).round(5).tolist())
    return strands


def overlap_figure() -> None:
    """Fig. 4.18 (the strokes of a strand overlapping itself, deferred's ID-buffer rule against
    forward's depth test) and 4.19 (the same faded toward the roots)."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "curls.json"
        path.write_text(json.dumps({"strands": curl_strands()}))

        def scene(fade):
            return scene_from_dict({
                "size": [360, 300], "tonemap": "none", "background": [0.93, 0.93, 0.96],
                "camera": {"position": [0.0, 1.55, 1.9], "target": [0.0, 0.3, 0.0],
                           "fov": 30.0},
                "object": [{"name": "ball", "mesh": "builtin:sphere?radius=0.1",
                            "material": "cartoon_hair", "position": [0.0, 0.62, 0.0],
                            "params": {"strands_file": str(path), "radius": 0.045,
                                       "hair_samples": 64, "sides": 10,
                                       "taper": [0.0, -0.4, 1.0], "gravity": [0.0, 0.0, 0.0],
                                       "color": [0.95, 0.72, 0.38], "silhouettes": True,
                                       "stroke_width": 4.0, "stroke_fade": fade,
                                       "stroke_color": [0.02, 0.01, 0.04]}}],
                "light": [{"type": "directional", "direction": [-0.5, -0.6, -0.6]}]})

        panels = []
        for label, pipeline, fade in (
                ("4.18 deferred: ID buffer, seen through itself", "deferred", [0.0, 0.0, 1.0]),
                ("forward: depth test", "forward", [0.0, 0.0, 1.0]),
                ("4.19 deferred, faded toward the root", "deferred", [-1.0, 2.0, 0.0])):
            with Renderer(scene(fade), pipeline) as renderer:
                image = renderer.render().image[..., :3]
            panels.append(preview.labelled(image, label, color=(0, 0, 0), box=None))
    gap = np.full((panels[0].shape[0], 4, 3), 255, np.uint8)
    write_image(FIGURES / "fig4_18_self_overlap.png",
                np.concatenate([panels[0], gap, panels[1], gap, panels[2]], axis=1))


def save(figure, name: str) -> None:
    figure.tight_layout(rect=(0.0, 0.08, 1.0, 1.0))
    figure.savefig(FIGURES / name)
    plt.close(figure)


def main() -> None:
    FIGURES.mkdir(parents=True, exist_ok=True)
    springs_figure()
    tube_figure()
    silhouette_figure()
    overlap_figure()
    print(f"wrote the cartoon hair step figures into {FIGURES.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
