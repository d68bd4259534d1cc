"""One pixel's fragment stack as the CPU models (oit.models, oit.models_mboit, oit.models_wavelet)
take it, and the optical depth mboit and wavelet blend."""

from __future__ import annotations

import numpy as np

from ._api import constants

# The smallest 1 - alpha an optical depth takes (crates/oit-core/src/consts.rs, as
# shaders/common/absorbance.wgsl caps it: alpha 1 would be infinite).
MIN_TRANSMITTANCE = float(np.float32(constants()["MBOIT_MIN_TRANSMITTANCE"]))


def visible(z, rgb, alpha):
    """The fragments as float64 arrays, alpha-0 ones left out (every method skips them)."""
    z, rgb, alpha = np.asarray(z, np.float64), np.asarray(rgb, np.float64).reshape(-1, 3), np.asarray(alpha, np.float64)
    keep = alpha > 0.0
    return z[keep], rgb[keep], alpha[keep]


def out(rgb, t, bg, bg_a):
    """RGBA of a composite `rgb` over the color behind, `bg` (coverage `bg_a`), seen through `t`."""
    return np.append(rgb + t * np.asarray(bg, np.float64), 1.0 - t * (1.0 - bg_a))


def optical_depth(alpha):
    """-ln(1 - alpha) with 1 - alpha at least MIN_TRANSMITTANCE, as shaders/common/absorbance.wgsl."""
    return -np.log(np.maximum(1.0 - np.asarray(alpha, np.float64), MIN_TRANSMITTANCE))
