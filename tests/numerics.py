"""Helpers of the numerics tests (test_numerics_*.py): per-pixel fragment stacks with known
depths, what each method should return on them (oit.models, or a local model of the plain
blends), and the float32 error bounds the tests allow, each derived in a comment.

Which method promises what is read from `oit.methods()` where it is declared there
(`exact`, `bounded_memory`, parameters, passes); what only docs/methods.md states (hybrid,
hybrid64 and ktab are bit-for-bit order independent, the blended sums are commutative) is
listed here by name.
"""

from __future__ import annotations

import inspect
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Callable

import numpy as np

import oit
from oit import models

BG = np.array([0.2, 0.4, 0.6])
INFO: dict[str, dict] = {m["name"]: m for m in oit.methods()}
NAMES: list[str] = list(INFO)
EXACT = [n for n in NAMES if INFO[n]["exact"]]
BOUNDED = [n for n in NAMES if INFO[n]["bounded_memory"]]
# Methods with a `seed` parameter are randomized per fragment (by triangle index): adding
# triangles, even invisible ones, changes their noise.
RANDOMIZED = [n for n in NAMES if any(p["name"] == "seed" for p in INFO[n]["params"])]
# Methods that draw the scene once per layer (their passes are declared "per layer ..."):
# n layers at a pixel cost n geometry passes, ~10 s for 4,000 layers on lavapipe.
PER_LAYER = [n for n in NAMES if any(p.startswith("per ") for p in INFO[n]["passes"])]
# docs/methods.md, "depth_peeling and dual_depth_peeling": the exact peeling methods order
# fragments at equal depth by submission (their (depth, triangle) keys), not by color as the
# A-buffer and the reference do: exact, but order-dependent where depths tie exactly.
ORDER_TIES = [n for n in NAMES if INFO[n]["order"] == "bitwise_except_ties"]
SUBMISSION_TIES = [n for n in EXACT if n in ORDER_TIES]

# The registry's `order` (docs/methods.md, "Guarantees"): the exact methods and those
# bit-identical under any submission order ("bitwise").
BIT_ORDER_INDEPENDENT = sorted(n for n in NAMES if (INFO[n]["exact"] and INFO[n]["order_independent"])
                               or INFO[n]["order"] == "bitwise")
# Commutative float accumulation (additive or multiplicative blending): a reordered
# submission changes only the last bits.
SUM_ORDER_INDEPENDENT = sorted(n for n in NAMES if INFO[n]["order"] == "rounding")

U = 2.0 ** -24  # float32 unit roundoff
# WGSL: log2 has an absolute error below 2^-21 on [0.5, 2], and pow(x, y) is exp2(y log2 x),
# so pow(1 - a, n) carries a relative error up to n 2^-21 (ln 2 < 1).
POW_LOG2 = 2.0 ** -21


def params_for(name: str, **overrides) -> dict:
    """The method's parameters at their defaults, with `overrides` for those it has."""
    own = {p["name"]: p["default"] for p in INFO[name]["params"]}
    own.update({k: v for k, v in overrides.items() if k in own})
    return own


def over_blend(rgb: np.ndarray, alpha: np.ndarray, bg: Sequence[float], bg_a: float = 0.0) -> np.ndarray:
    """Fixed-function over-blending in the given order (first = farthest), float64."""
    c, a = np.asarray(bg, np.float64).copy(), float(bg_a)
    for ci, ai in zip(np.asarray(rgb, np.float64), np.asarray(alpha, np.float64)):
        c = ai * ci + (1.0 - ai) * c
        a = ai + (1.0 - ai) * a
    return np.append(c, a)


# The plain blends, modelled here (over_blend) rather than in oit.models.
LOCAL_MODELS = ("unsorted", "sorted")


def has_model(name: str) -> bool:
    """Whether expected() has a CPU model of `name`: every registered method must."""
    return INFO[name]["exact"] or name in LOCAL_MODELS or name in models.MODELS


