"""The glass material's figures, in docs/figures/:

- glass_fur.png: a red pane and a clear glass ball in front of a fur ball over a white floor,
  lit by a shadowed spot light (the pane's shadow is red, the ball's pale), composed by
  weighted blended OIT and by the exact mode in the deferred pipeline, and in the forward
  pipeline; then the camera on the other side, the fur in front of the glass.
- glass_panes.png: three coloured panes, the exact mode, weighted blended OIT and their
  difference (x4).

Run from the repository root: python examples/glass_figures.py (matplotlib: pip install -e
'.[plot]')"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from fur_figures import FIGURES, panels  # noqa: E402

from deferred.render.renderer import Renderer  # noqa: E402
from deferred.scene.loader import scene_from_dict  # noqa: E402

SIZE = (480, 320)


def fur_scene(mode: str, behind: bool = False) -> dict:
    camera = [0.4, 1.3, 3.6] if not behind else [-0.6, 1.3, -3.4]
    return {
        "size": list(SIZE), "background": [0.05, 0.06, 0.08],
        "camera": {"position": camera, "target": [0.0, 0.45, 0.0], "fov": 40.0},
        "object": [
            {"mesh": "builtin:plane", "material": "standard", "scale": 4.0,
             "params": {"color": [0.9, 0.9, 0.9], "specular_intensity": 0.1}},
            {"mesh": "builtin:sphere", "material": "revie_fur", "position": [0.0, 0.55, -0.6],
             "scale": 0.45, "params": {"fur_length": 0.18, "shells": 24}},
            {"mesh": "builtin:plane", "material": "glass", "rotation": [90.0, 0.0, 0.0],
             "position": [-0.45, 0.6, 0.6], "scale": 0.45,
             "params": {"color": [1.0, 0.25, 0.2], "opacity": 0.08, "mode": mode}},
            {"mesh": "builtin:sphere", "material": "glass", "position": [0.55, 0.45, 0.55],
             "scale": 0.35,
             "params": {"color": [0.85, 0.95, 1.0], "opacity": 0.03, "mode": mode,
                        "refraction": 0.06}}],
        "light": [
            {"type": "spot", "position": [1.5, 3.0, 2.5], "direction": [-0.4, -0.8, -0.7],
             "outer_angle": 45.0, "inner_angle": 30.0, "intensity": 25.0, "radius": 12.0,
             "shadows": True, "shadow_resolution": 1024},
            {"type": "ambient", "color": [0.25, 0.27, 0.32]}]}


def panes_scene(mode: str) -> dict:
    colours = [(1.0, 0.25, 0.25), (0.25, 1.0, 0.25), (0.3, 0.3, 1.0)]
    return {
        "size": [320, 320], "background": [0.7, 0.7, 0.7],
        "camera": {"position": [0.0, 0.0, 4.0], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"mesh": "builtin:plane", "material": "glass", "rotation": [90.0, 0.0, 0.0],
                    "position": [0.3 * (k - 1), 0.2 * (k - 1), -0.5 * k], "scale": 0.8,
                    "params": {"color": list(colours[k]), "opacity": 0.3, "mode": mode}}
                   for k in (2, 0, 1)],
        "light": [{"type": "directional", "direction": [0.3, -0.5, -1.0], "intensity": 0.6}]}


def render(scene: dict, pipeline: str = "deferred", hdr: bool = False) -> np.ndarray:
    with Renderer(scene_from_dict(scene), pipeline) as renderer:
        result = renderer.render(hdr=hdr)
        return result.hdr[..., :3] if hdr else result.image[..., :3]


def main() -> None:
    images = [render(fur_scene("wboit")), render(fur_scene("exact")),
              render(fur_scene("wboit"), "forward"), render(fur_scene("wboit", behind=True))]
    panels(FIGURES / "glass_fur.png", images,
           ["glass in front of fur: wboit, deferred", "exact (sorted lists), deferred",
            "wboit, forward", "from behind: the fur in front of the glass"], columns=2)
    exact, wboit = render(panes_scene("exact"), hdr=True), render(panes_scene("wboit"), hdr=True)
    difference = np.clip(np.abs(exact - wboit) * 4.0, 0.0, 1.0)
    panels(FIGURES / "glass_panes.png",
           [np.clip(exact, 0, 1) ** (1 / 2.2), np.clip(wboit, 0, 1) ** (1 / 2.2), difference],
           ["three panes, exact", "weighted blended OIT", "|difference| x 4 (linear)"])


if __name__ == "__main__":
    main()
