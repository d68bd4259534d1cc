"""CPU models (numpy, float64) of the methods, on one pixel's fragment stack.

Each model takes the fragments of a pixel in submission order, `z` (n,) depths in [0, 1),
`rgb` (n, 3) straight colors, `alpha` (n,), and the color behind them `bg` (3,) with its
coverage `bg_a` (1 for an opaque surface, 0 for the background), and returns RGBA as the
renderer does. They mirror the shaders' equations, keys and tie rules (docs/methods.md), so
a GPU image can be checked against them to within float32 and fixed-point rounding. Models
that depend on more than the stack take it by keyword: the frame pixel (screen_door,
stochastic), the frame size and the fragments' triangle indices (stochastic). `auto` is the
one envelope: the exact composite, which auto promises to be within its tolerance of.
"""

from __future__ import annotations

import numpy as np

from ._api import constants
from ._stack import out as _out
from ._stack import visible as _visible
from .models_mboit import mboit, mboit_transmittance, mboit_trig_transmittance  # noqa: F401 (oit.models' API)
from .models_wavelet import wavelet

_SHARED = constants()  # the core's numbers (crates/oit-core/src/consts.rs), not copies
# 24-bit depths of k-TAB keys: z * DEPTH_SCALE in float32, at most DEPTH_MAX.
DEPTH_SCALE = np.float32(_SHARED["DEPTH_SCALE"])
DEPTH_MAX = int(_SHARED["DEPTH_MAX"])
# hybrid's 8-bit alpha (shaders/common/alpha8.wgsl): rounded after a bias of 2^-10 of a step,
# so that alphas on exact half steps (0.1, 0.3, 0.5, ...) always go up; error at most
# ALPHA_8BIT_ERROR.
ALPHA_8BIT_BIAS = np.float32(_SHARED["ALPHA_8BIT_BIAS"])
ALPHA_8BIT_ERROR = float(_SHARED["ALPHA_8BIT_ERROR"])


def alpha_8bit(alpha) -> np.ndarray:
    """The 8-bit key alpha (0..255) of straight alphas, as the shaders compute it in float32."""
    a = np.clip(np.asarray(alpha, np.float32), 0, 1) * np.float32(255.0) + np.float32(0.5) + ALPHA_8BIT_BIAS
    return np.minimum(np.floor(a), 255).astype(np.uint64)


def exact(z, rgb, alpha, bg, bg_a=0.0):
    """Sorted front-to-back compositing (ties by color, as the A-buffer)."""
    z, rgb, alpha = np.asarray(z, np.float64), np.asarray(rgb, np.float64).reshape(-1, 3), np.asarray(alpha, np.float64)
    order = np.lexsort((alpha, rgb[:, 2], rgb[:, 1], rgb[:, 0], z))
    c, t = np.zeros(3), 1.0
    for i in order:
        c += t * alpha[i] * rgb[i]
        t *= 1.0 - alpha[i]
    return _out(c, t, bg, bg_a)


def hybrid_keys(z, alpha):
    """The k-TAB key: 24-bit depth over 8-bit alpha, inverted (larger = nearer)."""
    d = np.minimum((np.asarray(z, np.float32) * DEPTH_SCALE).astype(np.uint64), DEPTH_MAX)
    a = alpha_8bit(alpha)
    return (~((d << np.uint64(8)) | a)) & np.uint64(0xFFFFFFFF)