def expected(name: str, z, rgb, alpha, bg=BG, bg_a: float = 0.0, mesh_per_fragment: bool = False,
             pixel=(0, 0), size=(1, 1), prims=None, **params) -> np.ndarray:
    """RGBA that `name` should return on one pixel's stack given in submission order.
    `mesh_per_fragment`: each fragment is its own mesh (what `sorted` sorts); otherwise all of
    them are one mesh, drawn in submission order. `pixel` (row, col) of a `size` (w, h) frame and
    `prims` (each fragment's triangle index) go to models that depend on them (screen_door's
    dither, stochastic's noise). A method with no model raises LookupError, never a skip."""
    if not has_model(name):
        raise LookupError(f"no CPU model of {name!r}: add one to oit.models.MODELS")
    z, rgb, alpha = np.asarray(z, np.float64), np.asarray(rgb, np.float64).reshape(-1, 3), np.asarray(alpha, np.float64)
    if INFO[name]["exact"]:
        return models.exact(z, rgb, alpha, bg, bg_a)
    if name == "unsorted" or (name == "sorted" and not mesh_per_fragment):
        return over_blend(rgb, alpha, bg, bg_a)
    if name == "sorted":
        back_to_front = np.argsort(-z, kind="stable")
        return over_blend(rgb[back_to_front], alpha[back_to_front], bg, bg_a)
    p = dict(params)
    if name == "wboit":
        p = {"eq": int(str(p.get("weight", "eq10"))[2:])}
    model = models.MODELS[name]
    wants = inspect.signature(model).parameters
    p.update({k: v for k, v in (("pixel", tuple(pixel)), ("size", tuple(size)), ("prims", prims)) if k in wants})
    return model(z, rgb, alpha, bg, bg_a, **p)


def full_screen_prims(n: int, pixel, size) -> np.ndarray:
    """Triangle index of each of n full_screen_layers quads at `pixel` (row, col) of a `size`
    (w, h) frame: quad i is triangles 2i (lower right on screen) and 2i + 1 (upper left), split
    by the diagonal x/w + y/h = 1 through pixel centers (x, y) = (col, row) + 1/2. A center on the
    diagonal is the lower right's: the top-left rule, that triangle's upper-left edge (checked
    against the GPU by stochastic's noise, which hashes the triangle index)."""
    (row, col), (w, h) = pixel, size
    lower_right = (2 * col + 1) * h + (2 * row + 1) * w >= 2 * w * h
    return 2 * np.arange(n) + (0 if lower_right else 1)


def expected_image(name: str, width: int, height: int, z, rgb, alpha, bg=BG, **kw) -> np.ndarray:
    """(h, w, 4) expected image of one stack drawn on every pixel (full_screen_layers)."""
    out = [expected(name, z, rgb, alpha, bg, pixel=(r, c), size=(width, height),
                    prims=full_screen_prims(len(z), (r, c), (width, height)), **kw)
           for r in range(height) for c in range(width)]
    return np.array(out).reshape(height, width, 4)


# Methods whose output sums sum(alpha c) unnormalized: values (and float32 rounding) grow
# with the alphas' sum.
UNNORMALIZED_SUMS = {"wsum", "additive"}


