"""PSNR between the deferred and the forward pipeline on scene files.

    python benchmarks/pipeline_psnr.py SCENE.toml [SCENE.toml ...] [--size WxH] [--time T]

Renders each scene in both pipelines (the default light path of each) and prints, per scene,
the PSNR of the final 8-bit sRGB images (peak 1) over the whole frame and over the pixels either
pipeline covers (not background), and the mean absolute difference. Materials whose deferred
technique approximates the forward one (fur lit from the light accumulation) show how far.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene
from deferred.scene.size import parse_size


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    mse = float(np.mean((a - b) ** 2))
    return math.inf if mse == 0.0 else 10.0 * math.log10(1.0 / mse)


def compare(path: str, size: tuple[int, int] | None, time: float) -> dict[str, float]:
    images = {}
    for pipeline in ("deferred", "forward"):
        with Renderer(load_scene(path), pipeline, size) as renderer:
            images[pipeline] = renderer.render(time=time).image[..., :3] / 255.0
    a, b = images["deferred"], images["forward"]
    background = np.all(np.abs(a - a[0, 0]) < 1e-6, axis=-1) & \
        np.all(np.abs(b - b[0, 0]) < 1e-6, axis=-1)
    covered = ~background
    return {"psnr": psnr(a, b),
            "psnr_covered": psnr(a[covered], b[covered]) if covered.any() else math.inf,
            "mean_abs": float(np.mean(np.abs(a - b))), "covered": float(covered.mean())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="+")
    parser.add_argument("--size", help="WIDTHxHEIGHT instead of each scene's size")
    parser.add_argument("--time", type=float, default=0.0, help="seconds (animated scenes)")
    args = parser.parse_args()
    size = parse_size(args.size) if args.size else None
    print(f"{'scene':<48} {'PSNR dB':>8} {'covered':>8} {'dB there':>9} {'mean |d|':>9}")
    for path in args.scenes:
        r = compare(path, size, args.time)
        print(f"{path:<48} {r['psnr']:8.2f} {r['covered']:8.2f} {r['psnr_covered']:9.2f} "
              f"{r['mean_abs']:9.4f}")


if __name__ == "__main__":
    main()
