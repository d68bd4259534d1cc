"""The claims of Real-Time Rendering 5.5 (transparency, alpha and compositing), each measured on this engine (docs/claims.md)."""

from __future__ import annotations

import numpy as np

from ... import Camera, Renderer, Scene
from ... import scenes as scene_lib
from .common import FAILS, HOLDS, Claim, full_screen_layers, mean_err, quad_scene, render


def peeling_passes() -> tuple[str, str]:
    out, ok = [], True
    for n in (4, 12, 24):
        built = scene_lib.stacks(layers=n, size=(8, 8), seed=1)
        single = render(built, "depth_peeling").stats["extra"]["geometry_passes"]
        dual = render(built, "dual_depth_peeling").stats["extra"]["geometry_passes"]
        out.append(f"{n} layers: {single:.0f} passes (dual {dual:.0f})")
        ok &= single == n + 1 and dual == n // 2 + 1
    return "; ".join(out) + " (one more finds nothing left)", HOLDS if ok else FAILS


def stochastic_noise() -> tuple[str, str]:
    built = scene_lib.stacks(layers=20, size=(32, 32), seed=2)
    errs = {s: mean_err(built, "stochastic", samples=s) for s in (4, 16, 64)}
    ratio = errs[4] / errs[64]
    text = ", ".join(f"{s} samples {e:.4f}" for s, e in errs.items()) + f"; 4 → 64 samples: {ratio:.1f}× lower (1/√S: 4×)"
    falling = errs[4] > errs[16] > errs[64] and ratio >= 2.0
    return text, HOLDS if falling else FAILS


def weighted_by_opacity() -> tuple[str, str]:
    out, faint, dense = [], {}, {}
    for method in ("wavg", "wboit"):
        faint[method] = mean_err(full_screen_layers(0.1), method)
        dense[method] = mean_err(full_screen_layers(0.9), method)
        out.append(f"{method}: {faint[method]:.4f} at alpha 0.1, {dense[method]:.4f} at alpha 0.9")
    ok = all(faint[m] < 0.05 and dense[m] > 3 * faint[m] for m in faint)
    return "; ".join(out) + " (10 layers, mean error against the A-buffer)", HOLDS if ok else FAILS


def weighted_sum_saturates() -> tuple[str, str]:
    built = full_screen_layers(0.5)
    rgb = {m: render(built, m).image[..., :3] for m in ("wsum", "wavg")}
    text = "; ".join(f"{m}: channels from {v.min():.2f} to {v.max():.2f}" for m, v in rgb.items())
    out_of_range = lambda v: v.min() < 0.0 or v.max() > 1.0  # noqa: E731
    verdict = HOLDS if out_of_range(rgb["wsum"]) and not out_of_range(rgb["wavg"]) else FAILS
    return f"ten layers at alpha 0.5 over the white background: {text} (a color is in [0, 1])", verdict


def wboit_against_wavg() -> tuple[str, str]:
    out, better = [], True
    for alpha in (0.1, 0.5, 0.9):
        built = full_screen_layers(alpha)
        e = {m: mean_err(built, m) for m in ("wboit", "wavg")}
        out.append(f"alpha {alpha}: wboit {e['wboit']:.4f}, wavg {e['wavg']:.4f}")
        better &= e["wboit"] < e["wavg"]
    return "; ".join(out) + " (ten full-screen layers, mean error against the A-buffer)", HOLDS if better else FAILS


def filter_order_independent() -> tuple[str, str]:
    rng = np.random.default_rng(6)
    colors = [(*rng.uniform(0, 1, 3), rng.uniform(0.1, 0.9)) for _ in range(8)]
    images = []
    for order in (range(8), reversed(range(8))):
        scene = Scene()
        for i in order:
            z = 0.1 + 0.1 * i
            quad = np.array([[-1, -1, z], [1, -1, z], [1, 1, z], [-1, 1, z]], np.float32)
            scene.add_mesh(quad, [[0, 1, 2], [0, 2, 3]], colors[i])
        images.append(Renderer(8, 8).render(scene, Camera(np.eye(4)), "filter").image)
    same = np.array_equal(images[0], images[1])
    diff = float(np.abs(images[0] - images[1]).max())
    return f"eight filter layers drawn in two orders: images {'bit-identical' if same else f'differ by {diff:.2e}'}", \
        HOLDS if diff <= 1e-6 else FAILS


