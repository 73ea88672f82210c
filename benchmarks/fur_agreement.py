"""How closely the fur's deferred shells match its forward shells: PSNR, forward against deferred,
of a fur ball (both furs; revie_fur also with its stipple sample) under a side light and a light
from the front left, without and with self-shadowing (deep opacity maps, ``self_shadow_density``),
and back-lit with ``shading = "marschner"`` (the scenes of
tests/deferred/lighting/test_opacity_shadows.py and
tests/materials/shading_models/test_marschner.py). Printed per scene: the PSNR of the luminance (as
the tests measure it) and of the colour, both HDR clipped to [0, 1]. With ``--out DIR`` each scene
is also written as one PNG: forward, deferred (gamma 2.2) and their difference (linear, x 4 about
grey), side by side. Run from the repository root:

    python benchmarks/fur_agreement.py [--scale N] [--out DIR]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from deferred.gl.context import create_context
from deferred.io.images import write_image
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

SIDE = [1.0, -0.1, 0.0]
FRONT_LEFT = [1.0, -0.3, -0.5]
AMBIENT = {"type": "ambient", "color": [0.05, 0.05, 0.05], "ground": [0.05, 0.05, 0.05]}
FUR = {"revie_fur": {"fur_length": 0.35, "shells": 16, "stipple": False, "self_shadow": 64.0,
                     "albedo_base": [0.7, 0.6, 0.5], "albedo_tip": [0.7, 0.6, 0.5]},
       "shell_fur": {"fur_length": 0.35, "shells": 16, "self_shadow": 64.0}}
LUMA = np.array([0.2126, 0.7152, 0.0722])


def lit_ball(material: str, direction: list[float], density: float, scale: int,
             stipple: bool = False) -> dict:
    """tests/deferred/lighting/test_opacity_shadows.py's fur_scene: a fur ball, one shadowed light
    (revie_fur: with its stipple sample or not)."""
    extra = {"stipple": True} if stipple else {}
    return {
        "size": [128 * scale, 96 * scale], "tonemap": "none", "background": [0.0, 0.0, 0.0],
        "camera": {"position": [0.0, 0.0, 2.0], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "shadows": {"atlas_size": 1024},
        "object": [{"mesh": "builtin:sphere", "scale": 0.45, "material": material,
                    "params": {**FUR[material], "self_shadow_density": density, **extra}}],
        "light": [AMBIENT, {"type": "directional", "direction": direction, "intensity": 2.0,
                            "cascades": 1, "shadows": True, "shadow_resolution": 1024,
                            "shadow_distance": 8.0}]}


def back_lit_ball(material: str, scale: int) -> dict:
    """tests/materials/shading_models/test_marschner.py's forward/deferred scene: marschner, a
    light behind the ball, a fill and a key light from the front."""
    colour = {"albedo_tip": [0.8, 0.55, 0.3]} if material == "revie_fur" else \
        {"color": [0.8, 0.55, 0.3], "settle": 0.0}
    return {
        "size": [160 * scale, 120 * scale], "background": [0.0, 0.0, 0.0], "tonemap": "none",
        "camera": {"position": [0.0, 0.0, 4.5], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"name": "fur", "mesh": "builtin:sphere", "material": material,
                    "params": {"shading": "marschner", "fur_length": 0.2, "shells": 16,
                               **colour}}],
        "light": [{"type": "directional", "direction": [0.0, -0.15, 1.0], "intensity": 2.0},
                  {"type": "ambient", "color": [0.05, 0.05, 0.05]},
                  {"type": "directional", "direction": [-0.4, -0.6, -1.0]}]}


def scenes(scale: int) -> list[tuple[str, dict]]:
    out = []
    for material, stipple in (("shell_fur", False), ("revie_fur", False), ("revie_fur", True)):
        name = f"{material}{' stippled' if stipple else ''}"
        for label, direction in (("side light", SIDE), ("front left", FRONT_LEFT)):
            for density in (0.0, 0.5):
                out.append((f"{name}, {label}, self_shadow_density {density}",
                            lit_ball(material, direction, density, scale, stipple)))
    for material in ("shell_fur", "revie_fur"):
        out.append((f"{material}, back-lit, marschner", back_lit_ball(material, scale)))
    return out


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    mse = float(np.mean((np.clip(a, 0, 1) - np.clip(b, 0, 1)) ** 2))
    return math.inf if mse == 0.0 else 10.0 * math.log10(1.0 / mse)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scale", type=int, default=1, help="image size x N (1: the tests')")
    parser.add_argument("--out", type=Path, help="write forward | deferred | diff x 4 PNGs here")
    parser.add_argument("--only", default="", help="scenes whose label contains this")
    args = parser.parse_args(argv)
    gl = create_context()
    print(f"| {'scene':<52} | luminance dB | colour dB |")
    print(f"|{'-' * 54}|-------------:|----------:|")
    for label, data in scenes(args.scale):
        if args.only not in label:
            continue
        hdr = {}
        for pipeline in ("forward", "deferred"):
            with Renderer(scene_from_dict(data), pipeline, gl=gl) as renderer:
                hdr[pipeline] = renderer.render(hdr=True).hdr[..., :3].astype(np.float64)
        f, d = hdr["forward"], hdr["deferred"]
        print(f"| {label:<52} | {psnr(f @ LUMA, d @ LUMA):12.1f} | {psnr(f, d):9.1f} |",
              flush=True)
        if args.out:
            args.out.mkdir(parents=True, exist_ok=True)
            diff = np.clip(0.5 + 4.0 * (d - f), 0.0, 1.0)  # linear, grey = equal
            row = np.concatenate([np.clip(f, 0, 1) ** (1 / 2.2), np.clip(d, 0, 1) ** (1 / 2.2),
                                  diff], axis=1)
            name = label.replace(", ", "_").replace(" ", "_").replace(".", "")
            write_image(args.out / f"{name}.png", (row * 255.0 + 0.5).astype(np.uint8))
    gl.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
