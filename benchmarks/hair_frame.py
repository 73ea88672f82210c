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
  silhouette strokes) in each pipeline, the hair moving, wall clock around ``ctx.finish()``;
- with ``--whole N``: only the whole deferred frame of N strands with the silhouette strokes and
  the edges effect at ``--size`` (1280x720), its process CPU time and wall clock and those of
  its passes, the strokes made by the compute pass (``SilhouetteEdges``) and by the geometry
  shader (the GL 3.3 path, the tubes by numpy), in turns for ``--rounds`` rounds (the median
  and the range of the rounds' medians).

    OPENBLAS_NUM_THREADS=1 python benchmarks/hair_frame.py [--frames N] [--no-silhouettes]
        [--pipelines]
    OPENBLAS_NUM_THREADS=1 python benchmarks/hair_frame.py --whole 10000 [--size 1280x720]
        [--rounds 3] [--frames 4]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from deferred.gl.context import Features, GLContext, create_context
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


HAIR_PASSES = ("hair", "silhouettes", "edges")  # the passes --whole reports on their own


def whole_frame_passes(count: int, frames: int, gl, size: tuple[int, int]
                       ) -> dict[str, tuple[float, float]]:
    """Median (process CPU ms, wall ms) a frame of the whole deferred frame (``frame``) and of
    the passes named with HAIR_PASSES (the edges effect's passes summed), the hair moving:
    spiky hair with silhouette strokes and the edges effect."""
    spent: dict[str, list[tuple[float, float]]] = {}
    with Renderer(head_scene(count, silhouettes=True, hair_samples=8, sides=8), "deferred",
                  size=size, gl=gl) as renderer:
        ctx = renderer.gl.ctx
        started: dict[str, tuple[float, float]] = {}
        totals: dict[str, list[float]] = {}

        def part(name: str) -> str | None:
            return next((key for key in HAIR_PASSES if key in name.rsplit(".", 1)[-1]), None)

        def before(render_pass, frame):
            if part(render_pass.name):
                ctx.finish()
                started[render_pass.name] = (time.process_time(), time.perf_counter())

        def after(render_pass, frame):
            if render_pass.name in started:
                ctx.finish()
                cpu, wall = started.pop(render_pass.name)
                total = totals.setdefault(part(render_pass.name), [0.0, 0.0])
                total[0] += time.process_time() - cpu
                total[1] += time.perf_counter() - wall

        for frame in range(frames + 1):  # the first builds the programs: not timed
            totals.clear()
            ctx.finish()
            cpu, wall = time.process_time(), time.perf_counter()
            renderer.render(time=0.2 + frame / 30.0, readback=False, before_pass=before,
                            on_pass=after)
            ctx.finish()
            if frame:
                spent.setdefault("frame", []).append((time.process_time() - cpu,
                                                      time.perf_counter() - wall))
                for name, (c, w) in totals.items():
                    spent.setdefault(name, []).append((c, w))
    return {name: (statistics.median(v[0] for v in values) * 1000.0,
                   statistics.median(v[1] for v in values) * 1000.0)
            for name, values in spent.items()}


def whole(count: int, size: tuple[int, int], rounds: int, frames: int, gl) -> None:
    """``--whole``: the compute path and the geometry shader's in turns."""
    paths = {"compute": gl,
             "geometry shader": GLContext(gl.ctx, Features(storage_buffers=True,
                                                           compute_shaders=False))}
    results: dict[str, list[dict[str, tuple[float, float]]]] = {name: [] for name in paths}
    for _ in range(rounds):
        for name, context in paths.items():
            results[name].append(whole_frame_passes(count, frames, context, size))
    print(f"{count:,} strands, {size[0]}x{size[1]}, deferred, silhouettes and edges; "
          f"median of {rounds} rounds of {frames} frames (range), process CPU ms / wall ms")
    for name, runs in results.items():
        parts = []
        for key in ("frame", *HAIR_PASSES):
            cpu = [run[key][0] for run in runs if key in run]
            wall = [run[key][1] for run in runs if key in run]
            if cpu:
                parts.append(f"{key} {statistics.median(cpu):.0f} ({min(cpu):.0f}-"
                             f"{max(cpu):.0f}) / {statistics.median(wall):.0f} "
                             f"({min(wall):.0f}-{max(wall):.0f})")
        print(f"  {name}: " + "; ".join(parts), flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=30)
    parser.add_argument("--no-silhouettes", action="store_true")
    parser.add_argument("--pipelines", action="store_true")
    parser.add_argument("--whole", type=int, default=0, metavar="STRANDS")
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    gl = create_context()
    if not gl.features.compute_shaders:
        raise SystemExit("the GPU tubes need compute shaders (GL 4.3)")
    if args.whole:
        try:
            whole(args.whole, tuple(int(v) for v in args.size.split("x")), args.rounds,
                  min(args.frames, 4) if args.frames == 30 else args.frames, gl)
        finally:
            gl.release()
        return
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
