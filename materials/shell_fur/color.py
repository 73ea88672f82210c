"""shell_fur's generated colour textures over the UV square (Silva et al. Fig. 3a): stripes and
spots, blended from ``color`` to ``pattern_color``."""

from __future__ import annotations

import moderngl
import numpy as np

from .params import ShellFurParams

COLOR_MAP_SIZE = 256


def color_pattern(name: str, size: int = COLOR_MAP_SIZE, seed: int = 1) -> np.ndarray:
    """(size, size) weight of the pattern colour over the UV square, tileable: ``stripes``
    (wavy bands across u, a tabby's), ``spots`` (round blotches), ``none`` (zeros)."""
    t = (np.arange(size) + 0.5) / size
    v, u = np.meshgrid(t, t, indexing="ij")
    if name == "none":
        return np.zeros((size, size))
    if name == "stripes":
        wave = u * 6.0 + 0.35 * np.sin(2.0 * np.pi * v * 2.0) + 0.1 * np.sin(2.0 * np.pi * v * 7.0)
        s = 0.5 + 0.5 * np.cos(2.0 * np.pi * wave)
        return np.clip((s - 0.55) / 0.15, 0.0, 1.0)
    if name == "spots":
        rng = np.random.default_rng(seed)
        centres = rng.uniform(0.0, 1.0, (40, 2))
        radii = rng.uniform(0.03, 0.06, 40)
        weight = np.zeros((size, size))
        for (cu, cv), r in zip(centres, radii, strict=True):
            du = (u - cu + 0.5) % 1.0 - 0.5  # tileable distance
            dv = (v - cv + 0.5) % 1.0 - 0.5
            weight = np.maximum(weight, np.clip((r - np.sqrt(du * du + dv * dv)) / 0.008,
                                                0.0, 1.0))
        return weight
    raise ValueError(f"unknown colour pattern '{name}'")


def pattern_texture(ctx: moderngl.Context, params: ShellFurParams) -> moderngl.Texture:
    """The generated colour texture: white, blended to pattern_color / color where the pattern
    is (the tint ``color`` multiplies the whole)."""
    weight = color_pattern(params.color_pattern, seed=params.seed)[..., None]
    ratio = np.asarray(params.pattern_color) / np.maximum(np.asarray(params.color), 1e-3)
    rgb = (1.0 - weight) + weight * ratio[None, None, :]
    rgba = np.concatenate([rgb, np.ones(rgb.shape[:2] + (1,))], -1).astype(np.float16)
    texture = ctx.texture((rgb.shape[1], rgb.shape[0]), 4, rgba.tobytes(), dtype="f2")
    texture.build_mipmaps()
    texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    return texture
