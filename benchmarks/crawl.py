"""The stipple crawl (#25): how much the image changes, other than by the camera's motion,
while the camera pans.

    python benchmarks/crawl.py [--frames N] [--size WxH] [--samples-check]

The built-in demo at 320x180 with the camera pulled back (its objects far away) and panned
sideways by 0.25 pixel a frame at the objects' distance: frame k + 4 should be frame k moved
one pixel left. The residual is the mean absolute difference, in 8-bit levels, between them on
the fur's interior (its pixels 2 away from its silhouette) and its edges (the band 2 pixels
either side), averaged over pairs of frames, for revie_fur in the deferred and the forward
pipeline and for the same meshes with the standard material (bare), each without and with
``[[effect]] type = "taa"`` (pairs taken once the history has built up).

``--samples-check`` also prints the PSNR over the fur's pixels (with a 1-pixel border) of
``render --samples 16`` against the 4x4 supersampled frame (box-filtered in linear light) in
each pipeline.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace

import numpy as np

from deferred.effects.taa import TAA
from deferred.io.images import srgb_decode, srgb_encode
from deferred.materials.standard import StandardMaterial
from deferred.render.renderer import Renderer
from deferred.scene.loader import load_scene

PULL_BACK = 3.0  # the camera's distance to its target, times the demo's
SHIFT = 0.25  # pixels a frame at the objects' distance
GAP = 4  # frames between the two of a pair: one pixel


def demo_scene(size: tuple[int, int], material: str, taa: bool):
    scene = load_scene()  # the built-in demo
    scene.size = size
    if material == "bare":
        for obj in scene.objects:
            if obj.material.name == "revie_fur":
                obj.material = StandardMaterial(StandardMaterial.Params(
                    color=tuple(obj.material.params.albedo_tip)))
    if taa:
        scene.effects.append(TAA())
    scene.camera = scene.camera.pulled_back(PULL_BACK)
    return scene


def panned(scene, frame: int, size: tuple[int, int]):
    """The camera moved right by frame x SHIFT pixels at its target's distance."""
    camera = scene.camera
    target, position = np.array(camera.target), np.array(camera.position)
    forward = target - position
    distance = float(np.linalg.norm(forward))
    right = np.cross(forward / distance, np.array(camera.up))
    right /= np.linalg.norm(right)
    pixel = 2.0 * distance * math.tan(math.radians(camera.fov) / 2.0) / size[1]
    offset = right * pixel * SHIFT * frame
    return replace(camera, position=tuple(position + offset), target=tuple(target + offset))


def fur_mask(size: tuple[int, int]) -> np.ndarray:
    """The pixels of the furred objects (their G-buffer surface id), top row first."""
    scene = demo_scene(size, "revie_fur", taa=False)
    fur_ids = {float(obj.material.surface_id()) for obj in scene.objects
               if obj.material.name == "revie_fur"}
    with Renderer(scene, "deferred") as renderer:
        renderer.render(readback=False)
        ids = renderer.targets.read("normal_exponent_id")[::-1, :, 3]
    return np.isin(np.rint(ids), list(fur_ids))


def grow(mask: np.ndarray, steps: int) -> np.ndarray:
    out = mask.copy()
    for _ in range(steps):
        grown = out.copy()
        grown[1:] |= out[:-1]
        grown[:-1] |= out[1:]
        grown[:, 1:] |= out[:, :-1]
        grown[:, :-1] |= out[:, 1:]
        out = grown
    return out


def residuals(pipeline: str, material: str, taa: bool, size: tuple[int, int], frames: int,
              interior: np.ndarray, edges: np.ndarray) -> tuple[float, float]:
    scene = demo_scene(size, material, taa)
    base = scene.camera
    images = []
    with Renderer(scene, pipeline) as renderer:
        for k in range(frames):
            scene.camera = base
            scene.camera = panned(scene, k, size)
            images.append(renderer.render(time=k / 24.0).image[..., :3].astype(np.float64))
    first = frames // 2 if taa else 0  # once the history has built up
    inside, edge = [], []
    for k in range(first, frames - GAP):
        # frame k + GAP at x shows what frame k showed at x + 1
        difference = np.abs(images[k + GAP][:, :-1] - images[k][:, 1:]).mean(axis=-1)
        inside.append(difference[interior[:, :-1]].mean())
        edge.append(difference[edges[:, :-1]].mean())
    return float(np.mean(inside)), float(np.mean(edge))


def samples_psnr(pipeline: str, size: tuple[int, int], region: np.ndarray) -> float:
    scene = demo_scene(size, "revie_fur", taa=False)
    with Renderer(scene, pipeline) as renderer:
        image = renderer.render_samples(16).image[..., :3] / 255.0
    big_size = (size[0] * 4, size[1] * 4)
    big_scene = demo_scene(big_size, "revie_fur", taa=False)
    with Renderer(big_scene, pipeline) as renderer:
        big = srgb_decode(renderer.render().image[..., :3].astype(np.float64) / 255.0)
    reference = srgb_encode(big.reshape(size[1], 4, size[0], 4, 3).mean(axis=(1, 3)))
    error = float(np.mean((image[region] - reference[region]) ** 2))
    return 10.0 * math.log10(1.0 / error)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=int, default=24)
    parser.add_argument("--size", default="320x180")
    parser.add_argument("--samples-check", action="store_true")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    mask = fur_mask(size)
    interior = ~grow(~mask, 2)
    edges = grow(mask, 2) & ~interior
    print(f"fur pixels: {mask.sum()} ({interior.sum()} interior, {edges.sum()} edges)")
    print(f"{'':24} {'interior':>9} {'edges':>9}")
    for taa in (False, True):
        for pipeline, material in (("deferred", "revie_fur"), ("forward", "revie_fur"),
                                   ("deferred", "bare")):
            inside, edge = residuals(pipeline, material, taa, size, args.frames, interior,
                                     edges)
            label = f"{material} {pipeline}{' taa' if taa else ''}"
            print(f"{label:24} {inside:9.2f} {edge:9.2f}", flush=True)
    if args.samples_check:
        region = grow(mask, 1)
        for pipeline in ("deferred", "forward"):
            print(f"--samples 16 vs 4x4 supersampled on the fur, {pipeline}: "
                  f"{samples_psnr(pipeline, size, region):.2f} dB", flush=True)


if __name__ == "__main__":
    main()
