"""The subsurface scattering profile: Burley's normalized diffusion (Christensen and Burley 2015,
"Approximate Reflectance Profiles for Efficient Subsurface Scattering") from a mean free path,
as the separable blur's 1D kernel (Jimenez et al. 2015, "Separable Subsurface Scattering") and
as the transmittance through a thickness (Jimenez et al. 2010, "Real-Time Realistic Skin
Translucency").

Per colour channel, with mean free path l and albedo A, the profile's shape is
d = l / s(A), s(A) = 1.85 - A + 7 |A - 0.8|^3 (their searchlight fit), and

    R(r) = (exp(-r / d) + exp(-r / (3 d))) / (8 pi d r),     integrating to 1 over the plane.

The separable blur convolves with K(x) K(y), K the profile's marginal (a straight edge is
blurred by exactly K across it):

    K(x) = (K0(|x| / d) + K0(|x| / (3 d))) / (4 pi d)         (K0: the modified Bessel function)

sampled at :data:`TAPS` offsets spread quadratically over +-:data:`REACH` d of the widest
channel, each weighing K's integral over the interval nearest to it, normalised to 1 per channel.
Light through a thickness t leaves by the profile integrated over the plane t behind the point:

    T(t) = exp(-t / d) / 4 + 3 exp(-t / (3 d)) / 4.
"""

from __future__ import annotations

import functools

import numpy as np

TAPS = 21  # the blur's taps a direction (odd: one at the centre)
REACH = 10.0  # the kernel's half width, in the widest channel's d (exp(-10/3): 3.6% left out)


def searchlight_scale(albedo) -> np.ndarray:
    """s(A) of Christensen and Burley's searchlight configuration."""
    a = np.asarray(albedo, np.float64)
    return 1.85 - a + 7.0 * np.abs(a - 0.8) ** 3


def profile_shape(mean_free_path, albedo) -> np.ndarray:
    """d per channel from the mean free path (world units) and the albedo."""
    return np.asarray(mean_free_path, np.float64) / searchlight_scale(albedo)


def bessel_k0(z: np.ndarray) -> np.ndarray:
    """K0(z) for z > 0: the integral of exp(-z cosh t) over t >= 0 (midpoint rule)."""
    t = (np.arange(4000) + 0.5) * (14.0 / 4000)
    z = np.asarray(z, np.float64)
    return np.exp(-z[..., None] * np.cosh(t)).sum(-1) * (14.0 / 4000)


def marginal(x: np.ndarray, d: float) -> np.ndarray:
    """K(x): the profile of shape ``d`` integrated along a line (the module documentation)."""
    ax = np.maximum(np.abs(np.asarray(x, np.float64)), 1e-9)
    return (bessel_k0(ax / d) + bessel_k0(ax / (3.0 * d))) / (4.0 * np.pi * d)


def profile(r: np.ndarray, d: float) -> np.ndarray:
    """R(r) (the module documentation)."""
    r = np.maximum(np.asarray(r, np.float64), 1e-9)
    return (np.exp(-r / d) + np.exp(-r / (3.0 * d))) / (8.0 * np.pi * d * r)


def transmittance(thickness, d) -> np.ndarray:
    """T(t) (the module documentation)."""
    t = np.asarray(thickness, np.float64)
    d = np.asarray(d, np.float64)
    return np.exp(-t / d) / 4.0 + 3.0 * np.exp(-t / (3.0 * d)) / 4.0


def tap_offsets(reach: float) -> np.ndarray:
    """The :data:`TAPS` offsets, world units, denser near the centre."""
    u = np.linspace(-1.0, 1.0, TAPS)
    return reach * np.sign(u) * u * u


@functools.lru_cache(maxsize=64)
def kernel(shape: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    """``(offsets (TAPS,), weights (TAPS, 3))`` of the separable blur for per-channel shapes
    ``shape`` (d): each tap weighs K's integral over the offsets nearer to it than to its
    neighbours, within the reach; each channel's weights sum to 1."""
    d = np.asarray(shape, np.float64)
    reach = REACH * float(d.max())
    offsets = tap_offsets(reach)
    edges = np.concatenate([[-reach], (offsets[1:] + offsets[:-1]) / 2.0, [reach]])
    weights = np.zeros((TAPS, 3))
    for k in range(TAPS):
        x = np.linspace(edges[k], edges[k + 1], 65)
        mid = (x[1:] + x[:-1]) / 2.0
        for c in range(3):
            weights[k, c] = marginal(mid, d[c]).sum() * (x[1] - x[0])
    return offsets, weights / weights.sum(0, keepdims=True)