def tolerance(name: str, n: int, mass: float = 1.0, **params) -> float:
    """Largest allowed |GPU - expected(...)| on a pixel of n fragments whose alphas sum to
    `mass` (`params`: the method's, where a term depends on them). The base is the A-buffer's
    bound in docs/methods.md: one float32 rounding per layer (n 2^-24, plus one for the float32
    background); a float32 sum of n + 1 terms is off by at most (n + 1) 2^-24 times their
    magnitude, which unnormalized sums (background included) bound by 1 + mass. Method terms:"""
    if name == "stochastic":
        # The model draws the same samples (bit for bit) and keeps the targets' float32 sums
        # and revealage, with the same operations in the same (submission) order as blending,
        # whatever n: only the float32 resolve differs, by its quotient (WGSL allows 2.5 ulp:
        # 5 2^-24 of a value <= 1), 1 - R, the products by it and by R, and their sum (one
        # rounding each). Measured on llvmpipe: at most 1.6 2^-24.
        return 9 * U
    tol = (n + 1) * U * ((1.0 + mass) if name in UNNORMALIZED_SUMS else 1.0)
    if name in ("hybrid", "hybrid64"):
        # Tail sums in fixed point at 2^-24 per unit (<= 2^-25 per term), and the tail's
        # transmittance pow(1 - α_avg, t) with t <= n (docs/methods.md, hybrid error bounds).
        tol += n * 2.0 ** -25 + n * POW_LOG2
    elif name == "ktab":
        tol += n * 2.0 ** -32  # core sums in fixed point at 2^-31 per unit
    elif name == "wavg":
        tol += n * POW_LOG2  # u = pow(1 - α_avg, n)
    elif name == "wboit":
        # Weights 3e3 pow(1 - z, 3) with relative error 3 2^-21 each; a weighted average of
        # colors in [0, 1] moves by at most twice that.
        tol += 6 * POW_LOG2
    elif name == "mboit":
        # The optical depths -ln(1 - α) carry WGSL log's error (POW_LOG2 absolute), so b0 is off
        # by up to n POW_LOG2 beyond its float32 sum: the total transmittance exp(-b0) by as much
        # (T <= 1), and each weight α exp(-b0 F) relatively by F n POW_LOG2 <= n POW_LOG2 (F <= 1),
        # which moves the weighted average of colors in [0, 1] by at most twice that. The
        # reconstruction of F from the normalized moments in float32 has no a-priori bound
        # (its sensitivity grows as the bias falls: docs/methods.md, "mboit"), nor do the
        # trigonometric basis' cos and sin, whose WGSL error bound (2^-11 absolute) the adapters
        # tested here beat by far: within the rest of this budget on every suite's stacks, measured
        # at most 6 2^-24 (power) and 50 2^-24 (trigonometric) on 10 random layers.
        tol += 3 * n * POW_LOG2
        # At 16 bits the model repeats each critical section's renormalization and rounding to
        # 16 bits in float64; where float32 lands a value on the other side of a rounding step,
        # the stored moment differs by one step (2^-15 of [-1, 1]) and the reconstruction by its
        # sensitivity to it. No a-priori bound: within the same budget on every suite's stacks,
        # measured at most 2.8e-5 on 40 random layers.
    elif name == "wavelet":
        # A(u) is off by E = 3 ((n + rank + 4) U b0 + n POW_LOG2): n-term float32 sums into
        # each coefficient and the reconstruction's (each term at most b0, and at most three
        # tents at a depth), and each optical depth's log; b0 <= 17 mass (tau / alpha is at most
        # -ln(2^-24) < 17). Each weight moves relatively by E, the average of colors in [0, 1]
        # by twice that, the total transmittance by E.
        tol += 9 * ((n + params.get("rank", 16) + 4) * U * 17 * mass + n * POW_LOG2)
    elif name == "auto":
        # The model is the exact composite (oit.models.auto): auto's rendered bound is at most
        # its `tolerance` where it keeps hybrid, (n + 2) ROUNDING_TERM where it falls back to
        # the A-buffer (crates/oit-core/src/method/auto.rs). That bound is for RGB; coverage
        # is off by the quantization and T_core |T_est - T_tail| <= T_core, within the same
        # tolerance where the tail term T_core (hi - lo) is, i.e. for tails whose colors span
        # about [0, 1], as these suites' random colors do.
        t = params.get("tolerance", params_for(name)["tolerance"])
        tol += t + (n + 2) * float(oit.constants()["ROUNDING_TERM"])
    return tol


def color_quantum(name: str) -> float:
    """How far a method may move a fragment's own color by storing it: hybrid64 packs colors
    as R11G11B10 unorm, <= 1/2046 a channel (docs/methods.md); the others keep float32."""
    return 1.0 / 2046 if name == "hybrid64" else 0.0


