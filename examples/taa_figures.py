"""Temporal anti-aliasing and accumulated samples (#25) in docs/figures/taa_*: Revie's Figure
2.21 (the demo) and the demo from afar as one frame, with taa (after 16 frames of a still
camera) and with --samples 16, in both pipelines, a close-up of the fur's silhouettes; and a
turntable of the demo's fur without and with taa (taa_turntable.gif, the second of two turns,
so the history has built up). Run from the repository root: python examples/taa_figures.py"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from deferred.debug.preview import labelled
from deferred.effects.taa import TAA
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene

ROOT = Path(__file__).parents[1]
FIGURES = ROOT / "docs" / "figures"
STILL_FRAMES = 16


def far_demo():
    """The demo with the camera three times as far from its target (benchmarks/crawl.py's)."""
    scene = load_scene()
    scene.camera = scene.camera.pulled_back(3.0)
    return scene


def frame(scene_path, pipeline: str, mode: str, size: tuple[int, int]) -> np.ndarray:
    """One frame (mode 'one'), the 16th of a still camera with taa ('taa'), or 16 samples."""
    scene = far_demo() if scene_path == "far demo" else load_scene(scene_path)
    if mode == "taa":
        scene.effects.append(TAA())
    with Renderer(scene, pipeline, size) as renderer:
        if mode == "samples":
            return renderer.render_samples(16).image[..., :3]
        for k in range(STILL_FRAMES if mode == "taa" else 1):
            image = renderer.render(time=0.0 if mode == "one" else k / 24.0).image[..., :3]
        return image


def comparison(scene_path, name: str, size: tuple[int, int], crop: tuple[int, int, int, int],
               zoom: int) -> None:
    """Rows: the pipelines; columns: one frame, taa, --samples 16; each a zoomed crop."""
    rows = []
    for pipeline in ("deferred", "forward"):
        tiles = []
        for mode, title in (("one", "one frame"), ("taa", f"taa, frame {STILL_FRAMES}"),
                            ("samples", "--samples 16")):
            x0, y0, x1, y1 = crop
            part = frame(scene_path, pipeline, mode, size)[y0:y1, x0:x1]
            part = np.repeat(np.repeat(part, zoom, axis=0), zoom, axis=1)
            tiles.append(labelled(part, f"{pipeline}: {title}"))
        rows.append(np.concatenate([np.asarray(t) for t in tiles], axis=1))
    Image.fromarray(np.concatenate(rows, axis=0)).save(FIGURES / f"taa_{name}.png")


def turntable(frames: int = 48, size: tuple[int, int] = (320, 180)) -> None:
    """The demo's fur orbited once, without taa (left) and with it (right)."""
    columns = []
    for taa in (False, True):
        scene = load_scene()
        if taa:
            scene.effects.append(TAA())
        period = frames / 24.0
        scene.set_turntable(period)
        images = []
        with Renderer(scene, "deferred", size) as renderer:
            for k in range(2 * frames):  # the second turn: the history has built up
                image = renderer.render(time=k / 24.0).image[..., :3]
                if k >= frames:
                    images.append(image)
        columns.append(images)
    pictures = [Image.fromarray(labelled(np.concatenate([a, b], axis=1), "one frame | taa"))
                for a, b in zip(*columns, strict=True)]
    pictures[0].save(FIGURES / "taa_turntable.gif", save_all=True,
                     append_images=pictures[1:], duration=1000 // 24, loop=0)


def main() -> None:
    FIGURES.mkdir(parents=True, exist_ok=True)
    # the sphere's upper left silhouette over the floor and the sky, and the torus beside it
    comparison(ROOT / "examples" / "fig2_21_final.toml", "fig2_21", (400, 225),
               (40, 40, 200, 130), 2)
    # the demo from afar (the crawl's view): its objects about 60 pixels across
    comparison("far demo", "demo_far", (320, 180), (120, 62, 205, 112), 4)
    turntable()


if __name__ == "__main__":
    main()
