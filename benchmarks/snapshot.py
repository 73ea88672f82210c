"""Renders of a fixed set of scenes through every light path, saved to compare two versions of
the code: ``snapshot.py save OUT.npz`` renders, ``snapshot.py compare A.npz B.npz`` says which
arrays differ and by how much (exit code 1 where any does). A refactor that should change no
pixel shows 0 differing arrays.

The set: the built-in demo, ``benchmarks/lights.toml``, every ``examples/*.toml`` and
shell_fur's ``fig7_curls`` and ``wet_wind`` (at 0 and 0.5 s: it simulates), each at 160x90
through deferred tiled, clustered and volumes and forward naive and tiled (shell_fur scenes skip
clustered), as the final 8-bit image and the HDR composition. Run from the repository root.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

SIZE = (160, 90)
COMBOS = [("deferred", "tiled"), ("deferred", "clustered"), ("deferred", "volumes"),
          ("forward", "naive"), ("forward", "tiled")]


def scenes() -> list[str | None]:
    figures = sorted(str(path) for path in Path("examples").glob("*.toml"))
    return [None, "benchmarks/lights.toml", *figures, "examples/shell_fur/fig7_curls.toml",
            "examples/shell_fur/wet_wind.toml"]


def save(out: str) -> None:
    from deferred import Renderer, load_scene

    arrays = {}
    for name in scenes():
        for pipeline, path in COMBOS:
            if name and "shell_fur" in name and path == "clustered":
                continue
            with Renderer(load_scene(name), pipeline, SIZE, light_path=path) as renderer:
                for time in ((0.0, 0.5) if name and "wet_wind" in name else (0.0,)):
                    renderer.render(time=time)
                    key = f"{name or 'demo'}|{pipeline}|{path}|{time}"
                    arrays[f"{key}|final"] = renderer.read_final()
                    arrays[f"{key}|hdr"] = renderer.read_hdr()
            print(f"{name or 'demo'} {pipeline} {path}", flush=True)
    np.savez_compressed(out, **arrays)


def compare(first: str, second: str) -> int:
    a, b = np.load(first), np.load(second)
    differ = 0
    for key in sorted(set(a.files) | set(b.files)):
        if key not in a.files or key not in b.files:
            print(f"only in one: {key}")
            differ += 1
        elif a[key].shape != b[key].shape or not np.array_equal(a[key], b[key]):
            worst = np.abs(a[key].astype(np.float64) - b[key].astype(np.float64)).max() \
                if a[key].shape == b[key].shape else float("nan")
            print(f"differs: {key} (largest difference {worst:g})")
            differ += 1
    print(f"{len(a.files)} arrays, {differ} differ")
    return 1 if differ else 0


def main() -> int:
    if len(sys.argv) == 3 and sys.argv[1] == "save":
        save(sys.argv[2])
        return 0
    if len(sys.argv) == 4 and sys.argv[1] == "compare":
        return compare(sys.argv[2], sys.argv[3])
    print(__doc__.splitlines()[0] + "\nusage: snapshot.py save OUT.npz | compare A.npz B.npz",
          file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
