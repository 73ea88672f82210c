"""The stipple crawl (#25): how much the image changes, other than by the camera's motion,
while the camera pans.

    python benchmarks/crawl.py [--scene FILE] [--frames N] [--size WxH] [--samples-check]
                               [--shift] [--close-up]

A scene (the built-in demo, or ``--scene FILE``: benchmarks/crawl_bunny.toml is the held-out
one) at 320x180 with the camera pulled back (its objects far away) and panned sideways by 0.25
pixel a frame at the objects' distance: frame k + 4 should be frame k moved one pixel left. The
residual is the mean absolute difference, in 8-bit levels, between them on the fur's interior
(its pixels 2 away from its silhouette) and its edges (the band 2 pixels either side), averaged
over pairs of frames, for revie_fur in the deferred and the forward pipeline and for the same
meshes with the standard material (bare), each without and with ``[[effect]] type = "taa"``
(pairs taken once the history has built up).

``--shift`` also prints the residual of a pure one-pixel shift without taa (the projection moved
by exactly one pixel, no parallax: what of the image stays on the screen), on the interior.
``--close-up`` prints, at the scene's own camera and size (``--scene``'s), the energy of the
frame at the 2x2 tile's frequencies ((-1)^x, (-1)^y, (-1)^(x+y), whole frame) and the mean
absolute difference of each fur pixel from the mean of its 4 neighbours (all high
frequencies: the stipple's error as noise counts here too), deferred against forward.

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


SCENE: str | None = None  # --scene; None: the built-in demo


def demo_scene(size: tuple[int, int] | None, material: str, taa: bool, pull_back: bool = True):
    scene = load_scene(SCENE)
    if size is not None:
        scene.size = size
    if material == "bare":
        for obj in scene.objects:
            if obj.material.name == "revie_fur":
                obj.material = StandardMaterial(StandardMaterial.Params(
                    color=tuple(obj.material.params.albedo_tip)))
    if taa:
        scene.effects.append(TAA())
    if pull_back:
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


def shift_residual(pipeline: str, size: tuple[int, int], interior: np.ndarray) -> float:
    """Frame with the projection moved one pixel right against the frame itself, moved."""
    scene = demo_scene(size, "revie_fur", taa=False)
    with Renderer(scene, pipeline) as renderer:
        still = renderer.render().image[..., :3].astype(np.float64)
        moved = renderer.render(jitter=(1.0, 0.0)).image[..., :3].astype(np.float64)
    # the moved frame at x + 1 shows what the still one showed at x (images: top row first)
    difference = np.abs(moved[:, 1:] - still[:, :-1]).mean(axis=-1)
    return float(difference[interior[:, :-1]].mean())


def tile_energy(image: np.ndarray) -> float:
    """Energy of the frame at the 2x2 tile's frequencies: (-1)^x, (-1)^y, (-1)^(x+y)."""
    luminance = image[..., :3].astype(np.float64).mean(axis=-1)
    y, x = np.mgrid[0:luminance.shape[0], 0:luminance.shape[1]]
    return float(sum(np.mean(luminance * wave) ** 2
                     for wave in ((-1.0) ** x, (-1.0) ** y, (-1.0) ** (x + y))))


def high_frequency(image: np.ndarray, region: np.ndarray) -> float:
    """Mean absolute difference of each pixel of ``region`` from the mean of its 4 neighbours."""
    image = image[..., :3].astype(np.float64)
    core = image[1:-1, 1:-1]
    neighbours = (image[:-2, 1:-1] + image[2:, 1:-1] + image[1:-1, :-2] + image[1:-1, 2:]) / 4
    return float(np.abs(core - neighbours).mean(axis=-1)[region[1:-1, 1:-1]].mean())


def close_up() -> None:
    images = {}
    for pipeline in ("deferred", "forward"):
        with Renderer(demo_scene(None, "revie_fur", taa=False, pull_back=False),
                      pipeline) as renderer:
            images[pipeline] = renderer.render().image
    region = np.any(np.abs(images["forward"][..., :3].astype(int) -
                           images["forward"][0, 0, :3].astype(int)) > 8, axis=-1)
    energy = {p: tile_energy(image) for p, image in images.items()}
    high = {p: high_frequency(image, region) for p, image in images.items()}
    print(f"close-up, 2x2 tile energy: deferred {energy['deferred']:.4f}, forward "
          f"{energy['forward']:.4f} ({energy['deferred'] / energy['forward']:.2f}x); "
          f"high frequencies on the fur ({region.sum()} pixels): deferred "
          f"{high['deferred']:.2f}, forward {high['forward']:.2f} "
          f"({high['deferred'] / high['forward']:.2f}x)", flush=True)


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
    parser.add_argument("--scene", default=None, help="a scene file (default: the demo)")
    parser.add_argument("--shift", action="store_true")
    parser.add_argument("--close-up", action="store_true")
    parser.add_argument("--no-crawl", action="store_true", help="skip the panned frames")
    args = parser.parse_args()
    global SCENE
    SCENE = args.scene
    if args.close_up:
        close_up()
    size = tuple(int(v) for v in args.size.split("x"))
    mask = fur_mask(size)
    interior = ~grow(~mask, 2)
    edges = grow(mask, 2) & ~interior
    print(f"fur pixels: {mask.sum()} ({interior.sum()} interior, {edges.sum()} edges)")
    if args.shift:
        for pipeline in ("deferred", "forward"):
            print(f"1-pixel shift, no taa, {pipeline}: "
                  f"{shift_residual(pipeline, size, interior):.3f}", flush=True)
    if args.no_crawl:
        return
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
