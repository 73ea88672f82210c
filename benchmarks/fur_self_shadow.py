"""What fur self-shadowing costs: the demo with shadows (examples/shadows_demo.toml, its size,
two fur objects under three shadowed lights) with the fur's deep opacity maps
(self_shadow_density at its default) against without (0: gamma(h) only), in both pipelines
(the deferred shells evaluate the shadowed lights again for their transmittance). Median
wall-clock frame time around ``ctx.finish()``, and the ``shadows`` pass's alone (the depth
atlas, and the opacity maps where drawn). Run from the repository root:

    python benchmarks/fur_self_shadow.py [--size WxH] [--runs N]
"""

from __future__ import annotations

import argparse

from shadows import timed  # benchmarks/shadows.py

from deferred.bench.scenes import set_self_shadow_density
from deferred.gl.context import create_context
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene

DEMO = "examples/shadows_demo.toml"


def demo(density: float | None):
    """The demo, its fur's self_shadow_density set (None: the default)."""
    scene = load_scene(DEMO)
    return scene if density is None else set_self_shadow_density(scene, density)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", default="960x540")
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    gl = create_context()
    print("| pipeline | light path | without self-shadowing | with | ratio |")
    print("|---|---|---:|---:|---:|")
    for pipeline, path in (("forward", "tiled"), ("forward", "naive"), ("deferred", "tiled")):
        ms = {}
        for label, density in (("without", 0.0), ("with", None)):
            with Renderer(demo(density), pipeline, size, gl=gl, light_path=path) as renderer:
                ms[label] = timed(renderer, args.runs)
        without, with_ = ms["without"], ms["with"]
        print(f"| {pipeline} | {path} | {without[0]:.1f} (shadows {without[1]:.1f}) | "
              f"{with_[0]:.1f} (shadows {with_[1]:.1f}) | {with_[0] / without[0]:.2f}x |",
              flush=True)


if __name__ == "__main__":
    main()
