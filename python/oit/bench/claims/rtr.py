"""The claims of Real-Time Rendering 5.5 (transparency, alpha and compositing), each measured on this engine (docs/claims.md)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ... import Renderer, memory_bytes, methods
from ... import scenes as scene_lib
from .common import (
    FAILS,
    HOLDS,
    TOL,
    Claim,
    error_against,
    flat_quad,
    full_screen_layers,
    mean_err,
    median_ms,
    method_passes,
    quad_scene,
    render,
)


def peeling_passes() -> tuple[str, str]:
    out, ok = [], True
    for n in (4, 12, 24):
        built = scene_lib.stacks(layers=n, size=(8, 8), seed=1)
        single = render(built, "depth_peeling").stats["extra"]["geometry_passes"]
        dual = render(built, "dual_depth_peeling").stats["extra"]["geometry_passes"]
        out.append(f"{n} layers: {single:.0f} passes (dual {dual:.0f})")
        ok &= single == n + 1 and dual == n // 2 + 1
    return "; ".join(out) + " (one more finds nothing left; rule: n + 1, and n / 2 + 1 for dual)", HOLDS if ok else FAILS


def stochastic_noise() -> tuple[str, str]:
    built = scene_lib.stacks(layers=20, size=(32, 32), seed=2)
    errs = {s: mean_err(built, "stochastic", samples=s) for s in (4, 16, 64)}
    ratio = errs[4] / errs[64]
    text = ", ".join(f"{s} samples {e:.4f}" for s, e in errs.items()) + f"; 4 → 64 samples: {ratio:.1f}× lower (1/√S: 4×; rule: " \
        "falls at every step, at least 2× from 4 to 64)"
    falling = errs[4] > errs[16] > errs[64] and ratio >= 2.0
    return text, HOLDS if falling else FAILS


def weighted_by_opacity() -> tuple[str, str]:
    out, faint, dense = [], {}, {}
    for method in ("wavg", "wboit"):
        faint[method] = mean_err(full_screen_layers(0.1), method)
        dense[method] = mean_err(full_screen_layers(0.9), method)
        out.append(f"{method}: {faint[method]:.4f} at alpha 0.1, {dense[method]:.4f} at alpha 0.9")
    ok = all(faint[m] < 0.05 and dense[m] > 3 * faint[m] for m in faint)
    return "; ".join(out) + " (10 layers, mean error against the A-buffer; rule: both within 0.05 at " \
        "alpha 0.1 and 3× worse at 0.9)", HOLDS if ok else FAILS


def weighted_sum_saturates() -> tuple[str, str]:
    built = full_screen_layers(0.5)
    rgb = {m: render(built, m).image[..., :3] for m in ("wsum", "wavg")}
    text = "; ".join(f"{m}: channels from {v.min():.2f} to {v.max():.2f}" for m, v in rgb.items())
    out_of_range = lambda v: v.min() < 0.0 or v.max() > 1.0  # noqa: E731
    verdict = HOLDS if out_of_range(rgb["wsum"]) and not out_of_range(rgb["wavg"]) else FAILS
    return f"ten layers at alpha 0.5 over the white background: {text} (rule: wsum leaves [0, 1], wavg stays in it)", verdict


def wboit_against_wavg() -> tuple[str, str]:
    out, better = [], True
    for alpha in (0.1, 0.5, 0.9):
        built = full_screen_layers(alpha)
        e = {m: mean_err(built, m) for m in ("wboit", "wavg")}
        out.append(f"alpha {alpha}: wboit {e['wboit']:.4f}, wavg {e['wavg']:.4f}")
        better &= e["wboit"] < e["wavg"]
    return "; ".join(out) + " (ten full-screen layers, mean error against the A-buffer; rule: wboit lower at " \
        "every alpha)", HOLDS if better else FAILS


def filter_order_independent() -> tuple[str, str]:
    rng = np.random.default_rng(6)
    colors = [(*rng.uniform(0, 1, 3), rng.uniform(0.1, 0.9)) for _ in range(8)]
    images = [render(replace(quad_scene([(flat_quad(0.1 + 0.1 * i), colors[i]) for i in order]), size=(8, 8)), "filter").image
              for order in (range(8), reversed(range(8)))]
    same = np.array_equal(images[0], images[1])
    diff = float(np.abs(images[0] - images[1]).max())
    return f"eight filter layers drawn in two orders: images {'bit-identical' if same else f'differ by {diff:.2e}'} (rule: within 1e-6)", \
        HOLDS if diff <= 1e-6 else FAILS


def sorting_by_centroid() -> tuple[str, str]:
    # Four separate layers submitted front to back (the worst order for plain blending).
    separate = quad_scene([(flat_quad(z), (z, 0.3, 1 - z, 0.5)) for z in (0.2, 0.4, 0.6, 0.8)])
    # Two quads that cross at the middle of the frame: each is in front over half of it.
    crossing = quad_scene([([[-1, -1, 0.2], [1, -1, 0.8], [1, 1, 0.8], [-1, 1, 0.2]], (1.0, 0.2, 0.1, 0.6)),
                            ([[-1, -1, 0.8], [1, -1, 0.2], [1, 1, 0.2], [-1, 1, 0.8]], (0.1, 0.3, 1.0, 0.6))])
    e = {(name, m): mean_err(b, m) for name, b in (("separate", separate), ("crossing", crossing)) for m in ("sorted", "unsorted")}
    text = (f"four separate layers: sorted {e['separate', 'sorted']:.4f}, unsorted {e['separate', 'unsorted']:.4f}; "
            f"two crossing quads: sorted {e['crossing', 'sorted']:.4f}, unsorted {e['crossing', 'unsorted']:.4f} "
            "(mean error against the A-buffer; rule: sorted exact on the separate layers, still wrong, above 0.01, on the crossing ones)")
    ok = e["separate", "sorted"] < 1e-4 < e["separate", "unsorted"] and e["crossing", "sorted"] > 0.01
    return text, HOLDS if ok else FAILS


def peeling_front_first() -> tuple[str, str]:
    built = scene_lib.stacks(layers=20, size=(16, 16), seed=9)
    errs = {n: mean_err(built, "depth_peeling", layers=n) for n in (1, 4, 8, 16, 20)}
    text = ", ".join(f"{n} peels {e:.4f}" for n, e in errs.items()) + " (20-layer stacks, mean error against the A-buffer; " \
        "rule: falls with every peel, below 1e-5 at 20)"
    values = list(errs.values())
    falling = all(a > b for a, b in zip(values, values[1:-1])) and values[-1] < 1e-5
    return text, HOLDS if falling else FAILS


def _with_alpha(built: scene_lib.BuiltScene, alpha: float) -> scene_lib.BuiltScene:
    """A one-mesh scene (`stacks`) with every alpha set to `alpha`."""
    mesh = built.meshes[0]
    colors = mesh.colors.copy()
    colors[:, 3] = alpha
    return scene_lib.from_meshes([replace(mesh, colors=colors)], built.camera, built.size)


def _resubmitted(built: scene_lib.BuiltScene, order) -> scene_lib.BuiltScene:
    """`stacks` with its quads submitted in `order(depths)`, an argsort of the quads' depths."""
    mesh = built.meshes[0]
    quads, colors = mesh.positions.reshape(-1, 4, 3), mesh.colors.reshape(-1, 4, 4)
    o = order(quads[:, 0, 2])
    moved = replace(mesh, positions=quads[o].reshape(-1, 3), colors=colors[o].reshape(-1, 4))
    return scene_lib.from_meshes([moved], built.camera, built.size)