def hybrid(z, rgb, alpha, bg, bg_a=0.0, k=8, tail=True):
    """Hybrid transparency (Maule et al. 2013, eqs. 2-11) with the renderer's packing and tie
    rule; `tail=False` is the k-TAB baseline."""
    z, rgb, alpha = _visible(z, rgb, alpha)
    keys = hybrid_keys(z, alpha)
    ranked = np.sort(keys)[::-1]
    table = ranked[:k]
    if len(table) < k:
        bound = 0
    else:
        last = int(table[-1])
        evicted = int(ranked[k]) if len(ranked) > k else 0
        bound = last + 1 if evicted != 0 and evicted == last else last
    slots = [int(x) for x in table if int(x) >= bound]
    t_before, t = [], 1.0
    for key in slots:
        t_before.append(t)
        t *= 1.0 - ((~key) & 0xFF) / 255.0
    core, t_core = np.zeros(3), t
    sum_c, sum_a, count = np.zeros(3), 0.0, 0
    for key, c, a in zip(keys, rgb, alpha):
        if bound <= key and int(key) in slots:
            j = slots.index(int(key))
            m = slots.count(int(key))
            share = a if m == 1 else (1.0 - (1.0 - a) ** m) / m
            core += c * t_before[j] * share
        else:
            count += 1
            sum_c += c * a
            sum_a += a
    tail_c, t_tail = np.zeros(3), 1.0
    if tail and count and sum_a > 0:
        a_avg = min(sum_a / count, 1.0)
        t_tail = 0.0 if a_avg >= 1.0 else (1.0 - a_avg) ** count
        tail_c = sum_c / sum_a * (1.0 - t_tail)
    return _out(core + t_core * tail_c, t_core * t_tail, bg, bg_a)


def hybrid64_words(z, rgb, alpha):
    """hybrid64's words before inversion: 24-bit depth, 8-bit alpha, R11G11B10 color."""
    d = np.minimum((np.asarray(z, np.float32) * DEPTH_SCALE).astype(np.uint64), DEPTH_MAX)
    a = alpha_8bit(alpha)
    q = np.round(np.clip(np.asarray(rgb, np.float32), 0, 1) * np.float32([2047.0, 2047.0, 1023.0])).astype(np.uint64)
    color = (q[:, 0] << np.uint64(21)) | (q[:, 1] << np.uint64(10)) | q[:, 2]
    return (((d << np.uint64(8)) | a) << np.uint64(32)) | color


def _unpack64(word):
    word = int(word)
    rgb, a = word & 0xFFFFFFFF, (word >> 32) & 0xFF
    return np.array([(rgb >> 21) / 2047.0, ((rgb >> 10) & 0x7FF) / 2047.0, (rgb & 0x3FF) / 1023.0]), a / 255.0


def hybrid64(z, rgb, alpha, bg, bg_a=0.0, k=8):
    """Single-pass hybrid: the k nearest words (by depth, alpha, color) composited from their
    quantized content, every other word's quantized content to the weighted-average tail."""
    z, rgb, alpha = _visible(z, rgb, alpha)
    words = np.sort(hybrid64_words(z, rgb, alpha))
    core, t = np.zeros(3), 1.0
    for w in words[:k]:
        c, a = _unpack64(w)
        core += t * a * c
        t *= 1.0 - a
    sum_c, sum_a, n = np.zeros(3), 0.0, 0
    for w in words[k:]:
        c, a = _unpack64(w)
        sum_c += c * a
        sum_a += a
        n += 1
    tail_c, t_tail = np.zeros(3), 1.0
    if n and sum_a > 0:
        a_avg = min(sum_a / n, 1.0)
        t_tail = 0.0 if a_avg >= 1.0 else (1.0 - a_avg) ** n
        tail_c = sum_c / sum_a * (1.0 - t_tail)
    return _out(core + t * tail_c, t * t_tail, bg, bg_a)


def ktab(z, rgb, alpha, bg, bg_a=0.0, k=8):
    return hybrid(z, rgb, alpha, bg, bg_a, k=k, tail=False)


def wavg(z, rgb, alpha, bg, bg_a=0.0):
    """Weighted average (Bavoil & Myers 2008; RTR 5.5)."""
    z, rgb, alpha = _visible(z, rgb, alpha)
    n, sa = len(alpha), alpha.sum()
    if n == 0 or sa <= 0:
        return _out(np.zeros(3), 1.0, bg, bg_a)
    c = (rgb * alpha[:, None]).sum(0) / sa
    a_avg = min(sa / n, 1.0)
    u = 0.0 if a_avg >= 1 else (1 - a_avg) ** n
    return _out(c * (1 - u), u, bg, bg_a)