def sorting_by_centroid() -> tuple[str, str]:
    flat = lambda z: [[-1, -1, z], [1, -1, z], [1, 1, z], [-1, 1, z]]  # noqa: E731
    # Four separate layers submitted front to back (the worst order for plain blending).
    separate = quad_scene([(flat(z), (z, 0.3, 1 - z, 0.5)) for z in (0.2, 0.4, 0.6, 0.8)])
    # Two quads that cross at the middle of the frame: each is in front over half of it.
    crossing = quad_scene([([[-1, -1, 0.2], [1, -1, 0.8], [1, 1, 0.8], [-1, 1, 0.2]], (1.0, 0.2, 0.1, 0.6)),
                            ([[-1, -1, 0.8], [1, -1, 0.2], [1, 1, 0.2], [-1, 1, 0.8]], (0.1, 0.3, 1.0, 0.6))])
    e = {(name, m): mean_err(b, m) for name, b in (("separate", separate), ("crossing", crossing)) for m in ("sorted", "unsorted")}
    text = (f"four separate layers: sorted {e['separate', 'sorted']:.4f}, unsorted {e['separate', 'unsorted']:.4f}; "
            f"two crossing quads: sorted {e['crossing', 'sorted']:.4f}, unsorted {e['crossing', 'unsorted']:.4f} "
            "(mean error against the A-buffer)")
    ok = e["separate", "sorted"] < 1e-4 < e["separate", "unsorted"] and e["crossing", "sorted"] > 0.01
    return text, HOLDS if ok else FAILS


def peeling_front_first() -> tuple[str, str]:
    built = scene_lib.stacks(layers=20, size=(16, 16), seed=9)
    errs = {n: mean_err(built, "depth_peeling", layers=n) for n in (1, 4, 8, 16, 20)}
    text = ", ".join(f"{n} peels {e:.4f}" for n, e in errs.items()) + " (20-layer stacks, mean error against the A-buffer)"
    values = list(errs.values())
    falling = all(a > b for a, b in zip(values, values[1:-1])) and values[-1] < 1e-5
    return text, HOLDS if falling else FAILS


CLAIMS: list[Claim] = [
    Claim("RTR-peel", "RTR 5.5", "depth peeling needs one geometry pass a layer", True, peeling_passes),
    Claim("RTR-stoch", "RTR 5.5", "stochastic transparency's noise falls with more samples", True, stochastic_noise),
    Claim("RTR-weighted", "RTR 5.5, weighted average", "nearly opaque objects give poor results ... works well for highly "
          "transparent surfaces and particles", True, weighted_by_opacity),
    Claim("RTR-wsum", "RTR 5.5, weighted sum", "the weighted sum saturates and can go negative; the weighted average avoids it",
          True,
          weighted_sum_saturates),
    Claim("RTR-wboit", "RTR 5.5, weighted blended OIT", "WB-OIT gives a more convincing result than the weighted average", True,
          wboit_against_wavg),
    Claim("RTR-filter", "RTR 5.5, transmission", "colour filtering (multiplying by the transmittance) is order-independent", True,
          filter_order_independent),
    Claim("RTR-centroid", "RTR 5.5, sort by centroid", "sorting meshes by centroid is right for separate objects; "
          "\"objects that interpenetrate are impossible to resolve on a per-mesh basis\"", True, sorting_by_centroid),
    Claim("RTR-peel-early", "RTR 5.5, depth peeling", "peeling front to back renders \"the most important transparent layers\" "
          "first, so a fixed number of passes can be specified", True, peeling_front_first),
]
