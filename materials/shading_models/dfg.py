"""The ``pbr`` shading model's DFG table (Karis's split-sum second factor, in Filament's
multiple-scattering layout): over N.V and perceptual roughness, the directional albedo of the
GGX / Smith height-correlated specular lobe split by Schlick's Fresnel, E(f0) = f0 (A + B) +
(1 - f0) B with f90 = 1. Channel x is B (the Fresnel-weighted part), y is A + B (the lobe's
albedo for f0 = 1, whose shortfall from 1 the energy compensation 1 + f0 (1 / y - 1) returns).

Made once in numpy by importance-sampling the GGX half vectors (Hammersley points): texel
(i, j) at N.V = (i + 0.5) / size, roughness (j + 0.5) / size, so a linear lookup at (N.V,
roughness) needs no remapping.
"""

from __future__ import annotations

import functools

import numpy as np

DFG_SIZE = 32
DFG_SAMPLES = 1024


def hammersley(count: int) -> np.ndarray:
    """``(count, 2)``: i / count and the base-2 radical inverse of i."""
    i = np.arange(count, dtype=np.uint32)
    bits = i.copy()
    bits = ((bits << 16) | (bits >> 16)) & 0xFFFFFFFF
    bits = ((bits & 0x55555555) << 1) | ((bits & 0xAAAAAAAA) >> 1)
    bits = ((bits & 0x33333333) << 2) | ((bits & 0xCCCCCCCC) >> 2)
    bits = ((bits & 0x0F0F0F0F) << 4) | ((bits & 0xF0F0F0F0) >> 4)
    bits = ((bits & 0x00FF00FF) << 8) | ((bits & 0xFF00FF00) >> 8)
    return np.stack([i / count, (bits & 0xFFFFFFFF) * 2.0 ** -32], axis=1)


@functools.lru_cache(maxsize=2)
def dfg_table(size: int = DFG_SIZE, samples: int = DFG_SAMPLES) -> np.ndarray:
    """``(size, size, 2)`` float32, rows by roughness, columns by N.V (module documentation)."""
    centres = (np.arange(size) + 0.5) / size
    n_dot_v = centres[None, :, None]
    alpha = (centres ** 2)[:, None, None]
    xi = hammersley(samples)
    u1, u2 = xi[None, None, :, 0], xi[None, None, :, 1]
    a2 = alpha * alpha
    cos_theta = np.sqrt((1.0 - u1) / (1.0 + (a2 - 1.0) * u1))
    sin_theta = np.sqrt(1.0 - cos_theta ** 2)
    phi = 2.0 * np.pi * u2
    h = np.stack(np.broadcast_arrays(sin_theta * np.cos(phi), sin_theta * np.sin(phi),
                                     cos_theta), axis=-1)  # about N = +z
    v = np.stack(np.broadcast_arrays(np.sqrt(1.0 - n_dot_v ** 2), 0.0 * n_dot_v, n_dot_v),
                 axis=-1)
    v_dot_h = np.sum(v * h, axis=-1)
    n_dot_l = 2.0 * v_dot_h * h[..., 2] - v[..., 2]
    n_dot_h = h[..., 2]
    lit = (n_dot_l > 0.0) & (v_dot_h > 0.0)
    n_dot_l = np.clip(n_dot_l, 1e-8, 1.0)
    view = n_dot_l * np.sqrt(n_dot_v ** 2 * (1.0 - a2) + a2)
    light = n_dot_v * np.sqrt(n_dot_l ** 2 * (1.0 - a2) + a2)
    visibility = 0.5 / (view + light)
    # f cos / pdf, the pdf of l being D (N.H) / (4 V.H): the D cancels
    weight = np.where(lit, visibility * 4.0 * n_dot_l * v_dot_h / n_dot_h, 0.0)
    fresnel = (1.0 - np.clip(v_dot_h, 0.0, 1.0)) ** 5
    table = np.stack([np.mean(weight * fresnel, axis=-1), np.mean(weight, axis=-1)], axis=-1)
    return table.astype(np.float32)
