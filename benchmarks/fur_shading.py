"""What revie_fur's shading options cost on the built-in demo: ``shading = "marschner"`` against
the default ``classic`` (the grain normal and rim), and the slab's second strand sample
(materials/revie_fur/slab.glsl) against one sample at the shell's height
(``benchmarks/variants/one_slab_sample``, a cut-out). Frames of the variants interleaved on one
GL context, as benchmarks/shader_ab.py does, in each pipeline; each round renders each variant's
frame timed by wall clock around ``render()`` and ``finish()``, then one with every pass fenced.
Printed: each variant's median and minimum frame time and the medians of its passes of 2 ms or
more. Run from the repository root:

    python benchmarks/fur_shading.py [--size WxH] [--rounds N] [--pipelines deferred,forward]

benchmarks/README.md ("revie_fur's shading options on the demo") has the results.
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

from deferred.bench.timing import interleaved_rounds
from deferred.errors import DeferredError
from deferred.gl.context import create_context
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "deferred" / "scenes" / "demo.toml"
ONE_SAMPLE = ROOT / "benchmarks" / "variants" / "one_slab_sample"

# (label, params set on every revie_fur object, shader root replacing files or None)
VARIANTS = [("classic, two slab samples (default)", {}, None),
            ("classic, one slab sample", {}, ONE_SAMPLE),
            ("marschner, two slab samples", {"shading": "marschner"}, None)]


def parse_size(text: str) -> tuple[int, int]:
    width, _, height = text.partition("x")
    return int(width), int(height)


def demo_with(params: dict):
    data = tomllib.loads(DEMO.read_text(encoding="utf-8"))
    for obj in data["object"]:
        if obj.get("material") == "revie_fur":
            obj["params"].update(params)
    return scene_from_dict(data, "the demo", DEMO.parent)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=parse_size, default=(640, 360))
    parser.add_argument("--rounds", type=int, default=9)
    parser.add_argument("--pipelines", default="deferred,forward")
    args = parser.parse_args(argv)
    gl = create_context()
    try:
        for pipeline in args.pipelines.split(","):
            renderers = []
            for _, params, root in VARIANTS:
                renderer = Renderer(demo_with(params), pipeline, args.size, gl=gl)
                if root is not None:
                    renderer.shaders.add_root(root, first=True)
                renderer.render(readback=False)  # compiles
                renderers.append(renderer)
            frames, passes = interleaved_rounds(renderers, args.rounds)
            for (label, _, _), times, by_pass in zip(VARIANTS, frames, passes, strict=True):
                fur = ", ".join(f"{name} {statistics.median(ms):.1f}"
                                for name, ms in by_pass.items()
                                if statistics.median(ms) >= 2.0)
                print(f"{pipeline} {args.size[0]}x{args.size[1]}, {label}: median "
                      f"{statistics.median(times):.1f} ms, min {min(times):.1f} ms; {fur}")
            for renderer in renderers:
                renderer.release()
    except DeferredError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    finally:
        gl.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
