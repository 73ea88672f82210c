"""The area light's and the subsurface material's figures (#36), in docs/figures/:

- area_rect_glossy_floor.png: a rect light over a glossy floor (pbr, roughness 0.05, 0.25 and
  0.5 from left to right), a box casting its soft shadow; forward beside deferred below.
- subsurface_bunny.png: the bunny (examples/meshes/bunny.ply) in the subsurface material
  against the standard one of the same albedo and highlight, lit from the front left (a shadowed
  directional light) and from behind (a shadowed rect light: light through its ears), deferred
  and forward.

Run from the repository root: python examples/area_subsurface_figures.py (matplotlib:
pip install -e '.[plot]')"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from fur_figures import FIGURES, panels  # noqa: E402

from deferred.render.renderer import Renderer  # noqa: E402
from deferred.scene.loader import scene_from_dict  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
BUNNY = str(ROOT / "examples" / "meshes" / "bunny.ply")


def render(scene: dict, pipeline: str = "deferred"):
    with Renderer(scene_from_dict(scene), pipeline) as renderer:
        return renderer.render().image[..., :3]


def glossy_floor(roughness: float) -> dict:
    return {
        "size": [420, 300], "background": [0.01, 0.01, 0.012],
        "camera": {"position": [0.0, 1.3, 3.4], "target": [0.0, 0.25, -0.4], "fov": 45.0},
        "object": [
            {"mesh": "builtin:plane", "scale": 4.0, "material": "pbr",
             "params": {"base_color": [0.12, 0.12, 0.13], "roughness": roughness}},
            {"mesh": "builtin:cube", "scale": 0.25, "position": [0.55, 0.19, -0.1],
             "rotation": [0.0, 30.0, 0.0], "material": "pbr",
             "params": {"base_color": [0.8, 0.25, 0.15], "roughness": 0.5}}],
        "light": [{"type": "rect", "position": [0.0, 0.9, -1.6], "direction": [0.0, -0.35, 1.0],
                   "size": [1.6, 0.4], "intensity": 6.0, "radius": 12.0, "shadows": True},
                  {"type": "ambient", "intensity": 0.03}]}


def bunny(material: str, params: dict) -> dict:
    return {
        "size": [360, 320], "background": [0.02, 0.02, 0.025],
        "camera": {"position": [0.35, 0.75, 1.9], "target": [0.0, 0.42, 0.0], "fov": 38.0},
        "object": [{"mesh": "builtin:plane", "scale": 3.0,
                    "params": {"color": [0.4, 0.4, 0.42], "specular_intensity": 0.1}},
                   {"mesh": BUNNY, "material": material, "params": params}],
        "light": [{"type": "directional", "direction": [0.6, -0.55, -0.45], "intensity": 1.6,
                   "color": [1.0, 0.95, 0.9], "shadows": True, "shadow_resolution": 2048},
                  {"type": "rect", "position": [-0.5, 1.0, -1.3],
                   "direction": [0.35, -0.4, 1.0], "size": [0.8, 0.8], "intensity": 3.0,
                   "radius": 6.0, "shadows": True},
                  {"type": "ambient", "intensity": 0.06}]}


def main() -> None:
    roughness = (0.05, 0.25, 0.5)
    images = [render(glossy_floor(r)) for r in roughness]
    images += [render(glossy_floor(r), "forward") for r in roughness]
    panels(FIGURES / "area_rect_glossy_floor.png", images,
           [f"rect light, pbr floor roughness {r} (deferred)" for r in roughness] +
           [f"roughness {r} (forward)" for r in roughness], columns=3)

    albedo = [0.86, 0.62, 0.5]
    standard = {"color": albedo, "specular_intensity": 0.3, "specular_exponent": 40.0}
    subsurface = {**standard, "radius": 0.03, "falloff": [1.0, 0.45, 0.3]}
    images = [render(bunny("standard", standard)), render(bunny("subsurface", subsurface)),
              render(bunny("subsurface", subsurface), "forward")]
    panels(FIGURES / "subsurface_bunny.png", images,
           ["standard", "subsurface, radius 0.03 (deferred)", "subsurface (forward)"])


if __name__ == "__main__":
    main()
