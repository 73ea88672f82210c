"""Costigan's cartoon hair figures in docs/figures/cartoon_hair/: the X-toon shading of Figs.
4.7-4.10 (the 1D ramp, back lighting, the Blinn band, the ramp's specular) and the depth
metric, the outline steps of Fig. 4.11 (edges, then dilated), Fig. 4.12's comparison (a Sobel of
the lit image against the deferred G-buffer's edges, where the thesis re-rendered the scene
solid shaded) and the result of Fig. 4.13, the silhouette strokes of Figs. 4.17 and 4.19 (without
and with the fade toward the roots), the hatching of Fig. 4.20 (screen and surface), and the
tonal art map's tones and tiling of Figs. 4.21-4.22. Run from the repository root:
python examples/cartoon_hair/figures.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from deferred.debug import preview
from deferred.io.images import write_image
from deferred.materials.cartoon_hair.params import CartoonHairParams
from deferred.materials.cartoon_hair.passes import hatching_map
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

ROOT = Path(__file__).parents[2]
FIGURES = ROOT / "docs" / "figures" / "cartoon_hair"
GREYS = [[0.0, "#4a4a4a"], [0.35, "#9a9a9a"], [0.75, "#ffffff"]]
LIGHT = {"type": "directional", "direction": [-0.5, -0.6, -0.6], "intensity": 1.0}
# strokes and ink are dark: they read on light hair (on the dark purple its shadow tone hid them)
FAIR = [0.95, 0.72, 0.38]


def head(params: dict | None = None, effects=None, size=(320, 320), objects=None) -> object:
    hair = {"strands": 150, "style": "spiky", "color": [0.55, 0.35, 0.85], "ramp": GREYS,
            **(params or {})}
    return scene_from_dict({
        "size": list(size), "tonemap": "none", "background": [0.93, 0.93, 0.96],
        "camera": {"position": [0.0, 0.05, 0.55], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": objects or [{"name": "head", "mesh": "builtin:head",
                               "material": "cartoon_hair", "params": hair}],
        "light": [LIGHT], "effect": effects or []}, "cartoon_hair.toml")


def render(scene, pipeline="deferred", targets=()) -> tuple[np.ndarray, dict]:
    with Renderer(scene, pipeline) as renderer:
        image = renderer.render().image[..., :3]
        read = {name: renderer.targets.read(name)[::-1] for name in targets}
    return image, read


def labelled(image: np.ndarray, label: str) -> np.ndarray:
    return preview.labelled(image, label, color=(0, 0, 0), box=None)


def row(*panels: np.ndarray) -> np.ndarray:
    gap = np.full((panels[0].shape[0], 4, 3), 255, np.uint8)
    parts = []
    for panel in panels:
        parts += [panel, gap]
    return np.concatenate(parts[:-1], axis=1)


def grey(mask: np.ndarray) -> np.ndarray:
    """A mask as black lines on white."""
    return np.repeat(np.where(mask, 0, 255).astype(np.uint8)[..., None], 3, axis=2)


def sobel_of_lit_image(image: np.ndarray, threshold: float = 0.25) -> np.ndarray:
    """Fig. 4.12a: the Sobel edge of the lit image's luminance, thresholded (the thesis'
    image-space method applied to the lit frame, without its solid-shaded re-render)."""
    luminance = image.astype(np.float64).mean(axis=-1) / 255.0
    padded = np.pad(luminance, 1, mode="edge")

    def at(dy: int, dx: int) -> np.ndarray:
        return padded[1 + dy:1 + dy + luminance.shape[0], 1 + dx:1 + dx + luminance.shape[1]]

    gx = (at(-1, 1) + 2 * at(0, 1) + at(1, 1)) - (at(-1, -1) + 2 * at(0, -1) + at(1, -1))
    gy = (at(1, -1) + 2 * at(1, 0) + at(1, 1)) - (at(-1, -1) + 2 * at(-1, 0) + at(-1, 1))
    return np.sqrt(gx * gx + gy * gy) > threshold


def shading_figures() -> None:
    """Figs. 4.7-4.10 and the depth metric (4.3.4)."""
    panels = [
        ("4.7 1D ramp", {}),
        ("4.8 back lighting", {"ramp_metric": "backlight", "backlight_power": 3.0,
                               "backlight_color": [0.5, 0.45, 0.35]}),
        ("4.9 Blinn band", {"specular_intensity": 0.6, "specular_exponent": 60.0}),
        ("4.10 ramp specular", {"ramp_metric": "specular", "ramp_shininess": 15.0}),
    ]
    images = [labelled(render(head(params))[0], label) for label, params in panels]
    write_image(FIGURES / "fig4_7_to_4_10_shading.png", row(*images))
    # the depth metric: the same hair near and far, the far one washed out
    objects = [{"name": f"head{k}", "mesh": "builtin:head", "material": "cartoon_hair",
                "position": position,
                "params": {"strands": 120, "style": "spiky", "color": [0.55, 0.35, 0.85],
                           "ramp": GREYS, "ramp_metric": "depth", "depth_range": [0.4, 3.0]}}
               for k, position in enumerate([[-0.1, 0.0, 0.1], [0.5, 0.1, -1.6]])]
    near_far, _ = render(head(objects=objects, size=(480, 320)))
    write_image(FIGURES / "depth_metric.png", labelled(near_far, "4.3.4 depth metric"))


def outline_figures() -> None:
    """Figs. 4.11-4.13: the G-buffer's edges, dilated, against a Sobel of the lit image."""
    scene = head(effects=[{"type": "edges", "width": 3}])
    outlined, targets = render(scene, targets=("edges_raw", "edges"))
    plain, _ = render(head())
    raw, dilated = targets["edges_raw"][..., 0] > 0.5, targets["edges"][..., 0] > 0.5
    write_image(FIGURES / "fig4_11_edges_then_dilated.png",
                row(labelled(grey(raw), "4.11a edges (G-buffer)"),
                    labelled(grey(dilated), "4.11b dilated, width 3")))
    write_image(FIGURES / "fig4_12_lit_sobel_against_gbuffer_edges.png",
                row(labelled(grey(sobel_of_lit_image(plain)), "4.12a Sobel of the lit image"),
                    labelled(grey(raw), "G-buffer edges (no re-render)"),
                    labelled(outlined, "4.13 outlined")))


