"""The framework's CPU time per draw call, this checkout against another, in paired trials.

Two worker processes, one running each checkout's Python, each hold renderers of 25 and 400
standard-material cubes (``draw_overhead.py``'s scene) on the tiled deferred and naive forward
paths; the trials alternate between them (which goes first alternates too), so a change in the
machine's speed falls on both alike. Each trial of a worker times 8 frames of each renderer
(``time_cpu``) and takes the slope between the two: microseconds per draw. Printed per path:
each side's median, the median of the paired differences (new - old) and in how many trials
the new side was faster. Two fresh processes of the same code differ by up to about 0.7 us a
draw that the pairing cannot take out (where each process's memory and code land): run it
several times and read the differences together. Run from the repository root:

    python benchmarks/draw_overhead_ab.py OLD_CHECKOUT [--trials N]

The editable install maps ``deferred.shaders``, ``deferred.materials`` and ``deferred.lights``
to this checkout's folders: link them inside the old checkout's ``deferred/`` first
(``ln -s ../shaders OLD/deferred/shaders``, and the same for ``materials`` and ``lights``), or
the old side runs this checkout's shaders and plugins.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

# The worker imports what both an older flat layout and the layered one name alike, or tries
# both spellings.
WORKER = r'''
import json, sys
import numpy as np
try:
    from deferred.bench.timing import time_cpu
except ImportError:
    from deferred.bench import time_cpu
try:
    from deferred.scene.camera import Camera
    from deferred.scene.meshes import load_mesh
except ImportError:
    from deferred.camera import Camera
    from deferred.mesh import load_mesh
from deferred import Renderer, Scene, create_context
from deferred.lights.ambient import AmbientLight
from deferred.lights.directional import DirectionalLight

def cube_grid(count):
    side = int(np.ceil(np.sqrt(count)))
    scene = Scene(camera=Camera(position=(0.0, 0.0, 1.6 * side), target=(0.0, 0.0, 0.0)),
                  source=f"{count} cubes")
    scene.lights = [AmbientLight.from_dict({}), DirectionalLight.from_dict({})]
    mesh = load_mesh("builtin:cube")
    rng = np.random.default_rng(7)
    for index in range(count):
        row, column = divmod(index, side)
        scene.add(mesh, "standard", position=(column - (side - 1) / 2, row - (side - 1) / 2, 0.0),
                  scale=0.35, params={"color": [float(c) for c in rng.uniform(0.2, 0.9, 3)]})
    return scene

gl = create_context()
paths = [("deferred", "tiled"), ("forward", "naive")]
renderers = {path: [Renderer(cube_grid(n), path[0], (160, 90), gl=gl, light_path=path[1])
                    for n in (25, 400)] for path in paths}
for group in renderers.values():
    for renderer in group:
        for _ in range(3):
            renderer.render(readback=False)
print("ready", flush=True)
for _ in sys.stdin:
    slopes = {}
    for path, (few, many) in renderers.items():
        (few_ms, few_draws), (many_ms, many_draws) = time_cpu(few, 8), time_cpu(many, 8)
        slopes["/".join(path)] = 1000.0 * (many_ms - few_ms) / (many_draws - few_draws)
    print(json.dumps(slopes), flush=True)
'''


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", type=Path, help="the other checkout's root")
    parser.add_argument("--trials", type=int, default=21)
    args = parser.parse_args()
    here = Path(__file__).resolve().parents[1]
    workers = {}
    for side, root in (("old", args.old.resolve()), ("new", here)):
        env = dict(os.environ, PYTHONPATH=str(root))
        workers[side] = subprocess.Popen([sys.executable, "-c", WORKER], cwd=root, env=env,
                                         stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                         text=True)
    try:
        for worker in workers.values():
            if worker.stdout.readline().strip() != "ready":
                raise SystemExit("a worker did not start (see its error above)")
        results: dict[str, list[dict[str, float]]] = {side: [] for side in workers}
        for trial in range(args.trials):
            for side in (("old", "new") if trial % 2 == 0 else ("new", "old")):
                workers[side].stdin.write("trial\n")
                workers[side].stdin.flush()
                results[side].append(json.loads(workers[side].stdout.readline()))
    finally:
        for worker in workers.values():
            worker.stdin.close()
            worker.wait()
    for path in results["old"][0]:
        old = [trial[path] for trial in results["old"]]
        new = [trial[path] for trial in results["new"]]
        differences = [n - o for o, n in zip(old, new, strict=True)]
        faster = sum(d < 0 for d in differences)
        difference = statistics.median(differences)
        print(f"{path}: old {statistics.median(old):.1f} us a draw, new "
              f"{statistics.median(new):.1f}; paired difference {difference:+.2f} us, the new "
              f"side faster in {faster} of {args.trials}")


if __name__ == "__main__":
    main()
