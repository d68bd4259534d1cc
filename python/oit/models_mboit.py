"""mboit's float64 models (oit.models.mboit): moment-based OIT (Münstermann et al. 2018) with
power or trigonometric moments at 32 bits, and at 16 bits the pixel's storage as each
fragment's critical section leaves it, in submission order (the order the critical sections run
in on one full-screen stack), reconstructed as at 32 bits (crates/oit-core/src/method/mboit.rs,
shaders/mboit.wgsl, shaders/common/mboit16.wgsl)."""

from __future__ import annotations

import numpy as np
from numpy.polynomial import chebyshev

from ._api import constants
from ._stack import optical_depth, out, visible

_SHARED = constants()  # the core's numbers (crates/oit-core/src/consts.rs), not copies

# mboit's shared numbers (crates/oit-core/src/consts.rs): the smallest 1 - alpha, the bias
# vectors' even moments and the default biases for 4, 6 and 8 power moments.
MBOIT_MIN_WEIGHT = float(np.float32(_SHARED["MBOIT_MIN_WEIGHT"]))
MBOIT_STAR = {m: [float(np.float32(_SHARED[f"MBOIT_STAR{m}_{k}"])) for k in range(2, m + 1, 2)] for m in (4, 6, 8)}
MBOIT_BIAS = {m: float(np.float32(_SHARED[f"MBOIT_BIAS_{m}"])) for m in (4, 6, 8)}
# Trigonometric biases by real moment count (2, 3, 4 complex moments).
MBOIT_TRIG_BIAS = {2 * m: float(np.float32(_SHARED[f"MBOIT_TRIG_BIAS_{m}"])) for m in (2, 3, 4)}
MBOIT_WRAP = float(np.float32(_SHARED["MBOIT_WRAP"]))


def mboit_angle(z) -> np.ndarray:
    """The trigonometric basis' angle of window depth z: [0, 2 pi - MBOIT_WRAP]."""
    half = np.pi - 0.5 * MBOIT_WRAP
    return (2.0 * np.asarray(z, np.float64) - 1.0) * half + half


def mboit_trig_moments(z, alpha, moments=3) -> np.ndarray:
    """(b0, b1, .., b_moments) complex (`moments` complex ones: twice as many reals): the
    optical depths' sum and their sums times exp(i j angle(z))."""
    od = optical_depth(alpha)
    phi = mboit_angle(z)
    return np.array([np.sum(od * np.exp(1j * j * phi)) for j in range(moments + 1)])


def mboit_trig_transmittance(b, z, bias, overestimation=0.25) -> float:
    """The transmittance in front of window depth z that mboit reconstructs from trigonometric
    moments b (mboit_trig_moments), as shaders/mboit.wgsl: the normalized moments biased toward
    0, the Hermitian Toeplitz matrix T, the nodes of the canonical representation through the
    fragment's angle (the kernel polynomial's roots on the unit circle) weighted by their
    Christoffel numbers 1 / (e^H T^-1 e), counted 1 in front, 0 behind, rising from 0 to 1
    across the wrapping zone, the fragment's own by the overestimation."""
    n = len(b) - 1
    m = np.concatenate([[1.0], (1.0 - bias) * np.asarray(b[1:]) / b[0].real])
    toeplitz = np.array([[m[k - j] if k >= j else np.conj(m[j - k]) for j in range(n + 1)] for k in range(n + 1)])

    def e(theta):
        return np.exp(1j * np.arange(n + 1) * theta)

    def christoffel(theta):
        return 1.0 / np.real(np.conj(e(theta)) @ np.linalg.solve(toeplitz, e(theta)))

    phi = float(mboit_angle(z))
    q = np.linalg.solve(toeplitz, e(phi))
    theta = np.mod(np.angle(np.roots(np.conj(q)[::-1])), 2.0 * np.pi)
    zone = 2.0 * np.pi - MBOIT_WRAP
    f = np.where(theta > zone, (theta - zone) / MBOIT_WRAP, (theta < phi).astype(np.float64))
    absorbance = overestimation * christoffel(phi) + sum(fi * christoffel(t) for fi, t in zip(f, theta))
    return float(np.clip(np.exp(-b[0].real * absorbance), MBOIT_MIN_WEIGHT, 1.0))


def mboit_moments(z, alpha, moments=6) -> np.ndarray:
    """(b0, b1, .., b_moments): the sums of the optical depths -ln(1 - alpha) (1 - alpha at least
    MBOIT_MIN_TRANSMITTANCE) and of the optical depths times the warped depth 2 z - 1 to the k
    (the shader's warp under an orthographic camera, the identity included)."""
    od = optical_depth(alpha)
    w = 2.0 * np.asarray(z, np.float64) - 1.0
    return np.array([np.sum(od * w ** k) for k in range(moments + 1)])


