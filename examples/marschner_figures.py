"""The marschner shading model's figures: docs/figures/fur_demo_marschner.png (the built-in demo
with both furs' `shading = "marschner"`, deferred and forward, beside the classic shading) and
docs/figures/fig2_21_final_marschner.png (Revie's Figure 2.21 scene with it). Run from the
repository root: python examples/marschner_figures.py (matplotlib: pip install -e '.[plot]')"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

sys.path.insert(0, str(Path(__file__).parent))
from fur_figures import FIGURES, panels  # noqa: E402

from deferred.render.renderer import Renderer  # noqa: E402
from deferred.scene.loader import scene_from_dict  # noqa: E402

ROOT = Path(__file__).parents[1]
DEMO = ROOT / "deferred" / "scenes" / "demo.toml"
FIG2_21 = ROOT / "examples" / "fig2_21_final.toml"
SIZE = (640, 360)


def scene(path: Path, shading: str | None):
    document = tomllib.loads(path.read_text())
    document["size"] = list(SIZE)
    for obj in document.get("object", []):
        if shading and obj.get("material") == "revie_fur":
            obj.setdefault("params", {})["shading"] = shading
    return scene_from_dict(document, str(path), base_dir=path.parent)


def render(path: Path, shading: str | None, pipeline: str) -> np.ndarray:
    with Renderer(scene(path, shading), pipeline) as renderer:
        return renderer.render().image[..., :3]


def main() -> None:
    for path, name in ((DEMO, "fur_demo_marschner.png"), (FIG2_21, "fig2_21_final_marschner.png")):
        images, titles = [], []
        for shading in ("classic", "marschner"):
            for pipeline in ("deferred", "forward"):
                images.append(render(path, shading, pipeline))
                titles.append(f"{shading}, {pipeline}")
        panels(FIGURES / name, images, titles, columns=2, scale=1.0)


if __name__ == "__main__":
    main()
