"""An environment light's maps: made on the GPU from an equirectangular image once, kept on disk.

From the image (an ``.hdr`` or ``.exr`` file through OpenImageIO, or :func:`builtin_sky`):

- the 9 spherical-harmonic coefficients of its irradiance over pi (``sh.comp``);
- a cube of ``resolution`` texels a side holding the image (``to_cube.comp``), and from it a
  mip chain down to 8 texels, level k prefiltered by GGX lobes of perceptual roughness
  k / (levels - 1) (``prefilter.comp``).

They are read back and cached in :func:`cache_path`: ``<cache folder>/environment/`` (the
cache folder is ``$DEFERRED_CACHE_DIR`` or the user's, :func:`deferred.api.cache_folder`), the
file named by the SHA-256 of the image file's bytes (the sky's by its version), the resolution
and the maps' version. The cube reaches the GPU the same way whether it was made or read
(``store.comp``).
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass
from pathlib import Path

import moderngl
import numpy as np

from deferred.api import (
    RenderError,
    cache_folder,
    file_digest,
    read_image,
    write_cached_arrays,
)

MAPS_VERSION = 1  # what the arrays are made by: a change makes new cache files
CACHE_SUBFOLDER = "environment"
SMALLEST_LEVEL = 8  # texels a side of the last prefiltered level (roughness 1)
SH_WIDTH = 256  # the image's mip level the harmonics are summed over is at most this wide
GROUP = 8  # the compute shaders' work group side
# GGX samples a texel of a rough level (filtered importance sampling: few make no noise)
PREFILTER_SAMPLES = 96
SKY_VERSION = 1


@dataclass
class EnvironmentMaps:
    """The GPU side of an environment: the prefiltered cube and the harmonics (9 x 1 texels)."""

    cube: moderngl.TextureCube
    sh: moderngl.Texture
    levels: int

    def release(self) -> None:
        self.cube.release()
        self.sh.release()


def level_sizes(resolution: int) -> list[int]:
    """Texels a side of each prefiltered level, ``resolution`` halved down to SMALLEST_LEVEL."""
    sizes = [resolution]
    while sizes[-1] > SMALLEST_LEVEL:
        sizes.append(sizes[-1] // 2)
    return sizes


def cache_path(digest: str, resolution: int, folder: Path | None = None) -> Path:
    """The file an environment's maps are cached in."""
    folder = cache_folder() if folder is None else folder
    return folder / CACHE_SUBFOLDER / f"{digest[:32]}-{resolution}-v{MAPS_VERSION}.npz"


def image_digest(path: Path | None) -> str:
    """What names an image's maps: its bytes' hash, or the built-in sky's version."""
    return f"sky{SKY_VERSION}" + "0" * 28 if path is None else file_digest(path)


def builtin_sky(width: int = 512) -> np.ndarray:
    """The built-in sky, ``(width / 2, width, 4)`` float32 linear radiance, top row first: a
    blue zenith fading to a pale horizon, a sun (a small disk, 2,000 times the sky's
    brightness, 40 degrees up toward -Z rotated 30 degrees to +X) and a brown ground below."""
    height = width // 2
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    theta = v[:, None] * np.pi
    phi = (u[None, :] - 0.5) * 2.0 * np.pi
    d = np.stack(np.broadcast_arrays(np.sin(theta) * np.sin(phi), np.cos(theta),
                                     -np.sin(theta) * np.cos(phi)), axis=-1)
    elevation = np.clip(d[..., 1], -1.0, 1.0)
    zenith = np.array([0.18, 0.32, 0.75])
    horizon = np.array([0.85, 0.9, 1.0])
    ground = np.array([0.22, 0.18, 0.14])
    up = np.clip(elevation, 0.0, 1.0)[..., None] ** 0.5
    sky = horizon + (zenith - horizon) * up
    below = np.clip(-elevation * 8.0, 0.0, 1.0)[..., None]
    color = sky * (1.0 - below) + ground * below
    sun_elevation, sun_azimuth = np.radians(40.0), np.radians(30.0)
    sun = np.array([np.cos(sun_elevation) * np.sin(sun_azimuth), np.sin(sun_elevation),
                    -np.cos(sun_elevation) * np.cos(sun_azimuth)])
    cos_angle = d @ sun
    disk = np.clip((cos_angle - np.cos(np.radians(2.0))) / (1.0 - np.cos(np.radians(2.0))) * 4.0,
                   0.0, 1.0)
    glow = np.exp((cos_angle - 1.0) * 40.0) * 0.6
    color = color + (disk[..., None] * 2000.0 + glow[..., None]) * np.array([1.0, 0.95, 0.85])
    out = np.ones((height, width, 4), np.float32)
    out[..., :3] = color
    return out


def read_cached(path: Path, resolution: int) -> dict[str, np.ndarray] | None:
    """The maps in ``path``, or None where it is missing, unreadable or not what was asked."""
    sizes = level_sizes(resolution)
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {"sh": np.array(data["sh"]),
                      **{f"level{k}": np.array(data[f"level{k}"]) for k in range(len(sizes))}}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile):
        return None
    if arrays["sh"].shape != (9, 4) or not np.isfinite(arrays["sh"]).all():
        return None
    for k, size in enumerate(sizes):
        if arrays[f"level{k}"].shape != (6, size, size, 4):
            return None
    return arrays