def wsum(z, rgb, alpha, bg, bg_a=0.0):
    """Weighted sum (Meshkin 2007; RTR 5.5), unclamped."""
    z, rgb, alpha = _visible(z, rgb, alpha)
    return _out((rgb * alpha[:, None]).sum(0), 1.0 - alpha.sum(), bg, bg_a)


def wboit_weight(z, view_w, alpha, eq=10):
    d = np.abs(view_w)
    if eq == 7:
        return alpha * np.clip(10 / (1e-5 + (d / 5) ** 2 + (d / 200) ** 6), 1e-2, 3e3)
    if eq == 8:
        return alpha * np.clip(10 / (1e-5 + (d / 10) ** 3 + (d / 200) ** 6), 1e-2, 3e3)
    if eq == 9:
        return alpha * np.clip(0.03 / (1e-5 + (d / 200) ** 4), 1e-2, 3e3)
    return alpha * np.maximum(1e-2, 3e3 * (1 - z) ** 3)


def wboit(z, rgb, alpha, bg, bg_a=0.0, eq=10, view_w=None):
    """Weighted blended OIT (McGuire & Bavoil 2013); view_w defaults to 1 (orthographic)."""
    z, rgb, alpha = _visible(z, rgb, alpha)
    if len(alpha) == 0:
        return _out(np.zeros(3), 1.0, bg, bg_a)
    w = wboit_weight(z, np.ones_like(z) if view_w is None else view_w, alpha, eq)
    acc = (rgb * (alpha * w)[:, None]).sum(0)
    acc_a = (alpha * w).sum()
    reveal = np.prod(1 - alpha)
    c = acc / np.clip(acc_a, 1e-5, 5e4)
    return _out(c * (1 - reveal), reveal, bg, bg_a)


def adaptive_visibility(z, alpha, nodes=8):
    """Salvi et al. 2011: insert in submission order into at most `nodes` steps, removing the
    node whose merge into its predecessor changes the area under the curve least."""
    depth: list[float] = []
    trans: list[float] = []
    for zi, ai in zip(z, alpha):
        p = len(depth)
        while p > 0 and depth[p - 1] > zi:
            p -= 1
        front = trans[p - 1] if p > 0 else 1.0
        trans[p:] = [t * (1 - ai) for t in trans[p:]]
        depth.insert(p, float(zi))
        trans.insert(p, front * (1 - ai))
        if len(depth) > nodes:
            areas = [(depth[i] - depth[i - 1]) * (trans[i - 1] - trans[i]) for i in range(1, len(depth))]
            best = 1 + int(np.argmin(areas))
            trans[best - 1] = trans[best]
            del depth[best], trans[best]
    return depth, trans


def adaptive(z, rgb, alpha, bg, bg_a=0.0, nodes=8):
    z, rgb, alpha = _visible(z, rgb, alpha)
    depth, trans = adaptive_visibility(z, alpha, nodes)

    def vis(zi):
        t = 1.0
        for d, tr in zip(depth, trans):
            if d >= zi:
                break
            t = tr
        return t

    c = sum((rgb[i] * alpha[i] * vis(z[i]) for i in range(len(z))), np.zeros(3))
    return _out(c, trans[-1] if trans else 1.0, bg, bg_a)


def additive(z, rgb, alpha, bg, bg_a=0.0):
    """Additive blending (RTR 5.5): C = sum(alpha c) + background; coverage as over."""
    z, rgb, alpha = _visible(z, rgb, alpha)
    color = (rgb * alpha[:, None]).sum(0) + np.asarray(bg, np.float64)
    return np.append(color, 1.0 - np.prod(1 - alpha) * (1.0 - bg_a))


def filter_(z, rgb, alpha, bg, bg_a=0.0):
    """Colored transmission (RTR 5.5): the color behind times each 1 - alpha (1 - c)."""
    z, rgb, alpha = _visible(z, rgb, alpha)
    t = np.prod(1.0 - alpha[:, None] * (1.0 - rgb), axis=0) if len(alpha) else np.ones(3)
    return np.append(np.asarray(bg, np.float64) * t, 1.0 - np.prod(1 - alpha) * (1.0 - bg_a))