def mboit_transmittance(b, z, bias, overestimation=0.25) -> float:
    """The transmittance in front of window depth z that mboit reconstructs from the moments b
    (mboit_moments), as shaders/mboit.wgsl: the normalized moments biased toward the bias vector,
    the Hankel system's kernel polynomial through the warped depth, its roots, and the
    polynomial interpolating the overestimation there, 1 at the roots in front and 0 behind,
    integrated against the biased moments (Münstermann et al. 2018, Algorithm 1); at least
    MBOIT_MIN_WEIGHT."""
    moments = len(b) - 1
    n = moments // 2
    star = np.zeros(moments + 1)
    star[2::2] = MBOIT_STAR[moments]
    m = np.empty(moments + 1)
    m[0] = 1.0
    m[1:] = (1.0 - bias) * (np.asarray(b[1:]) / b[0]) + bias * star[1:]
    x0 = 2.0 * z - 1.0
    hankel = np.array([[m[i + j] for j in range(n + 1)] for i in range(n + 1)])
    c = np.linalg.solve(hankel, x0 ** np.arange(n + 1))
    roots = np.sort(np.roots(c[::-1]).real)[::-1]  # real for a positive definite Hankel matrix
    x = np.concatenate([[x0], roots])
    f = np.concatenate([[overestimation], (roots < x0).astype(np.float64)])
    for j in range(1, n + 1):  # Newton's divided differences
        f[j:] = (f[j:] - f[j - 1:-1]) / (x[j:] - x[:-j])
    p = np.zeros(n + 1)
    p[0] = f[n]
    for j in range(n - 1, -1, -1):  # to monomial coefficients: p = p (t - x_j) + f_j
        p[1:] = p[:-1] - x[j] * p[1:]
        p[0] = f[j] - x[j] * p[0]
    return float(np.clip(np.exp(-b[0] * np.dot(p, m[:n + 1])), MBOIT_MIN_WEIGHT, 1.0))


def mboit(z, rgb, alpha, bg, bg_a=0.0, moments=6, basis="power", precision="32", bias=0.0, overestimation=0.25):
    """Moment-based OIT (Münstermann et al. 2018) at 32 bits (16: mboit16): each fragment's color weighted by
    alpha and its reconstructed transmittance, averaged, times 1 - exp(-b0); the color behind
    times exp(-b0). `moments` counts reals (a complex trigonometric moment is two); `bias` 0 is
    the paper's for the basis and count (MBOIT_BIAS, MBOIT_TRIG_BIAS)."""
    if str(precision) == "16":
        return mboit16(z, rgb, alpha, bg, bg_a, moments, basis, bias, overestimation)
    defaults = {"power": MBOIT_BIAS, "trigonometric": MBOIT_TRIG_BIAS}.get(basis, {})
    if str(precision) != "32" or moments not in defaults:
        raise ValueError(f"mboit model: no model of basis={basis!r}, precision={precision!r}, moments={moments}")
    z, rgb, alpha = visible(z, rgb, alpha)
    beta = bias if bias > 0 else defaults[moments]
    if basis == "power":
        b = mboit_moments(z, alpha, moments)
        w = np.array([a * mboit_transmittance(b, zi, beta, overestimation) for zi, a in zip(z, alpha)])
    else:
        b = mboit_trig_moments(z, alpha, moments // 2)
        w = np.array([a * mboit_trig_transmittance(b, zi, beta, overestimation) for zi, a in zip(z, alpha)])
    t = float(np.exp(-b[0].real))
    if len(w) == 0 or w.sum() <= 0:
        return out(np.zeros(3), t, bg, bg_a)
    return out((rgb * w[:, None]).sum(0) / w.sum() * (1.0 - t), t, bg, bg_a)


# The default biases at 16 bits (crates/oit-core/src/consts.rs MBOIT_BIAS16, MBOIT_TRIG_BIAS16).
MBOIT_BIAS16 = {m: float(np.float32(_SHARED[f"MBOIT_BIAS16_{m}"])) for m in (4, 6, 8)}
MBOIT_TRIG_BIAS16 = {2 * m: float(np.float32(_SHARED[f"MBOIT_TRIG_BIAS16_{m}"])) for m in (2, 3, 4)}


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
        od = float(optical_depth(ai))
        if basis == "power":
            p = np.array([chebyshev.chebval(2.0 * zi - 1.0, np.eye(moments + 1)[k]) for k in range(1, moments + 1)])
        else:
            phi = float(mboit_angle(zi))
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
    z, rgb, alpha = visible(z, rgb, alpha)
    beta = bias if bias > 0 else defaults[moments]
    b0, t = stored16(z, alpha, moments, basis)
    if basis == "power":
        b = b0 * power_moments(t)
        w = np.array([a * mboit_transmittance(b, zi, beta, overestimation) for zi, a in zip(z, alpha)])
    else:
        b = b0 * np.concatenate([[1.0], t[0::2] + 1j * t[1::2]])
        w = np.array([a * mboit_trig_transmittance(b, zi, beta, overestimation) for zi, a in zip(z, alpha)])
    tt = float(np.exp(-b0))
    if len(w) == 0 or w.sum() <= 0:
        return out(np.zeros(3), tt, bg, bg_a)
    return out((rgb * w[:, None]).sum(0) / w.sum() * (1.0 - tt), tt, bg, bg_a)
