"""Writes the two keyframe poses of examples/cartoon_hair/anchored_head.toml: combed hair on the
built-in head parted to the left (pose_left.json, also the rest style) and to the right
(pose_right.json), from the same roots, so the anchors (Costigan 4.2.3) can pull the hair from
one pose to the other. Run from the repository root: python examples/cartoon_hair/make_poses.py
"""

from __future__ import annotations

import json
from pathlib import Path

from deferred.materials.techniques.hair_strands import grow_strands, scalp_roots
from deferred.scene.builtin_meshes import builtin_head_spheres
from deferred.scene.meshes import load_mesh

HERE = Path(__file__).parent
STRANDS, LENGTH, SEGMENTS, SEED = 120, 0.2, 7, 3


def main() -> None:
    roots = scalp_roots(load_mesh("builtin:head"), STRANDS, SEED)
    for name, parting in (("pose_left", -0.6), ("pose_right", 0.6)):
        strands = grow_strands(roots, LENGTH, SEGMENTS, "combed", SEED, builtin_head_spheres(),
                               parting)
        (HERE / f"{name}.json").write_text(json.dumps(
            {"strands": [[[round(float(c), 5) for c in point] for point in strand]
                         for strand in strands]}) + "\n")
    print(f"wrote {STRANDS} strands in two poses into {HERE.relative_to(Path.cwd())}")


if __name__ == "__main__":
    main()