def _distance(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(((a[..., :3] - b[..., :3]) ** 2).sum(-1)).mean())


def _geometry_passes(method: str) -> int:
    return sum("(geometry)" in p for p in method_passes(method))


def weighted_by_depth() -> tuple[str, str]:
    depths, out, ok, errs = (2, 4, 8, 16, 32, 64), [], True, {}
    for alpha in (0.1, 0.6):
        built = {n: _with_alpha(scene_lib.stacks(layers=n, size=(16, 16), seed=3), alpha) for n in depths}
        for m in ("wavg", "wboit"):
            e = errs[m, alpha] = [mean_err(built[n], m) for n in depths]
            out.append(f"{m} at alpha {alpha}: " + "/".join(f"{x:.3f}" for x in e))
            ok &= all(a < b for a, b in zip(e, e[1:])) and e[0] <= 3 * TOL
    alpha_rules = all(a < b for m in ("wavg", "wboit") for a, b in zip(errs[m, 0.1], errs[m, 0.6]))
    text = ("; ".join(out) + f" (16² stacks of {'/'.join(map(str, depths))} layers, mean error against the A-buffer); "
            f"error higher at alpha 0.6 than 0.1 at every depth: {'yes' if alpha_rules else 'no'} "
            "(holds if both rise at every doubling and are within 3/255 at 2 layers, at both alphas)")
    return text, HOLDS if ok else FAILS


