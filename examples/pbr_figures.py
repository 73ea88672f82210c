"""The pbr material's figure: docs/figures/pbr_roughness_metallic.png, spheres of roughness 0
to 1 (left to right) and metallic 0, 0.5 and 1 (top to bottom) under two image-based lights:
the built-in sky, and a small studio HDR made here (two soft boxes over a dim warm room),
each shown behind the spheres (background = "environment"), with a fur ball of the shell_fur
material lit by the same environment. Run from the repository root:
python examples/pbr_figures.py (matplotlib: pip install -e '.[plot]')"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from fur_figures import FIGURES, panels  # noqa: E402

from deferred.io.images import write_image  # noqa: E402
from deferred.render.renderer import Renderer  # noqa: E402
from deferred.scene.loader import scene_from_dict  # noqa: E402

SIZE = (960, 520)
ROUGHNESS = (0.0, 0.2, 0.4, 0.6, 0.8, 1.0)
METALLIC = (0.0, 0.5, 1.0)


def studio_hdr(path: Path, width: int = 256) -> Path:
    """An equirectangular studio: a dim warm room, a large soft box above and in front, a
    narrow strip light to the left."""
    height = width // 2
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    vv, uu = np.meshgrid(v, u, indexing="ij")
    room = np.stack([0.06 + 0.04 * vv, 0.05 + 0.02 * vv, 0.04 + 0.01 * vv], -1)
    box = (np.abs(uu - 0.5) < 0.09) & (vv > 0.12) & (vv < 0.3)
    strip = (np.abs(uu - 0.27) < 0.012) & (vv > 0.25) & (vv < 0.6)
    pixels = room + box[..., None] * 12.0 + strip[..., None] * np.array([4.0, 5.0, 7.0])
    write_image(path, pixels.astype(np.float32), channels=("R", "G", "B"))
    return path


def grid_scene(light: dict):
    objects = []
    for row, metallic in enumerate(METALLIC):
        for column, roughness in enumerate(ROUGHNESS):
            objects.append({
                "mesh": "builtin:sphere", "material": "pbr", "scale": 0.42,
                "position": [(column - 2.5) * 1.0, (1 - row) * 1.0 + 0.2, 0.0],
                "params": {"base_color": [0.95, 0.64, 0.54], "metallic": metallic,
                           "roughness": roughness}})
    objects.append({"mesh": "builtin:sphere", "material": "shell_fur", "scale": 0.3,
                    "position": [3.45, 0.2, 0.0]})
    return scene_from_dict({
        "size": list(SIZE), "background": "environment",
        "camera": {"position": [0.45, 0.25, 6.6], "target": [0.45, 0.2, 0.0], "fov": 40.0},
        "object": objects, "light": [light]})


def render(light: dict) -> np.ndarray:
    with Renderer(grid_scene(light), "deferred") as renderer:
        return renderer.render().image[..., :3]


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        studio = studio_hdr(Path(folder) / "studio.hdr")
        images = [render({"type": "environment", "intensity": 1.0}),
                  render({"type": "environment", "map": str(studio), "rotation": 20.0})]
    panels(FIGURES / "pbr_roughness_metallic.png", images,
           ["pbr: roughness 0 to 1 (left to right), metallic 0, 0.5, 1 (top to bottom); "
            "the built-in sky", "the same under a studio HDR made by the script; right: "
            "shell_fur in the same light"], columns=1, scale=1.0)


if __name__ == "__main__":
    main()
