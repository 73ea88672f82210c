"""CPU time a frame of cartoon_hair's simulation and tube building (Costigan's Table 5.3 and
Fig. 5.1: 100 strands x 8 samples x 8 sides at 28 fps): spiky hair on the built-in head turning
back and forth, 30 frames a second at a fixed step of 1/60 s (two steps a frame), 8 samples x 8
sides, for 100, 1,000 and 10,000 strands, with averaged and with swept normals.

    python benchmarks/hair_frame.py [--iterations N] [--frames N]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from deferred.materials.techniques.hair_dynamics import HairPhysics, HairSimulation
from deferred.materials.techniques.hair_strands import grow_strands, scalp_roots
from deferred.materials.techniques.hair_tubes import build_tubes
from deferred.scene.builtin_meshes import builtin_head_spheres
from deferred.scene.meshes import load_mesh


def turning_head(t: float) -> np.ndarray:
    angle = 0.6 * np.sin(2.0 * np.pi * t)
    c, s = np.cos(angle), np.sin(angle)
    model = np.eye(4)
    model[:3, :3] = [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
    return model


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--iterations", type=int, default=1)
    parser.add_argument("--frames", type=int, default=30)
    args = parser.parse_args()
    head, spheres = load_mesh("builtin:head"), builtin_head_spheres()
    for count in (100, 1000, 10000):
        strands = grow_strands(scalp_roots(head, count, 1), 0.15, 7, "spiky", 1, spheres)
        physics = HairPhysics(bend_stiffness=0.6, torsion_stiffness=0.6,
                              iterations=args.iterations)
        simulation = HairSimulation(strands, physics, spheres=spheres)
        simulation.advance(0.2, turning_head)
        for normals in ("averaged", "swept"):
            simulated = tubed = 0.0
            for frame in range(args.frames):
                start = time.process_time()
                simulation.advance(0.2 + (frame + 1) / 30.0, turning_head)
                middle = time.process_time()
                build_tubes(simulation.strands, 8, 8, 0.004, (0.0, -1.0, 1.0),
                            simulation.root_references(), normals)
                simulated += middle - start
                tubed += time.process_time() - middle
            print(f"{count:6d} strands, {normals:8s} normals: simulation "
                  f"{simulated / args.frames * 1e3:6.2f} ms + tubes "
                  f"{tubed / args.frames * 1e3:6.2f} ms = "
                  f"{(simulated + tubed) / args.frames * 1e3:6.2f} ms a frame")


if __name__ == "__main__":
    main()