def silhouette_figures() -> None:
    """Figs. 4.17 and 4.19: object-space silhouette strokes along the tubes, then faded toward
    the roots by the quadratic stroke_fade, so the strands' overlaps near the roots fade."""
    strokes = {"color": FAIR, "silhouettes": True, "stroke_width": 5.0,
               "stroke_color": [0.02, 0.01, 0.04]}
    plain, _ = render(head({**strokes, "stroke_fade": [0.0, 0.0, 1.0]}))
    faded, _ = render(head({**strokes, "stroke_fade": [-1.0, 2.0, 0.0]}))
    write_image(FIGURES / "fig4_17_4_19_silhouettes.png",
                row(labelled(plain, "4.17 silhouette strokes"),
                    labelled(faded, "4.19 faded toward the roots")))


def hatching_figures() -> None:
    """Fig. 4.20: the hair hatched over the screen (a, Lake) and along its tubes (b, Praun) as
    pen strokes hatching_width pixels wide, at 320 px and, cropped, at 1280 px (the same
    strokes' width in pixels, the map read at about a texel a pixel); Figs. 4.21-4.22: the
    tones of a tonal art map, and one tone tiled 2 x 2."""
    panels = []
    for size in (320, 1280):
        for mode, letter in (("screen", "a"), ("surface", "b")):
            image, _ = render(head({"color": FAIR, "hatching": mode}, size=(size, size)))
            if size > 320:  # a 320-pixel crop: the strokes at the same width in pixels
                image = image[100:420, 380:700]
            panels.append(labelled(image, f"4.20{letter} {mode} hatching, {size} px"))
    write_image(FIGURES / "fig4_20_hatching_screen_and_surface.png", row(*panels))
    tam = hatching_map(CartoonHairParams().hatching_width)  # the hair's own map
    ink = tam.levels[0]  # (tones, size, size) uint8 ink
    paper = 255 - ink
    tones = np.concatenate(list(paper), axis=1)
    tiled = np.tile(paper[-1], (2, 2))
    write_image(FIGURES / "fig4_21_tam_tones.png",
                labelled(np.repeat(tones[..., None], 3, axis=2), "tones, light to dark"))
    write_image(FIGURES / "fig4_22_tam_tiled.png",
                labelled(np.repeat(tiled[..., None], 3, axis=2), "darkest tone tiled 2 x 2"))


def main() -> None:
    FIGURES.mkdir(parents=True, exist_ok=True)
    shading_figures()
    outline_figures()
    silhouette_figures()
    hatching_figures()
    print(f"wrote the cartoon hair figures into {FIGURES.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
