"""The time a frame of cartoon_hair's simulation, tubes and silhouette strokes (Costigan's
Table 5.3 and Fig. 5.1: 100 strands x 8 samples x 8 sides at 28 fps): spiky hair on the built-in
head turning back and forth, 30 frames a second at a fixed step of 1/60 s (two steps a frame),
8 samples x 8 sides, for 100, 1,000 and 10,000 strands.

- simulation: process CPU time of the numpy steps;
- tubes, GPU: the strands' upload and the two compute shaders (:class:`GpuTubes`, what the
  material runs), wall clock around ``ctx.finish()`` and process CPU time (on llvmpipe the
  "GPU" is this process's threads, so its work is CPU time too);
- tubes, numpy: :func:`build_tubes` (the GL 3.3 path and the tests' reference), process CPU;
- silhouettes: the ``.silhouettes`` pass of the spiky head scene at 640x360 with that many
  strands (the geometry shader finding and extruding the tubes' silhouette edges, and their
  strokes' fragments), wall clock around ``ctx.finish()``;
- with ``--pipelines``: the whole frame of that scene (outlines by the edges effect, no
  silhouette strokes) in each pipeline, the hair moving, wall clock around ``ctx.finish()``.

    OPENBLAS_NUM_THREADS=1 python benchmarks/hair_frame.py [--frames N] [--no-silhouettes]
        [--pipelines]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from deferred.gl.context import create_context
from deferred.gl.shaderlib import ShaderLibrary
from deferred.materials.techniques.hair_dynamics import HairPhysics, HairSimulation
from deferred.materials.techniques.hair_strands import grow_strands, scalp_roots
from deferred.materials.techniques.hair_tubes import GpuTubes, build_tubes
from deferred.render.renderer import Renderer
from deferred.scene.builtin_meshes import builtin_head_spheres
from deferred.scene.loader import load_scene
from deferred.scene.meshes import load_mesh

COUNTS = (100, 1000, 10000)
TAPER = (0.0, -1.0, 1.0)


def turning_head(t: float) -> np.ndarray:
    angle = 0.6 * np.sin(2.0 * np.pi * t)
    c, s = np.cos(angle), np.sin(angle)
    model = np.eye(4)
    model[:3, :3] = [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
    return model


def simulation_and_tubes(count: int, frames: int, gl, shaders) -> dict[str, float]:
    """Median milliseconds a frame of each part."""
    head, spheres = load_mesh("builtin:head"), builtin_head_spheres()
    strands = grow_strands(scalp_roots(head, count, 1), 0.15, 7, "spiky", 1, spheres)
    simulation = HairSimulation(strands, HairPhysics(bend_stiffness=0.6, torsion_stiffness=0.6),
                                spheres=spheres)
    simulation.advance(0.2, turning_head)
    tubes = GpuTubes(gl.ctx, count, simulation.point_count, 8, 8)
    vertices = gl.ctx.buffer(reserve=tubes.vertex_count * 24)
    times: dict[str, list[float]] = {"simulation": [], "gpu_wall": [], "gpu_cpu": [],
                                     "numpy": []}
    try:
        for frame in range(frames + 1):  # the first builds the programs: not timed
            start = time.process_time()
            simulation.advance(0.2 + (frame + 1) / 30.0, turning_head)
            simulated = time.process_time()
            gl.ctx.finish()
            wall = time.perf_counter()
            tubes.upload(simulation.component_points, simulation.component_references())
            tubes.build(shaders, vertices, 0.004, TAPER, np.linalg.inv(turning_head(0.0)))
            gl.ctx.finish()
            wall = time.perf_counter() - wall
            built = time.process_time()
            build_tubes(simulation.strands, 8, 8, 0.004, TAPER, simulation.root_references())
            if frame:
                times["simulation"].append(simulated - start)
                times["gpu_wall"].append(wall)
                times["gpu_cpu"].append(built - simulated)
                times["numpy"].append(time.process_time() - built)
    finally:
        tubes.release()
        vertices.release()
    return {key: statistics.median(values) * 1000.0 for key, values in times.items()}


def head_scene(count: int, **params):
    """The spiky head example with ``count`` strands (thinner at 10,000)."""
    scene = load_scene("examples/cartoon_hair/spiky_head.toml")
    scene.objects[0].set_params(strands=count, radius=0.012 if count < 10000 else 0.005,
                                **params)
    return scene


def whole_frames(count: int, frames: int, gl, pipeline: str) -> float:
    """Median milliseconds of a whole frame, the hair moving."""
    spent: list[float] = []
    with Renderer(head_scene(count), pipeline, size=(640, 360), gl=gl) as renderer:
        ctx = renderer.gl.ctx
        for frame in range(frames + 1):
            ctx.finish()
            start = time.perf_counter()
            renderer.render(time=0.2 + frame / 30.0, readback=False)
            ctx.finish()
            spent.append(time.perf_counter() - start)
    return statistics.median(spent[1:]) * 1000.0


def silhouettes(count: int, frames: int, gl) -> float:
    """Median milliseconds of the silhouette pass a frame, the hair moving."""
    scene = head_scene(count, silhouettes=True)
    spent: list[float] = []
    with Renderer(scene, size=(640, 360), gl=gl) as renderer:
        ctx = renderer.gl.ctx
        started: dict[str, float] = {}

        def before(render_pass, frame):
            if render_pass.name.endswith(".silhouettes"):
                ctx.finish()
                started[render_pass.name] = time.perf_counter()

        def after(render_pass, frame):
            if render_pass.name in started:
                ctx.finish()
                spent.append(time.perf_counter() - started.pop(render_pass.name))

        for frame in range(frames + 1):
            renderer.render(time=0.2 + frame / 30.0, readback=False, before_pass=before,
                            on_pass=after)
    return statistics.median(spent[1:]) * 1000.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=30)
    parser.add_argument("--no-silhouettes", action="store_true")
    parser.add_argument("--pipelines", action="store_true")
    args = parser.parse_args()
    gl = create_context()
    if not gl.features.compute_shaders:
        raise SystemExit("the GPU tubes need compute shaders (GL 4.3)")
    shaders = ShaderLibrary(gl.ctx, gl.features.glsl_version())
    try:
        for count in COUNTS:
            t = simulation_and_tubes(count, args.frames, gl, shaders)
            line = (f"{count:6d} strands: simulation {t['simulation']:6.2f} ms + tubes on the GPU "
                    f"{t['gpu_wall']:6.2f} ms wall ({t['gpu_cpu']:6.2f} ms CPU) = "
                    f"{t['simulation'] + t['gpu_cpu']:6.2f} ms CPU; tubes by numpy "
                    f"{t['numpy']:6.2f} ms")
            if not args.no_silhouettes:
                line += f"; silhouette pass {silhouettes(count, min(args.frames, 8), gl):6.2f} ms"
            if args.pipelines:
                line += "; frame " + ", ".join(
                    f"{pipeline} {whole_frames(count, 6, gl, pipeline):6.1f} ms"
                    for pipeline in ("deferred", "forward"))
            print(line, flush=True)
    finally:
        gl.release()


if __name__ == "__main__":
    main()