def screen_door_one_layer() -> tuple[str, str]:
    errs = {}
    for n in (1, 2, 4):
        built = full_screen_layers(0.5, n)
        door, exact = (render(built, m).image[..., :3].reshape(4, 4, 4, 4, 3).mean((1, 3)) for m in ("screen_door", "abuffer"))
        errs[n] = _distance(door, exact)
    text = ", ".join(f"{n} layer{'s' * (n > 1)} {e:.4f}" for n, e in errs.items())
    ok = errs[1] <= TOL and min(errs[2], errs[4]) > 10 * TOL
    return (f"full-screen layers at alpha 0.5 (16², every layer the same 4×4 dither pattern), mean RGB error of the 4×4 block "
            f"means against the A-buffer: {text} (holds if one layer is within 1/255 and more miss by 10/255)"), HOLDS if ok else FAILS


def additive_saturates() -> tuple[str, str]:
    built = replace(scene_lib.smoke(particles=300), size=(32, 32))
    add, exact = (render(built, m, background=(0, 0, 0)) for m in ("additive", "abuffer"))
    covered = exact.depth_complexity > 0
    over = float((add.image[..., :3].max(-1)[covered] > 1).mean())
    text = (f"smoke (300 particles, 32², up to {exact.depth_complexity.max()} layers) over black: additive channels up to "
            f"{add.image[..., :3].max():.2f}, {over:.0%} of covered pixels past 1 (white); the A-buffer's up to "
            f"{exact.image[..., :3].max():.2f}")
    return text, HOLDS if over > 0 and exact.image[..., :3].max() <= 1 else FAILS


def over_needs_order() -> tuple[str, str]:
    built = scene_lib.stacks(layers=8, size=(16, 16), seed=4)
    e = {name: mean_err(_resubmitted(built, key), "unsorted") for name, key in
         (("back to front", lambda z: np.argsort(-z)), ("front to back", np.argsort))}
    text = ", ".join(f"submitted {k} {v:.4f}" for k, v in e.items())
    return (f"over in submission order on 8-layer stacks (16²), mean error against the A-buffer: {text} "
            "(holds if back to front is within 1/255 and front to back is not)"), \
        HOLDS if e["back to front"] <= TOL < e["front to back"] else FAILS