BAYER4 = np.array([[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]])


def screen_door(z, rgb, alpha, bg, bg_a=0.0, pixel=(0, 0)):
    """Screen door: the nearest fragment whose alpha beats the pixel's 4 x 4 Bayer threshold
    (pixel = (row, col)), opaque."""
    z, rgb, alpha = _visible(z, rgb, alpha)
    threshold = (BAYER4[pixel[0] % 4, pixel[1] % 4] + 0.5) / 16.0
    kept = np.flatnonzero(alpha > threshold)
    if len(kept) == 0:
        return np.append(np.asarray(bg, np.float64), bg_a)
    return np.append(rgb[kept[np.argmin(z[kept])]], 1.0)


def mlab(z, rgb, alpha, bg, bg_a=0.0, layers=4):
    """Multi-layer alpha blending (Salvi & Vaidyanathan 2014) in submission order: insert
    into depth-sorted blended layers, merge the two farthest with over on overflow."""
    z, rgb, alpha = _visible(z, rgb, alpha)
    cs, ts, zs = [], [], []
    for zi, ci, ai in zip(z, rgb, alpha):
        p = len(zs)
        while p > 0 and zs[p - 1] > zi:
            p -= 1
        cs.insert(p, ci * ai)
        ts.insert(p, 1.0 - ai)
        zs.insert(p, float(zi))
        if len(zs) > layers:
            k = layers - 1
            cs[k] = cs[k] + ts[k] * cs[layers]
            ts[k] = ts[k] * ts[layers]
            del cs[layers], ts[layers], zs[layers]
    c, t = np.zeros(3), 1.0
    for ci, ti in zip(cs, ts):
        c += t * ci
        t *= ti
    return _out(c, t, bg, bg_a)


def bucket_peeling(z, rgb, alpha, bg, bg_a=0.0, buckets=32):
    """Bucket depth peeling: the pixel's depth range split into equal buckets (float32, as
    the shader), the nearest fragment of each bucket (ties: earlier submission) composited
    front to back, the others dropped. Alpha-0 fragments take part, as on the GPU."""
    z = np.asarray(z, np.float32)
    rgb, alpha = np.asarray(rgb, np.float64).reshape(-1, 3), np.asarray(alpha, np.float64)
    if len(z) == 0:
        return _out(np.zeros(3), 1.0, bg, bg_a)
    lo, hi = z.min(), z.max()
    if hi <= lo:
        index = np.zeros(len(z), np.int64)
    else:
        index = np.minimum(((z - lo) / (hi - lo) * np.float32(buckets)).astype(np.int64), buckets - 1)
    c, t = np.zeros(3), 1.0
    for b in range(buckets):
        members = np.flatnonzero(index == b)
        if len(members):
            i = members[np.lexsort((members, z[members]))[0]]
            c += t * alpha[i] * rgb[i]
            t *= 1.0 - alpha[i]
    return _out(c, t, bg, bg_a)


_M32 = 0xFFFFFFFF


def lowbias32(x) -> np.ndarray:
    """shaders/stochastic.wgsl `hash` (lowbias32, Wellons) on uint32 values."""
    h = np.asarray(x, np.uint64) & _M32
    h ^= h >> np.uint64(16)
    h = (h * np.uint64(0x7FEB352D)) & _M32
    h ^= h >> np.uint64(15)
    h = (h * np.uint64(0x846CA68B)) & _M32
    h ^= h >> np.uint64(16)
    return h


