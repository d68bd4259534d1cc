"""The float64 model of `wavelet` (wavelet transparency, Aizenshtein, Smal, McGuire 2022, with
Haar wavelets), re-exported by oit.models: the same equations as shaders/wavelet.wgsl on one
pixel's stack under an orthographic camera, where the warped depth is the window depth."""

from __future__ import annotations

import numpy as np

from ._api import constants
from ._stack import optical_depth, out, visible

_SHARED = constants()
# mboit's floor, shared: the smallest weight.
MIN_WEIGHT = float(np.float32(_SHARED["MBOIT_MIN_WEIGHT"]))


def wavelet_levels(rank: int) -> tuple[np.ndarray, np.ndarray]:
    """(2^j, k) of Haar functions 0 .. rank - 1 (i = 2^j + k for the wavelets; 2^j = 0 marks
    the scaling function)."""
    i = np.arange(rank)
    level = 2.0 ** np.floor(np.log2(np.maximum(i, 1)))
    return np.where(i == 0, 0.0, level), np.where(i == 0, 0.0, i - level)


def wavelet_coefficients(z, alpha, rank=16) -> np.ndarray:
    """d_i = sum of tau h_i(z) over the fragments: tau = -ln(1 - alpha) (1 - alpha at least
    MBOIT_MIN_TRANSMITTANCE), h_0 = 1, h_i = +1 on the near half of wavelet i's support and -1
    on its far half (unnormalized: the orthonormal psi_i is 2^(j/2) h_i)."""
    tau = optical_depth(alpha)
    scale, shift = wavelet_levels(rank)
    x = np.minimum(np.asarray(z, np.float64), WAVELET_BELOW_ONE)[:, None] * scale - shift
    h = np.where((x >= 0) & (x < 1), np.where(x < 0.5, 1.0, -1.0), 0.0)
    return tau @ h


def wavelet_absorbance(d, u) -> float:
    """A(u) = d_0 u + sum_i 2^j d_i tent_i(u): the projection of the optical depth onto the Haar
    functions, integrated from 0 to u (exact at the boundaries of the finest cells)."""
    scale, shift = wavelet_levels(len(d))
    x = u * scale - shift
    tents = np.where(scale == 0, u, np.maximum(0.5 - np.abs(x - 0.5), 0.0))
    return float(np.dot(d, tents))


def wavelet_cell(rank: int, u: float) -> tuple[float, float]:
    """The finest cell around u of the Haar functions 0 .. rank - 1: half the support of the
    finest wavelet whose support holds u."""
    scale, shift = wavelet_levels(rank)
    x = u * scale - shift
    cells = 2.0 * scale[(x >= 0) & (x < 1) & (scale > 0)].max()
    near = np.floor(u * cells) / cells
    return near, near + 1.0 / cells


# The largest float32 below 1: a fragment on the far plane lies in the last cell.
WAVELET_BELOW_ONE = float(np.float32(1.0) - np.float32(2.0**-24))
RANKS = (4, 8, 12, 16)


def wavelet_transmittance(d, z, alpha) -> float:
    """exp(-A(z) + own), at least MIN_WEIGHT: A less the fragment's own optical depth spread
    over its cell up to z."""
    u = min(float(z), WAVELET_BELOW_ONE)
    near, far = wavelet_cell(len(d), u)
    own = (u - near) / (far - near) * float(optical_depth(alpha))
    return float(np.clip(np.exp(own - wavelet_absorbance(d, u)), MIN_WEIGHT, 1.0))


def wavelet(z, rgb, alpha, bg, bg_a=0.0, rank=16):
    """Wavelet transparency: each fragment's color weighted by alpha T (wavelet_transmittance),
    averaged, times 1 - exp(-d_0); the color behind times exp(-d_0)."""
    if rank not in RANKS:
        raise ValueError(f"wavelet model: no model of rank={rank}; use one of {RANKS}")
    z, rgb, alpha = visible(z, rgb, alpha)
    d = wavelet_coefficients(z, alpha, rank)
    w = np.array([a * wavelet_transmittance(d, zi, a) for zi, a in zip(z, alpha)])
    t = float(np.exp(-d[0]))
    if len(w) == 0 or w.sum() <= 0:
        return out(np.zeros(3), t, bg, bg_a)
    return out((rgb * w[:, None]).sum(0) / w.sum() * (1.0 - t), t, bg, bg_a)
