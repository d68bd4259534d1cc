"""One pixel's fragment stack as the CPU models (oit.models, oit.models_wavelet) take it."""

from __future__ import annotations

import numpy as np


def visible(z, rgb, alpha):
    """The fragments as float64 arrays, alpha-0 ones left out (every method skips them)."""
    z, rgb, alpha = np.asarray(z, np.float64), np.asarray(rgb, np.float64).reshape(-1, 3), np.asarray(alpha, np.float64)
    keep = alpha > 0.0
    return z[keep], rgb[keep], alpha[keep]


def out(rgb, t, bg, bg_a):
    """RGBA of a composite `rgb` over the color behind, `bg` (coverage `bg_a`), seen through `t`."""
    return np.append(rgb + t * np.asarray(bg, np.float64), 1.0 - t * (1.0 - bg_a))