def dual_halves_passes() -> tuple[str, str]:
    out, ok = [], True
    for n in (3, 8, 13, 32):
        built = scene_lib.stacks(layers=n, size=(8, 8), seed=1)
        single, dual = (render(built, m).stats["extra"]["geometry_passes"] for m in ("depth_peeling", "dual_depth_peeling"))
        out.append(f"{n} layers: {dual:.0f} against {single:.0f}")
        ok &= dual - 1 == -(-n // 2) and single - 1 == n
    return ("geometry passes of dual against single depth peeling (8² stacks): " + "; ".join(out) +
            " (holds if ⌈n/2⌉ against n, plus one that finds nothing left)"), HOLDS if ok else FAILS


def bucket_sort() -> tuple[str, str]:
    errs = {n: mean_err(scene_lib.stacks(layers=n, size=(16, 16), seed=7), "bucket_peeling", buckets=32) for n in (2, 4, 8, 16, 32)}
    per_pixel = {m: memory_bytes(m, 512, 512, **p) / 512 ** 2 for m, p in
                 (("bucket_peeling", {"buckets": 32}), ("depth_peeling", {}), ("wboit", {}))}
    exact, big = all(e <= TOL for e in errs.values()), per_pixel["bucket_peeling"] >= 4 * per_pixel["depth_peeling"]
    text = ("buckets=32 on 16² stacks, mean error against the A-buffer: " + ", ".join(f"{n} layers {e:.4f}" for n, e in errs.items()) +
            f"; memory {per_pixel['bucket_peeling']:.0f} B a pixel against depth peeling's {per_pixel['depth_peeling']:.0f} and "
            f"WB-OIT's {per_pixel['wboit']:.0f}; {_geometry_passes('bucket_peeling')} geometry passes here (holds if every stack "
            f"of ≤ 32 layers is within 1/255 and the memory is at least 4× depth peeling's: memory "
            f"{'yes' if big else 'no'}, exact {'yes' if exact else 'no'})")
    return text, HOLDS if exact and big else FAILS


def mlab_graceful() -> tuple[str, str]:
    deep = scene_lib.stacks(layers=16, size=(8, 8), seed=4)
    errs = {k: mean_err(deep, "mlab", layers=k) for k in (1, 2, 4, 8)}
    built = scene_lib.stacks(layers=8, size=(16, 16), seed=4)
    rng = np.random.default_rng(0)
    rough = _resubmitted(built, lambda z: np.argsort(z + rng.normal(0, 0.1, len(z))))
    shuffled, sorted_ = mean_err(built, "mlab", layers=2), mean_err(rough, "mlab", layers=2)
    exact_order = mean_err(_resubmitted(built, np.argsort), "mlab", layers=2)
    per_pixel = render(deep, "mlab").stats["memory_bytes"] / 64
    ok = all(a > b for a, b in zip(list(errs.values()), list(errs.values())[1:])) and shuffled - sorted_ >= TOL
    text = ("16-layer stacks (8²), mean error against the A-buffer: " + ", ".join(f"layers={k} {e:.4f}" for k, e in errs.items()) +
            f"; 8-layer stacks (16²) at layers=2: shuffled {shuffled:.4f}, roughly sorted front to back (depth + noise of "
            f"σ 0.1) {sorted_:.4f} ({shuffled / sorted_:.1f}× lower), sorted {exact_order:.4f}; cost: it keeps every fragment, "
            f"{per_pixel:.0f} B a pixel on the 16-layer stacks against "
            "WB-OIT's 20 (holds if the error falls at every step and a rough sort lowers it by at least 1/255)")
    return text, HOLDS if ok else FAILS


def wboit_near_wavg() -> tuple[str, str]:
    diffs = {}
    for spread in (0.8, 0.4, 0.2, 0.1, 0.05, 0.02):
        built = full_screen_layers(0.3, zs=np.linspace(0.5 - spread / 2, 0.5 + spread / 2, 8))
        diffs[spread] = _distance(*(render(built, m).image for m in ("wboit", "wavg")))
    values = list(diffs.values())
    ok = all(a > b for a, b in zip(values, values[1:])) and values[-1] <= TOL
    return ("8 full-screen layers at alpha 0.3 (16²) spread over window depths around 0.5, mean RGB distance between the "
            "wboit and wavg images: " + ", ".join(f"spread {s} {d:.4f}" for s, d in diffs.items()) +
            " (holds if it falls at every step and ends within 1/255)"), HOLDS if ok else FAILS


def wboit_gradual() -> tuple[str, str]:
    images = [render(full_screen_layers(0.3, zs=np.linspace(0.05, 0.45, 8) + 0.01 * i), "wboit").image for i in range(41)]
    steps = [_distance(a, b) for a, b in zip(images, images[1:])]
    jump = max(b / a for a, b in zip(steps, steps[1:]))
    exact = _distance(*(render(full_screen_layers(0.3, zs=np.linspace(0.05, 0.45, 8) + dz), "abuffer").image for dz in (0.0, 0.4)))
    ok = max(steps) <= TOL and jump <= 1.5
    return (f"8 full-screen layers at alpha 0.3 (16²) moved back 40 times by 0.01 in window depth: wboit's image changes "
            f"{min(steps):.5f} to {max(steps):.5f} a step (mean RGB distance), each at most {jump:.2f}× the one before "
            f"(the A-buffer's image moves {exact:.5f} over the whole path; holds if every step is within 1/255 and none is "
            "1.5× the one before)"), HOLDS if ok else FAILS


def stochastic_memory() -> tuple[str, str]:
    built = scene_lib.stacks(layers=20, size=(32, 32), seed=2)
    errs = {s: mean_err(built, "stochastic", samples=s) for s in (4, 16, 64)}
    enough = next((s for s, e in errs.items() if e <= 3 * TOL), 64)
    per_pixel = lambda m, **p: memory_bytes(m, 32, 32, **p) / 32 ** 2  # noqa: E731
    lists = render(built, "abuffer").stats["memory_bytes"] / 32 ** 2
    ok = enough >= 16 and per_pixel("stochastic", samples=enough) >= 4 * per_pixel("wboit")
    return ("20-layer stacks (32²), mean error against the A-buffer and memory a pixel: " +
            ", ".join(f"{s} samples {e:.4f} ({per_pixel('stochastic', samples=s):.0f} B)" for s, e in errs.items()) +
            f"; WB-OIT {per_pixel('wboit'):.0f} B, the A-buffer {lists:.0f} B (holds if no count below 16 is within 3/255 and the "
            "memory at the first count that is, else at 64, is at least 4× WB-OIT's)"), HOLDS if ok else FAILS


def lists_one_pass() -> tuple[str, str]:
    out, ok = [], _geometry_passes("abuffer") == 1
    for n in (4, 16, 64):
        built = scene_lib.stacks(layers=n, size=(8, 8), seed=1)
        peel = render(built, "depth_peeling").stats["extra"]["geometry_passes"]
        out.append(f"{n} layers: {peel:.0f}")
        ok &= peel == n + 1
    return (f"geometry passes on 8² stacks: the A-buffer {_geometry_passes('abuffer')} (capture; sort and resolve are "
            "full screen), depth peeling " + ", ".join(out) + " (holds if 1 against n + 1)"), HOLDS if ok else FAILS


def peeling_slow() -> tuple[str, str]:
    out, ratios = [], []
    for n in (4, 32):
        built = scene_lib.stacks(layers=n, size=(64, 64), seed=1)
        r = Renderer(*built.size)
        lists, peel = median_ms(r, built, "abuffer"), median_ms(r, built, "depth_peeling")
        ratios.append(peel / lists)
        out.append(f"{n} layers: abuffer {lists:.1f} ms, depth_peeling {peel:.1f} ms ({ratios[-1]:.1f}×)")
    return ("median GPU time on 64² stacks: " + "; ".join(out) + " (holds if depth peeling takes at least 2× the A-buffer's "
            "time at 32 layers)"), HOLDS if ratios[-1] >= 2 else FAILS


def no_perfect_method() -> tuple[str, str]:
    names = [m["name"] for m in methods()]
    scenes = {"glass": replace(scene_lib.glass(detail=8), size=(24, 24)), "smoke": replace(scene_lib.smoke(particles=150), size=(24, 24)),
              "stacks": scene_lib.stacks(layers=12, size=(8, 8), seed=3)}
    out, best = [], []
    for name, built in scenes.items():
        exact = render(built, "abuffer")
        good = {}
        for m in names:
            frame = render(built, m)
            if error_against(frame.image, exact) <= TOL:
                good[m] = frame.stats["memory_bytes"]
        least = min(good.values())
        best.append({m for m, b in good.items() if b == least})
        out.append(f"{name} {', '.join(sorted(best[-1]))} ({least / 1024:.1f} KiB; {len(good)} methods within)")
    everywhere = set.intersection(*best)
    return (f"the least memory among the methods within 1/255 of the A-buffer (mean error; all {len(names)} methods; glass and "
            f"smoke at 24², 12-layer stacks at 8²): " + "; ".join(out) + " (holds if no method is that on every scene)"), \
        HOLDS if not everywhere else FAILS


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
    Claim("RTR-depth", "RTR 5.5, weighted average", "(our issue's wording) WB-OIT and the weighted average are plausible at "
          "low depth complexity and wrong at high; RTR: \"nearly opaque objects give poor results\"", True, weighted_by_depth),
    Claim("RTR-door", "RTR 5.5, screen-door transparency", "\"often only one transparent object can be convincingly rendered on "
          "one area of the screen\"", True, screen_door_one_layer),
    Claim("RTR-additive", "RTR 5.5, additive blending", "\"for several layered semitransparent surfaces, such as smoke or fire, "
          "additive blending has the effect of saturating the colors\"", True, additive_saturates),
    Claim("RTR-order", "RTR 5.5, blending order", "\"when using over the transparent surfaces ... need to be rendered in "
          "back-to-front order\"", True, over_needs_order),
    Claim("RTR-dual", "RTR 5.5, depth peeling", "dual depth peeling strips the closest and farthest layers each pass, \"cutting "
          "the number of rendering passes in half\"", True, dual_halves_passes),
    Claim("RTR-bucket", "RTR 5.5, depth peeling", "\"a bucket sort method that captures up to 32 layers in a single pass ... needs "
          "considerable memory\"", True, bucket_sort),
    Claim("RTR-mlab", "RTR 5.5, multi-layer alpha blending", "MLAB \"gracefully degrades if memory runs out\"; \"a rough sort "
          "order can benefit their scheme\"; \"can be expensive\"", True, mlab_graceful),
    Claim("RTR-wboit-near", "RTR 5.5, weighted blended OIT", "\"objects close to one another ... can have nearly equal weightings "
          "from distance, making the result little different than the weighted average\"", True, wboit_near_wavg),
    Claim("RTR-wboit-gradual", "RTR 5.5, weighted blended OIT", "\"as the camera's distance to the transparent objects changes, "
          "the depth weightings may then vary in effect, but this change is gradual\"", True, wboit_gradual),
    Claim("RTR-stoch-mem", "RTR 5.5, stochastic transparency", "\"a large number of samples per pixel is needed ... as well as a "
          "sizable amount of memory\"", True, stochastic_memory),
    Claim("RTR-lists", "RTR 5.5, A-buffer", "linked lists capture every fragment in one pass, where depth peeling needs a pass "
          "a layer", True, lists_one_pass),
    Claim("RTR-peel-slow", "RTR 5.5, depth peeling", "\"while depth peeling is effective, it can be slow\"", False, peeling_slow),
    Claim("RTR-none", "RTR 5.5, end", "\"there is no perfect solution for rendering transparent objects\"", False, no_perfect_method),
]
