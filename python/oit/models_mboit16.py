"""mboit at 16 bits (precision="16") as a float64 model: the pixel's storage as each fragment's
critical section leaves it, in submission order (the order the critical sections run in on one
full-screen stack), then the 32-bit model's reconstruction from the stored moments
(crates/oit-core/src/method/mboit.rs, shaders/common/mboit16.wgsl)."""

from __future__ import annotations

import numpy as np
from numpy.polynomial import chebyshev

from . import models as _m

# The default biases at 16 bits (crates/oit-core/src/consts.rs MBOIT_BIAS16, MBOIT_TRIG_BIAS16).
MBOIT_BIAS16 = {m: float(np.float32(_m._SHARED[f"MBOIT_BIAS16_{m}"])) for m in (4, 6, 8)}
MBOIT_TRIG_BIAS16 = {2 * m: float(np.float32(_m._SHARED[f"MBOIT_TRIG_BIAS16_{m}"])) for m in (2, 3, 4)}


def quantize16(t: np.ndarray) -> np.ndarray:
    """A value of [-1, 1] stored as unorm16 of (t + 1) / 2 (WGSL's pack2x16unorm) and read back."""
    q = np.floor(0.5 + np.clip(0.5 * np.asarray(t, np.float64) + 0.5, 0.0, 1.0) * 65535.0)
    return q / 65535.0 * 2.0 - 1.0


def stored16(z, alpha, moments: int, basis: str) -> tuple[float, np.ndarray]:
    """b0 (float32) and the `moments` normalized moments in [-1, 1] after each fragment in turn
    renormalized them with its optical depth added and stored them at 16 bits: Chebyshev moments
    T_k(2z - 1) for the power basis, cos and sin of j times the angle for the trigonometric."""
    b0, t = 0.0, np.zeros(moments)
    for zi, ai in zip(z, alpha):
        od = -np.log(max(1.0 - float(ai), _m.MBOIT_MIN_TRANSMITTANCE))
        if basis == "power":
            p = np.array([chebyshev.chebval(2.0 * zi - 1.0, np.eye(moments + 1)[k]) for k in range(1, moments + 1)])
        else:
            phi = float(_m.mboit_angle(zi))
            p = np.ravel([[np.cos(j * phi), np.sin(j * phi)] for j in range(1, moments // 2 + 1)])
        total = float(np.float32(b0 + od))
        t = quantize16((t * b0 + p * od) / total)
        b0 = total
    return b0, t


def power_moments(t: np.ndarray) -> np.ndarray:
    """(1, m_1, .., m_n): the power moments of a unit measure from its Chebyshev moments t_1 .. t_n."""
    cheb = np.concatenate([[1.0], t])
    return np.array([chebyshev.poly2cheb(np.eye(len(cheb))[k])[: k + 1] @ cheb[: k + 1] for k in range(len(cheb))])


def mboit16(z, rgb, alpha, bg, bg_a=0.0, moments=6, basis="power", bias=0.0, overestimation=0.25):
    """mboit with precision="16": the 32-bit reconstruction (models.mboit_transmittance,
    models.mboit_trig_transmittance) from the stored moments; `bias` 0 is MBOIT_BIAS16's or
    MBOIT_TRIG_BIAS16's for the basis and count."""
    defaults = {"power": MBOIT_BIAS16, "trigonometric": MBOIT_TRIG_BIAS16}.get(basis, {})
    if moments not in defaults:
        raise ValueError(f"mboit model: no model of basis={basis!r}, moments={moments} at 16 bits")
    z, rgb, alpha = _m._visible(z, rgb, alpha)
    beta = bias if bias > 0 else defaults[moments]
    b0, t = stored16(z, alpha, moments, basis)
    if basis == "power":
        b = b0 * power_moments(t)
        w = np.array([a * _m.mboit_transmittance(b, zi, beta, overestimation) for zi, a in zip(z, alpha)])
    else:
        b = b0 * np.concatenate([[1.0], t[0::2] + 1j * t[1::2]])
        w = np.array([a * _m.mboit_trig_transmittance(b, zi, beta, overestimation) for zi, a in zip(z, alpha)])
    tt = float(np.exp(-b0))
    if len(w) == 0 or w.sum() <= 0:
        return _m._out(np.zeros(3), tt, bg, bg_a)
    return _m._out((rgb * w[:, None]).sum(0) / w.sum() * (1.0 - tt), tt, bg, bg_a)
