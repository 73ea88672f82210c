"""The comb field's figure, docs/figures/fur_demo_comb_before_after.png: the built-in demo before
the comb field (docs/figures/before/demo*.png, rendered from the code before it) and now, in
both pipelines, with close-ups of the ball's top pole (the old blue spot) and the torus (the old
parting ring). Run from the repository root: python examples/comb_figures.py (matplotlib:
pip install -e '.[plot]')"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from fur_figures import FIGURES, panels  # noqa: E402

from deferred.io.images import read_image  # noqa: E402
from deferred.render.renderer import Renderer  # noqa: E402
from deferred.scene.loader import load_scene  # noqa: E402

DEMO = Path(__file__).parents[1] / "deferred" / "scenes" / "demo.toml"
POLE = (slice(150, 250), slice(330, 490))  # rows, columns of the 1280x720 demo
TORUS = (slice(90, 250), slice(640, 896))


def demo(pipeline: str) -> np.ndarray:
    with Renderer(load_scene(DEMO), pipeline) as renderer:
        return renderer.render().image[..., :3]


def zoom(image: np.ndarray, crop: tuple[slice, slice], factor: int) -> np.ndarray:
    return np.repeat(np.repeat(image[crop], factor, axis=0), factor, axis=1)


def main() -> None:
    images, titles = [], []
    for pipeline, suffix in (("deferred", ""), ("forward", "_forward")):
        before = (read_image(FIGURES / "before" / f"demo{suffix}.png")[..., :3] * 255.0
                  ).round().astype(np.uint8)
        after = demo(pipeline)
        for label, image in (("before", before), ("comb field", after)):
            images += [zoom(image, POLE, 3), zoom(image, TORUS, 2)[:300, :480]]
            titles += [f"{pipeline}, {label}: ball's top pole (x3)",
                       f"{pipeline}, {label}: torus (x2)"]
    panels(FIGURES / "fur_demo_comb_before_after.png", images, titles, columns=4, scale=0.8)


if __name__ == "__main__":
    main()
