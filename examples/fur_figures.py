"""The fur technique's figures in docs/figures/fur_*.png: Revie's Figures 2.20 and 2.21 before and
after the fur technique, fins off and on at a silhouette, three distances with their shell counts,
and the fur debug views. Run from the repository root: python examples/fur_figures.py (matplotlib:
pip install -e '.[plot]')"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from deferred.debug.views import with_material_view  # noqa: E402
from deferred.io.images import read_image  # noqa: E402
from deferred.render.renderer import Renderer  # noqa: E402
from deferred.scene.loader import load_scene, scene_from_dict  # noqa: E402

ROOT = Path(__file__).parents[1]
FIGURES = ROOT / "docs" / "figures"
LIGHTS = [{"type": "ambient", "color": [0.18, 0.2, 0.26]},
          {"type": "directional", "direction": [-0.5, -0.7, -0.6], "intensity": 1.2},
          {"type": "point", "position": [0.6, 1.0, -2.0], "color": [1.0, 0.8, 0.6],
           "intensity": 5.0, "radius": 6.0}]


def ball(distance: float, size=(400, 300), **params):
    return scene_from_dict({
        "size": list(size), "background": [0.015, 0.017, 0.022],
        "camera": {"position": [0.0, 0.0, distance], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"name": "fur", "mesh": "builtin:sphere", "material": "revie_fur",
                    "params": {"shells": 24, "fur_length": 0.15, **params}}],
        "light": LIGHTS})


def render(scene, pipeline="deferred"):
    with Renderer(scene, pipeline) as renderer:
        result = renderer.render()
        return result.image[..., :3], result.draws_by_pass


def panels(path: Path, images, titles, columns=None, scale=1.0):
    columns = columns or len(images)
    rows = (len(images) + columns - 1) // columns
    height, width = images[0].shape[:2]
    figure, axes = plt.subplots(rows, columns, figsize=(columns * width / 100 * scale,
                                                        rows * (height / 100 + 0.3) * scale),
                                squeeze=False)
    for axis in axes.ravel():
        axis.axis("off")
    for axis, image, title in zip(axes.ravel(), images, titles, strict=False):
        axis.imshow(image, interpolation="nearest")
        axis.set_title(title, fontsize=9)
    figure.tight_layout()
    figure.savefig(path, dpi=100, facecolor="white")
    plt.close(figure)
    print(f"wrote {path}")


def main() -> None:
    for name, title in (("fig2_20_shells", "Figure 2.20"), ("fig2_21_final", "Figure 2.21")):
        before = read_image(FIGURES / "before" / f"{name}.png")[..., :3]
        after, _ = render(load_scene(ROOT / "examples" / f"{name}.toml"))
        panels(FIGURES / f"fur_{name}_before_after.png", [before, after],
               [f"{title}, before: heightfield without mipmaps", f"{title}, the fur technique"])

    crops, titles = [], []
    for fins in (False, True):
        for pipeline in ("deferred", "forward"):
            image, _ = render(ball(3.0, fins=fins), pipeline)
            crops.append(np.kron(image[10:110, 40:170], np.ones((3, 3, 1), np.uint8)))
            titles.append(f"{'fins' if fins else 'no fins'}, {pipeline}")
    panels(FIGURES / "fur_fins.png", crops, titles, columns=2, scale=0.7)

    images, titles = [], []
    for distance in (1.8, 5.0, 14.0):
        image, draws = render(ball(distance))
        images.append(image)
        titles.append(f"distance {distance}: {draws['fur.shells']} shells")
    panels(FIGURES / "fur_lod.png", images, titles)

    images, titles = [], []
    demo = load_scene(None)
    for view in ("samples", "comb", "shell_count", "single_shell"):
        image, _ = render(with_material_view(demo, f"revie_fur.{view}"))
        images.append(image[::2, ::2])
        titles.append(f"--view revie_fur.{view}")
    panels(FIGURES / "fur_debug_views.png", images, titles, columns=2)


if __name__ == "__main__":
    main()
