"""The materials gallery's figures: ``python docs/material_figures.py [NAME ...]`` renders each
built-in material (or those named) on the same small scene, a ball over a floor under a key
light, a fill and an ambient, deferred, and writes ``docs/figures/materials/<name>.png``. The
site's gallery (docs/hooks.py) shows each beside its parameters; a material without a figure
is listed without one."""

from __future__ import annotations

import sys
from pathlib import Path

import deferred
from deferred.interfaces import registry

OUT = Path(__file__).resolve().parent / "figures" / "materials"
SIZE = (320, 200)
# what a material needs beyond its defaults to show what it is on a ball
PARAMS: dict[str, dict] = {
    "standard": {"color": (0.75, 0.3, 0.2), "specular_exponent": 48.0},
    "pbr": {"base_color": (0.9, 0.7, 0.3, 1.0), "metallic": 1.0, "roughness": 0.35},
    "stipple_glass": {"color": (0.4, 0.7, 0.9)},
    "cartoon_hair": {"strands": 300, "length": 0.45, "radius": 0.025, "color": (0.6, 0.32, 0.15),
                     "style": "combed", "settle": 1.0,
                     "skin_color": (0.9, 0.75, 0.6)},
}


def figure(name: str) -> Path:
    """Render material ``name`` on the gallery's scene; the PNG written."""
    camera = deferred.Camera(position=(0.0, 0.95, 2.3), target=(0.0, 0.5, 0.0), fov=40.0)
    scene = deferred.Scene(camera=camera, size=SIZE)
    scene.background = (0.02, 0.022, 0.028)
    scene.add_object("builtin:plane", "standard", label="floor", scale=6.0,
                     params={"color": (0.1, 0.1, 0.11), "specular_intensity": 0.05})
    scene.add_object("builtin:sphere", name, label="ball", position=(0.0, 0.55, 0.0),
                     scale=0.5, params=PARAMS.get(name, {}))
    scene.add_light("directional", direction=(-0.5, -1.0, -0.6), intensity=1.0)
    scene.add_light("point", position=(1.5, 1.2, 1.5), intensity=2.0, radius=6.0,
                    color=(0.9, 0.9, 1.0))
    scene.add_light("ambient", color=(0.12, 0.13, 0.16))
    OUT.mkdir(parents=True, exist_ok=True)
    out = OUT / f"{name}.png"
    with deferred.Renderer(scene) as renderer:
        renderer.render().save(out)
    return out


def main(names: list[str]) -> int:
    for name in names or list(registry.materials):
        try:
            print(f"wrote {figure(name)}")
        except deferred.InputError as error:  # a material that needs more than a ball
            print(f"{name}: no figure ({error})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
