"""Fur self-shadowing (#27) in docs/figures/fur_self_shadowing.png: the demo with shadows
(examples/shadows_demo.toml) in the forward pipeline without self-shadowing (gamma(h) only,
self_shadow_density = 0) and with it (the deep opacity maps, the default), and the same two in
the deferred pipeline (whose shells correct the light they read from the skin and stipple
samples by each shadowed light's transmittance); the whole frame and a close-up of the ball's
side away from the key light. Run from the repository root:
python examples/self_shadow_figures.py"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from deferred.bench.scenes import set_self_shadow_density
from deferred.debug.preview import labelled
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene
from deferred.scene.scene import Scene

ROOT = Path(__file__).parents[1]
FIGURES = ROOT / "docs" / "figures"
DEMO = ROOT / "examples" / "shadows_demo.toml"
SIZE = (1280, 720)
CROP = (170, 200, 550, 520)  # the ball, x0, y0, x1, y1 at SIZE


def demo(density: float | None) -> Scene:
    """The demo with shadows, its fur's self_shadow_density set (None: the default)."""
    scene = load_scene(DEMO)
    return scene if density is None else set_self_shadow_density(scene, density)


def main() -> None:
    columns = []
    for pipeline, density, title in (("forward", 0.0, "forward, without self-shadowing"),
                                     ("forward", None, "forward, deep opacity maps"),
                                     ("deferred", 0.0, "deferred, without self-shadowing"),
                                     ("deferred", None, "deferred, deep opacity maps")):
        with Renderer(demo(density), pipeline, SIZE) as renderer:
            image = renderer.render().image[..., :3]
        x0, y0, x1, y1 = CROP
        close = np.ascontiguousarray(image[y0:y1, x0:x1])
        whole = np.asarray(Image.fromarray(image).resize((close.shape[1],
                                                          close.shape[1] * SIZE[1] // SIZE[0])))
        columns.append(np.concatenate([labelled(whole, title), close], axis=0))
    Image.fromarray(np.concatenate(columns, axis=1)).save(FIGURES / "fur_self_shadowing.png")


if __name__ == "__main__":
    main()