def stochastic_coverage(prims, alpha, frame_px: int, samples: int, seed: int) -> np.ndarray:
    """(n, samples) bool: whether each fragment covers each sample, as `covers` in
    shaders/stochastic.wgsl hashes it: hash(prim ^ hash(px ^ hash(s ^ hash(seed)))), kept where
    its top 24 bits over 2^24 are below the float32 alpha (exact in float64)."""
    s = np.arange(samples, dtype=np.uint64)
    inner = lowbias32(np.uint64(frame_px) ^ lowbias32(s ^ lowbias32(np.uint64(seed & _M32))))
    h = lowbias32(np.asarray(prims, np.uint64)[:, None] ^ inner[None, :])
    a = np.asarray(alpha, np.float32).astype(np.float64)
    return (h >> np.uint64(8)).astype(np.float64) * 2.0 ** -24 < a[:, None]


def stochastic(z, rgb, alpha, bg, bg_a=0.0, samples=8, seed=0, prims=None, pixel=(0, 0), size=(1, 1)):
    """Stochastic transparency (Enderton et al. 2010) with alpha correction, as
    shaders/stochastic.wgsl on the frame pixel `pixel` (row, col) of a `size` (w, h) frame:
    `prims` are the fragments' triangle indices in the drawn transparent geometry (the hash's
    input). Each sample keeps the nearest covering depth (the largest ~bits of the float32
    depth), a fragment's visibility is the share of samples whose nearest is not in front of
    it, and the sums and revealage are float32 in submission order, as the blended targets."""
    if prims is None:
        raise ValueError("stochastic needs each fragment's triangle index (prims)")
    z, rgb = np.asarray(z, np.float32), np.asarray(rgb, np.float32).reshape(-1, 3)
    alpha, prims = np.asarray(alpha, np.float32), np.asarray(prims, np.uint64)
    keep = alpha > 0  # both passes skip alpha-0 fragments
    z, rgb, alpha, prims = z[keep], rgb[keep], alpha[keep], prims[keep]
    key = ~z.view(np.uint32)  # larger = nearer; an empty sample is 0
    cover = stochastic_coverage(prims, alpha, pixel[0] * size[0] + pixel[1], samples, seed)
    nearest = np.where(cover, key[:, None], np.uint32(0)).max(0, initial=np.uint32(0))
    seen = (key[:, None] >= nearest[None, :]).sum(1)
    acc, acc_a, reveal = np.zeros(3, np.float32), np.float32(0), np.float32(1)
    for c, a, v in zip(rgb, alpha, seen):
        w = a * np.float32(v) / np.float32(samples)
        acc, acc_a = acc + c * w, acc_a + w
        reveal = reveal * (np.float32(1) - a)
    bg, t = np.asarray(bg, np.float64), float(reveal)
    color = np.zeros(3) if acc_a <= 0 else acc.astype(np.float64) / float(acc_a) * (1.0 - t)
    return np.append(color + t * bg, 1.0 - t * (1.0 - bg_a))


def auto(z, rgb, alpha, bg, bg_a=0.0, tolerance=1.0 / 255.0):
    """auto as an envelope, not a replica: the exact composite, which auto's RGB stays within
    `tolerance` of (hybrid's rendered bound is at most it) or within the A-buffer's rounding
    where it falls back (the allowed error is numerics.tolerance's). A replica cannot be built
    from one pixel's stack: auto's choice is the frame's (one pixel with no k predicted to meet
    `tolerance` sends every pixel to the A-buffer, and so does a miss after widening), and its
    widening reads the bound hybrid rendered (crates/oit-core/src/method/auto.rs)."""
    return exact(z, rgb, alpha, bg, bg_a)


MODELS = {"abuffer": exact, "hybrid": hybrid, "hybrid64": hybrid64, "ktab": ktab, "wavg": wavg, "wsum": wsum, "wboit": wboit,
          "adaptive": adaptive, "additive": additive, "filter": filter_, "screen_door": screen_door, "mlab": mlab,
          "bucket_peeling": bucket_peeling, "stochastic": stochastic, "mboit": mboit, "auto": auto}
# The list versions run the same update in the same (submission) order.
MODELS.update({"adaptive_lists": adaptive, "mlab_lists": mlab})
MODELS["wavelet"] = wavelet  # its own module: python/oit/models_wavelet.py