def exact_in_submission_order(z, rgb, alpha, bg=BG, bg_a: float = 0.0) -> np.ndarray:
    """The exact composite with equal depths in submission order (the peeling methods' rule)."""
    z, rgb, alpha = np.asarray(z, np.float64), np.asarray(rgb, np.float64).reshape(-1, 3), np.asarray(alpha, np.float64)
    c, t = np.zeros(3), 1.0
    for i in np.argsort(z, kind="stable"):
        c += t * alpha[i] * rgb[i]
        t *= 1.0 - alpha[i]
    return np.append(c + t * np.asarray(bg, np.float64), 1.0 - t * (1.0 - bg_a))


def assert_within_error_bound(frame, exact_image: np.ndarray) -> None:
    """Where a method reports `frame.error_bound` (hybrid, hybrid64, ktab, auto), the RGB error
    against the exact composite is within it at every pixel and channel."""
    if getattr(frame, "error_bound", None) is None:
        return
    err = np.abs(frame.image[..., :3].astype(np.float64) - exact_image[..., :3])
    over = err - frame.error_bound
    worst = np.unravel_index(np.argmax(over), over.shape)
    assert (over <= 0).all(), f"error {err[worst]:.3g} > bound {frame.error_bound[worst]:.3g} at {worst}"


def hybrid_tail_count(z, alpha, k: int) -> int:
    """Fragments hybrid and ktab send to the tail (stats["overflow_fragments"]): the model's
    k-TAB with its tie rule (oit.models.hybrid), alpha-0 fragments skipped."""
    z, alpha = np.asarray(z, np.float64), np.asarray(alpha, np.float64)
    keys = [int(x) for x in models.hybrid_keys(z[alpha > 0], alpha[alpha > 0])]
    ranked = sorted(keys, reverse=True)
    table = ranked[:k]
    if len(table) < k:
        return 0
    evicted = ranked[k] if len(ranked) > k else 0
    bound = table[-1] + 1 if evicted != 0 and evicted == table[-1] else table[-1]
    core = {x for x in table if x >= bound}
    return sum(1 for key in keys if key not in core)


def expected_overflow(name: str, z, alpha, **params) -> int | None:
    """What stats["overflow_fragments"] should say for one pixel's stack, or None when no
    model of it is known here. Only hybrid and ktab have a bounded structure that overflows;
    the blends have none, the list methods grow theirs, and adaptive and mlab merge entries
    by design (their overflow counts fragments that gave up on a pixel lock: none here)."""
    if name in ("hybrid", "ktab"):
        return hybrid_tail_count(z, alpha, int(params["k"]))
    if name in ("unsorted", "sorted", "wavg", "wsum", "wboit", "adaptive", "mlab") or INFO[name]["exact"]:
        return 0
    return None


# ---- scenes


@dataclass
class Stacks:
    """Per-pixel fragment stacks: `z`, `rgb`, `alpha` of each pixel in submission order
    (row-major pixels), and the scene that draws them under the identity camera."""

    scene: oit.Scene
    width: int
    height: int
    z: list[np.ndarray]
    rgb: list[np.ndarray]
    alpha: list[np.ndarray]
    prims: list[np.ndarray]  # each fragment's triangle index (see stacks)

    def expect(self, name: str, bg=BG, **params) -> np.ndarray:
        """(h, w, 4) float64 expected image."""
        out = [expected(name, z, c, a, bg, pixel=divmod(p, self.width), size=(self.width, self.height), prims=t, **params)
               for p, (z, c, a, t) in enumerate(zip(self.z, self.rgb, self.alpha, self.prims))]
        return np.array(out).reshape(self.height, self.width, 4)


def pixel_quads(width: int, height: int, cells: np.ndarray, z: np.ndarray) -> np.ndarray:
    """(m, 4, 3) positions of small quads (0.3 pixel half-size) around the centers of the
    pixels `cells` (row-major indices), at depths z."""
    row, col = np.divmod(cells, width)
    cx = (col + 0.5) * 2.0 / width - 1.0
    cy = 1.0 - (row + 0.5) * 2.0 / height
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], np.float64)
    pos = np.empty((len(cells), 4, 3))
    pos[:, :, 0] = cx[:, None] + corners[None, :, 0] * (0.6 / width)
    pos[:, :, 1] = cy[:, None] + corners[None, :, 1] * (0.6 / height)
    pos[:, :, 2] = np.asarray(z)[:, None]
    return pos