def _groups(size: int, faces: int = 6) -> tuple[int, int, int]:
    return ((size + GROUP - 1) // GROUP, (size + GROUP - 1) // GROUP, faces)


def _equirect_texture(ctx: moderngl.Context, image: np.ndarray) -> moderngl.Texture:
    height, width = image.shape[:2]
    texture = ctx.texture((width, height), 4, np.ascontiguousarray(image[::-1], np.float32),
                          dtype="f4")
    texture.build_mipmaps()
    texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    texture.repeat_x, texture.repeat_y = True, False  # around the horizon, not over the poles
    return texture


def make_arrays(ctx: moderngl.Context, shaders, image: np.ndarray,
                resolution: int) -> dict[str, np.ndarray]:
    """The harmonics and the prefiltered levels of ``image`` (top row first), made on the GPU
    and read back: ``sh`` (9, 4), ``level<k>`` (6, size, size, 4) float16."""
    sizes = level_sizes(resolution)
    equirect = _equirect_texture(ctx, image)
    source = ctx.texture_cube((resolution, resolution), 4, dtype="f2")
    texels = ctx.buffer(reserve=sum(6 * s * s for s in sizes) * 16)
    coefficients = ctx.buffer(reserve=9 * 16)
    try:
        width = image.shape[1]
        equirect.use(0)
        to_cube = shaders.compute("lights/environment/to_cube.comp")
        to_cube["u_equirect"] = 0
        to_cube["u_size"] = resolution
        # the map's level whose texels are about a cube texel's angle (pi/2 / resolution)
        to_cube["u_lod"] = float(max(0.0, np.log2(width / (4.0 * resolution))))
        source.bind_to_image(0, read=False, write=True, level=0)
        to_cube.run(*_groups(resolution))
        ctx.memory_barrier()
        source.build_mipmaps()
        source.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        prefilter = shaders.compute("lights/environment/prefilter.comp")
        source.use(0)
        prefilter["u_source"] = 0
        prefilter["u_source_size"] = float(resolution)
        prefilter["u_samples"] = PREFILTER_SAMPLES
        texels.bind_to_storage_buffer(0)
        first = 0
        for k, size in enumerate(sizes):
            prefilter["u_size"] = size
            prefilter["u_first"] = first
            prefilter["u_roughness"] = k / (len(sizes) - 1)
            prefilter.run(*_groups(size))
            first += 6 * size * size
        equirect.use(0)
        sh = shaders.compute("lights/environment/sh.comp")
        sh["u_equirect"] = 0
        sh["u_lod"] = int(max(0, np.ceil(np.log2(max(width / SH_WIDTH, 1.0)))))
        coefficients.bind_to_storage_buffer(0)
        sh.run(9, 1, 1)
        ctx.memory_barrier()
        flat = np.frombuffer(texels.read(), np.float32).reshape(-1, 4)
        arrays = {"sh": np.frombuffer(coefficients.read(), np.float32).reshape(9, 4).copy()}
        first = 0
        for k, size in enumerate(sizes):
            count = 6 * size * size
            arrays[f"level{k}"] = flat[first:first + count].reshape(6, size, size, 4) \
                .astype(np.float16)
            first += count
    finally:
        for made in (equirect, source, texels, coefficients):
            made.release()
    if not all(np.isfinite(array).all() for array in arrays.values()):
        raise RenderError("the environment's maps came out non-finite (an image with "
                          "values beyond half-float range?)")
    return arrays


def upload(ctx: moderngl.Context, shaders, arrays: dict[str, np.ndarray],
           resolution: int) -> EnvironmentMaps:
    """The arrays of :func:`make_arrays` as textures."""
    sizes = level_sizes(resolution)
    cube = ctx.texture_cube((resolution, resolution), 4, dtype="f2")
    cube.build_mipmaps(0, len(sizes) - 1)  # the levels' storage, written below
    flat = np.concatenate([arrays[f"level{k}"].reshape(-1, 4) for k in range(len(sizes))])
    texels = ctx.buffer(np.ascontiguousarray(flat, np.float32).tobytes())
    try:
        store = shaders.compute("lights/environment/store.comp")
        texels.bind_to_storage_buffer(0)
        first = 0
        for k, size in enumerate(sizes):
            cube.bind_to_image(0, read=False, write=True, level=k)
            store["u_size"] = size
            store["u_first"] = first
            store.run(*_groups(size))
            first += 6 * size * size
        ctx.memory_barrier()
    finally:
        texels.release()
    cube.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    sh = ctx.texture((9, 1), 4, np.ascontiguousarray(arrays["sh"], np.float32).tobytes(),
                     dtype="f4")
    sh.filter = (moderngl.NEAREST, moderngl.NEAREST)
    return EnvironmentMaps(cube, sh, len(sizes))


def environment_maps(ctx: moderngl.Context, shaders, path: Path | None, digest: str,
                     resolution: int, where: str | None = None) -> EnvironmentMaps:
    """The maps of the image at ``path`` (None: the built-in sky) whose bytes hash to
    ``digest``: from the disk cache, else made and cached."""
    cached = cache_path(digest, resolution)
    arrays = read_cached(cached, resolution)
    if arrays is None:
        image = builtin_sky() if path is None else \
            read_image(path, where=where, max_size=ctx.info["GL_MAX_TEXTURE_SIZE"])
        arrays = make_arrays(ctx, shaders, np.asarray(image, np.float32), resolution)
        write_cached_arrays(cached, arrays)
    return upload(ctx, shaders, arrays, resolution)
