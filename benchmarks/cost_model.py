"""The cost model's constants measured, and its predictions against measured renders
(``deferred.render.cost``; benchmarks/README.md, "The cost model").

- ``calibrate``: each unit the model counts, timed alone in one process (wall clock around
  ``ctx.finish()``, the median of a few frames after a warm-up): the frame's own passes a
  pixel, a full-screen and a point light a pixel, an effect (ssao) a pixel, a triangle, a fur
  shell a triangle and a covered pixel and fins a triangle (revie_fur and shell_fur), a hair
  tube vertex made and built and a tube triangle drawn and stroked, a particle step and a
  collision-sphere test, a sample read back and added, a frame written, compiling a material
  type's programs.
- ``check``: the cases of the table in benchmarks/README.md through ``deferred render`` in a
  child process each (its wall clock and peak RSS), beside what the model predicts for them;
  ``--quick`` leaves out the ones that take minutes.

    python benchmarks/cost_model.py calibrate
    python benchmarks/cost_model.py check [--quick] [--case NAME ...]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from deferred.bench.scenes import with_extra_lights
from deferred.cli.budget import render_work
from deferred.gl.context import create_context
from deferred.io.images import write_image
from deferred.render.cost import loaded_objects, predict_render
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_toml
from deferred.scene.timeline import SceneEvaluator

ROOT = Path(__file__).resolve().parents[1]
FACING = """
size = [{w}, {h}]
[camera]
position = [0.0, 0.0, 2.0]
target = [0.0, 0.0, 0.0]
fov = 60.0
[[object]]
name = "subject"
mesh = "{mesh}"
material = "{material}"
rotation = [{tilt}, 0.0, 0.0]
[object.params]
{params}
[[light]]
type = "directional"
direction = [0.2, -0.5, -1.0]
{extra}
"""


def scene(mesh: str = "builtin:plane?divisions=8", material: str = "standard", params: str = "",
          size: tuple[int, int] = (256, 256), extra: str = "", tilt: float = 90.0):
    text = FACING.format(w=size[0], h=size[1], mesh=mesh, material=material, params=params,
                         extra=extra, tilt=tilt)
    return scene_from_toml(text, "calibration.toml")


def frame_seconds(gl, loaded, size=None, frames: int = 3) -> float:
    """Median wall seconds of a frame, after a warm-up frame."""
    with Renderer(loaded, "deferred", size, gl=gl) as renderer:
        renderer.render(readback=False)
        gl.ctx.finish()
        times = []
        for _ in range(frames):
            start = time.perf_counter()
            renderer.render(readback=False)
            gl.ctx.finish()
            times.append(time.perf_counter() - start)
    return statistics.median(times)


def covered(loaded, size) -> float:
    """The pixels the model counts the subject as covering (its bounds' disc)."""
    state = SceneEvaluator(loaded).evaluate(0.0)
    obj = loaded_objects(state, size)[0]
    return obj.screen.share(size) * size[0] * size[1]


def slope(x0: float, y0: float, x1: float, y1: float) -> float:
    return (y1 - y0) / (x1 - x0)


class Said(dict):
    """Units measured, each printed as it is."""

    def __setitem__(self, name: str, seconds: float) -> None:
        super().__setitem__(name, seconds)
        print(f"{name:45s} {seconds * 1e9:12.1f} ns", flush=True)

    def update(self, other: dict[str, float]) -> None:
        for name, seconds in other.items():
            self[name] = seconds


def calibrate() -> None:
    gl = create_context()
    out = Said()
    small, large = (256, 256), (1024, 1024)
    plane = [frame_seconds(gl, scene(size=s)) for s in (small, large)]
    pixels = [s[0] * s[1] for s in (small, large)]
    out["frame pixel (1 directional light)"] = slope(pixels[0], plane[0], pixels[1], plane[1])
    lit = scene(size=large, extra="\n".join(
        '[[light]]\ntype = "directional"\ndirection = [0.1, -0.5, -1.0]' for _ in range(4)))
    out["full-screen light pixel"] = (frame_seconds(gl, lit) - plane[1]) / 4 / pixels[1]
    points = with_extra_lights(scene(size=large), 64, 1.0)
    out["point light pixel (bench lights)"] = (frame_seconds(gl, points) - plane[1]) / 64 / \
        pixels[1]
    ssao = scene(size=large, extra='[[effect]]\ntype = "ssao"')
    out["ssao pixel"] = (frame_seconds(gl, ssao) - plane[1]) / pixels[1]
    tiny = (64, 64)
    mesh = "builtin:sphere?segments=1024&rings=512"
    base = frame_seconds(gl, scene(size=tiny))
    dense = frame_seconds(gl, scene(mesh=mesh, size=tiny))
    out["triangle"] = (dense - base) / (2 * 1024 * 512)
    for material in ("revie_fur", "shell_fur"):
        still = "\nsettle = 0.0" if material == "shell_fur" else ""  # no simulation steps
        few = "shells = 4\nmin_shells = 4\nfins = false" + still
        many = "shells = 36\nmin_shells = 36\nfins = false" + still
        ball = "builtin:sphere?segments=64&rings=32"
        loaded = scene(mesh=ball, material=material, params=few, size=(512, 512))
        px = covered(loaded, (512, 512))
        thin = frame_seconds(gl, loaded)
        thick = frame_seconds(gl, scene(mesh=ball, material=material, params=many,
                                        size=(512, 512)))
        out[f"{material} shell pixel"] = (thick - thin) / 32 / px
        t_few = frame_seconds(gl, scene(mesh=mesh, material=material, params=few, size=tiny))
        t_many = frame_seconds(gl, scene(mesh=mesh, material=material, params=many, size=tiny))
        out[f"{material} shell triangle"] = (t_many - t_few) / 32 / (2 * 1024 * 512)
        finned = frame_seconds(gl, scene(mesh=mesh, material=material,
                                         params=few.replace("false", "true"), size=tiny))
        out[f"{material} fin triangle"] = (finned - t_few) / (2 * 1024 * 512)
    out.update(hair_units(gl))
    out.update(sample_units(gl))
    gl.release()


def hair_units(gl) -> dict[str, float]:
    """The hair's units: making, building, drawing and stroking tubes; particles and
    spheres."""
    from deferred.materials.cartoon_hair.params import tube_counts

    out = {}
    params = "strands = {n}\nsegments = 16\nhair_samples = 32\nsides = 8\nradius = 0.003\n{x}"
    size = (128, 128)
    head = "builtin:head"
    measured = {}
    for n in (500, 4000):
        loaded = scene(mesh=head, material="cartoon_hair", params=params.format(n=n, x=""),
                       size=size, tilt=0.0)
        material = loaded.objects[0].material
        vertices, triangles = tube_counts(n, material.params)
        with Renderer(loaded, "deferred", size, gl=gl) as renderer:
            start = time.perf_counter()
            renderer.render(readback=False, time=0.0)
            gl.ctx.finish()
            first = time.perf_counter() - start
            draws, steps = [], []
            for k in range(3):
                start = time.perf_counter()
                renderer.render(readback=False, time=0.0)  # the same time: drawn only
                gl.ctx.finish()
                draws.append(time.perf_counter() - start)
                start = time.perf_counter()
                renderer.render(readback=False, time=(k + 1) / 60.0)  # a step and a build
                gl.ctx.finish()
                steps.append(time.perf_counter() - start)
        measured[n] = (vertices, triangles, first, statistics.median(draws),
                       statistics.median(steps))
    (v0, t0, f0, d0, s0), (v1, t1, f1, d1, s1) = measured[500], measured[4000]
    out["hair tube vertex made (first frame)"] = slope(v0, f0 - d0, v1, f1 - d1)
    out["hair tube triangle drawn"] = slope(t0, d0, t1, d1)
    out["hair step + build a vertex"] = slope(v0, s0 - d0, v1, s1 - d1)
    stroked = scene(mesh=head, material="cartoon_hair",
                    params=params.format(n=4000, x="silhouettes = true"), size=size, tilt=0.0)
    out["hair silhouette triangle"] = (frame_seconds(gl, stroked) - d1) / t1
    from deferred.materials.techniques.hair_dynamics import HairSimulation
    from deferred.materials.techniques.hair_strands import grow_strands, scalp_roots
    from deferred.scene.builtin_meshes import builtin_head_spheres
    from deferred.scene.meshes import load_mesh

    mesh = load_mesh(head)
    strands = grow_strands(scalp_roots(mesh, 4000, 1), 0.18, 16, "spiky", 1,
                           builtin_head_spheres())
    particles = 4000 * (2 * strands.shape[1] + 1)
    for spheres, key in ((np.zeros((0, 4)), "hair particle step"),
                         (np.tile([[0.0, 0.0, 0.0, 0.01]], (64, 1)), "hair sphere test")):
        simulation = HairSimulation(strands, spheres=spheres)
        start = time.process_time()
        simulation.advance(20 / 60.0, lambda t: np.eye(4))
        seconds = (time.process_time() - start) / 21
        out[key] = seconds / particles if len(spheres) == 0 else \
            (seconds - out["hair particle step"] * particles) / particles / len(spheres)
    return out


def sample_units(gl) -> dict[str, float]:
    """A sample read back and added; a frame written; compiling a material type."""
    size = (512, 512)
    loaded = scene(size=size)
    out = {}
    with Renderer(loaded, "deferred", size, gl=gl) as renderer:
        renderer.render(readback=False)
        start = time.perf_counter()
        for _ in range(4):
            renderer.render(readback=False)
        gl.ctx.finish()
        plain = (time.perf_counter() - start) / 4
        start = time.perf_counter()
        renderer.render_samples(4)
        sampled = (time.perf_counter() - start) / 4
    out["sample read back and added, a pixel"] = (sampled - plain) / (size[0] * size[1])
    image = np.random.default_rng(0).integers(0, 255, (1024, 1024, 4), dtype=np.uint8)
    with tempfile.TemporaryDirectory() as folder:
        start = time.perf_counter()
        write_image(Path(folder) / "x.png", image)
        out["frame written, a pixel"] = (time.perf_counter() - start) / (1024 * 1024)
    for material in ("standard", "revie_fur", "shell_fur", "cartoon_hair"):
        mesh = "builtin:head" if material == "cartoon_hair" else "builtin:sphere"
        loaded = scene(mesh=mesh, material=material, size=(64, 64))
        start = time.perf_counter()
        with Renderer(loaded, "deferred", (64, 64), gl=gl) as renderer:
            renderer.render(readback=False)
            gl.ctx.finish()
            first = time.perf_counter() - start
            start = time.perf_counter()
            renderer.render(readback=False)
            gl.ctx.finish()
            out[f"setup and compile, {material}"] = first - (time.perf_counter() - start)
    return out


# -- predicted against measured ------------------------------------------------------------------

HAIR = ROOT / "examples" / "cartoon_hair" / "spiky_head.toml"
HAIR_MAX = "strands = 20000\nsegments = 32\nhair_samples = 64\nsides = 16\nradius = 0.004\n"
FUR_5M = """size = [256, 256]
[[object]]
mesh = "builtin:sphere?segments=2236&rings=1118"
material = "shell_fur"
[[light]]
type = "directional"
direction = [0, -1, -1]
"""


def hair_scene(folder: Path, name: str, extra: str) -> Path:
    text = HAIR.read_text().replace("strands = 150\n", HAIR_MAX + extra)
    path = folder / f"{name}.toml"
    path.write_text(text)
    return path


def cases(folder: Path) -> dict[str, tuple[list[str], bool]]:
    """name -> (the render's arguments, whether it takes minutes)."""
    fur = folder / "fur5m.toml"
    fur.write_text(FUR_5M)
    hair = hair_scene(folder, "hair_max", "")
    strokes = hair_scene(folder, "hair_max_strokes", 'silhouettes = true\nhatching = "surface"\n')
    demo = []
    return {
        "demo 640x360": ([*demo, "--size", "640x360"], False),
        "demo 1280x720": ([*demo], False),
        "demo 1024x1024 x 4 samples": ([*demo, "--size", "1024x1024", "--samples", "4"], False),
        "demo 4096x4096 x 1024 samples": ([*demo, "--size", "4096x4096", "--samples", "1024"],
                                          False),
        "spiky head (150 strands)": ([str(HAIR)], False),
        "hair 20,000 x 32 x 64 x 16": ([str(hair)], True),
        "hair 20,000 x 32 x 64 x 16, silhouettes, hatching": ([str(strokes)], True),
        "shell_fur on 5M triangles": ([str(fur)], False),
        "fig2_21 (revie_fur)": ([str(ROOT / "examples" / "fig2_21_final.toml")], False),
        "shell_fur Table 1 torus": ([str(ROOT / "examples" / "shell_fur" /
                                         "table1_torus.toml")], False),
    }


def predict(arguments: list[str]) -> float:
    """What the model predicts for ``deferred render`` with ``arguments`` (the whole
    prediction, made as the command makes it)."""
    from deferred.cli.options import parse_size_option
    from deferred.scene.loader import load_scene

    scene_path = arguments[0] if arguments and not arguments[0].startswith("-") else None
    options = dict(zip(arguments[1 if scene_path else 0::2], arguments[2 if scene_path else 1::2],
                       strict=False))
    loaded = load_scene(scene_path)
    size = parse_size_option(options.get("--size")) or loaded.size
    samples = int(options.get("--samples", 1))
    state = SceneEvaluator(loaded).evaluate(0.0)
    prediction = predict_render(render_work(size, samples, [0.0], "deferred"), state.lights,
                                state.effects, loaded_objects(state, size))
    return prediction.seconds


def check(quick: bool, names: list[str]) -> None:
    with tempfile.TemporaryDirectory() as folder:
        listed = cases(Path(folder))
        env = {**os.environ, "DEFERRED_TARGET_TIME": "1e9",
               "DEFERRED_TARGET_MEMORY": str(16 << 30)}
        for name, (arguments, slow) in listed.items():
            if (names and name not in names) or (quick and slow):
                continue
            if "1024 samples" in name:  # hours: predicted and refused, not run
                env_run = os.environ.copy()
            else:
                env_run = env
            try:
                predicted = f"{predict(arguments):.1f}"
            except Exception as exc:  # noqa: BLE001 - a refusal before the meshes load
                predicted = f"refused before loading: {exc}"[:60]
            start = time.perf_counter()
            done = subprocess.run(["/usr/bin/time", "-f", "peak RSS %M KB, CPU %U + %S s",
                                   sys.executable,
                                   "-m", "deferred", "render", *arguments, "-o",
                                   str(Path(folder) / "out.png")], env=env_run,
                                  capture_output=True, text=True)
            wall = time.perf_counter() - start
            lines = [line for line in done.stderr.strip().splitlines()
                     if not line.startswith("Command exited")]  # /usr/bin/time's
            rss = lines.pop() if lines and lines[-1].startswith("peak RSS") else ""
            last = lines[-1] if lines else ""
            print(f"{name}: predicted {predicted} s, measured {wall:.1f} s, exit "
                  f"{done.returncode}, {rss}: {last[:160]}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mode", choices=("calibrate", "check"))
    parser.add_argument("--quick", action="store_true", help="check: leave out the slow cases")
    parser.add_argument("--case", action="append", default=[], help="check: only this case")
    args = parser.parse_args()
    if args.mode == "calibrate":
        calibrate()
    else:
        check(args.quick, args.case)


if __name__ == "__main__":
    main()