def stacks(width: int, height: int, layers: int, seed: int = 0, alpha: Callable | None = None,
           z_range=(0.01, 0.99)) -> Stacks:
    """`layers` fragments on every pixel at distinct float32 depths (evenly spaced in
    z_range, so float32 and the 24-bit keys keep them apart), random colors, alphas from
    `alpha(rng, n)` (default uniform in [0.05, 0.95]), one mesh, globally shuffled order."""
    rng = np.random.default_rng(seed)
    pixels = width * height
    depths = np.linspace(*z_range, layers).astype(np.float32)
    z = np.stack([rng.permutation(depths) for _ in range(pixels)])
    rgb = rng.uniform(0, 1, (pixels, layers, 3)).astype(np.float32)
    draw_alpha = alpha or (lambda r, n: r.uniform(0.05, 0.95, n))
    a = np.stack([draw_alpha(rng, layers) for _ in range(pixels)]).astype(np.float32)
    order = rng.permutation(pixels * layers)  # submission order of (pixel, layer) quads
    pix, lay = np.divmod(order, layers)
    pos = pixel_quads(width, height, pix, z[pix, lay]).astype(np.float32)
    colors = np.repeat(np.concatenate([rgb[pix, lay], a[pix, lay][:, None]], 1), 4, axis=0)
    quad = np.array([[0, 1, 2], [0, 2, 3]])
    idx = (np.arange(len(order))[:, None, None] * 4 + quad[None]).reshape(-1, 3)
    scene = oit.Scene()
    scene.add_mesh(pos.reshape(-1, 3), idx, colors)
    # Each pixel's fragments in submission order.
    # The quad submitted j-th is triangles 2j and 2j + 1, split by the diagonal through the
    # pixel's center (corners 0 and 2), which the top-left rule gives to 2j, as in
    # full_screen_prims (checked against the GPU by stochastic's noise).
    zs, cs, als, prims = [], [], [], []
    for p in range(pixels):
        mine = lay[pix == p]
        zs.append(z[p, mine].astype(np.float64))
        cs.append(rgb[p, mine].astype(np.float64))
        als.append(a[p, mine].astype(np.float64))
        prims.append(2 * np.flatnonzero(pix == p))
    return Stacks(scene, width, height, zs, cs, als, prims)


def full_screen_layers(layers: Sequence, opaque: Sequence[int] = ()) -> oit.Scene:
    """One full-screen quad per (z, (r, g, b, a)), each its own mesh, in the given order;
    the indices in `opaque` are opaque meshes. Under the identity camera the quads' shared
    diagonal is drawn once (top-left rule): exactly one fragment a pixel per layer."""
    s = oit.Scene()
    for i, (z, rgba) in enumerate(layers):
        p = np.array([[-1, -1, z], [1, -1, z], [1, 1, z], [-1, 1, z]], np.float32)
        s.add_mesh(p, [[0, 1, 2], [0, 2, 3]], tuple(float(c) for c in rgba), opaque=i in opaque)
    return s


def layer_arrays(layers: Sequence):
    """z, rgb, alpha arrays (float64 of the float32 values the GPU sees) of (z, rgba) layers."""
    z = np.array([np.float32(layer[0]) for layer in layers], np.float64)
    rgba = np.array([layer[1] for layer in layers], np.float32).astype(np.float64)
    return z, rgba[:, :3], rgba[:, 3]


def render_or_limit(renderer: oit.Renderer, scene: oit.Scene, name: str, **kw):
    """Renders, or returns the RuntimeError when the adapter refuses the frame for a loop
    limit it names (llvmpipe's 65,535 iterations per invocation, docs/methods.md). The census
    runs whatever the method, since the callers check its counts."""
    try:
        return renderer.render(scene, oit.Camera(np.eye(4)), name, census=True, **kw)
    except RuntimeError as e:
        limit = renderer.adapter_info["loop_limit"]
        if limit is not None and str(limit) in str(e):
            return e
        raise
