"""`python -m oit bench --splats`: Gaussian splats (issue 44). The trade: each method's time,
memory, error against the exact frame and flicker over an orbit on splat scenes, with both depth
choices where a method's order follows the depth (`splat_trade`). The scale: every bounded method
at a million splats under a memory budget (`splat_scale`)."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from .. import scenes as scene_lib
from .._api import Renderer
from .._api import methods as list_methods
from .harness import QUICK_SIZE, Progress, Result, image_errors
from .temporal import TEMPORAL_FRAMES, TEMPORAL_STEP_DEG, frame_changes, orbit

# oit.scenes.splats of each kind: scenes.SCENES' "splats" and "splat_cloud", which SHOWCASE leaves
# out (the main sweep's rows stay those of the mesh scenes).
SPLAT_KINDS = ("surface", "cloud")
SPLAT_COUNT = 30_000
# The methods each splat renderer of the literature uses, and the others of their families:
# sorted (3DGS's center order), abuffer (per-pixel exact, StopThePop's answer), hybrid (HTGS),
# stochastic (StochasticSplats), the weighted sums (sort-free splatting), adaptive, MLAB, MBOIT.
TRADE_METHODS = ("sorted", "abuffer", "hybrid", "stochastic", "wboit", "wavg", "wsum", "adaptive", "mlab", "mboit")
# Methods whose image does not depend on the fragments' depths (sorted orders splats by their
# means whatever the fragments' depth): one row, at "center".
DEPTH_FREE = ("sorted", "wavg", "wsum")
SCALE_COUNT = 1_000_000
SCALE_SIZES = ((512, 512), (1920, 1080))
SCALE_BUDGET = 256 * 2 ** 20


def splat_trade(kinds: tuple[str, ...] = SPLAT_KINDS, methods: tuple[str, ...] = TRADE_METHODS, count: int = SPLAT_COUNT,
                size: int = 256, frames: int = TEMPORAL_FRAMES, step_deg: float = TEMPORAL_STEP_DEG, quick: bool = False,
                show_progress: bool = True) -> Result:
    """Each splat scene over a slow orbit (oit.bench.temporal.orbit) with each method at its
    defaults, the set's splat_depth "center" and "ray" (one row for DEPTH_FREE methods). The
    exact frame is abuffer with "ray" (each pixel's splats in the order of their peaks along its
    ray): every row's `mean_err` (over the frames) and `flicker` (frame_changes: the part of its
    frame-to-frame change that the exact sequence does not have) are against it, `flicker_ratio`
    over the exact change, `max_flicker` its largest value at a pixel (a pop). `ms` is the
    median wall time of a frame, `peak_mib` its memory."""
    if quick:
        count, size, frames = min(count, 2000), min(size, QUICK_SIZE), min(frames, 3)
    known = {m["name"] for m in list_methods()}
    unknown = sorted(set(methods) - known)
    if unknown:
        raise ValueError(f"unknown method(s) {', '.join(unknown)}; `python -m oit methods` lists them")
    runs = [(m, d) for m in methods for d in (("center",) if m in DEPTH_FREE else ("center", "ray"))]
    renderer = Renderer(size, size)
    adapter = renderer.adapter_info["name"]
    result = Result(rows=[])
    progress = Progress(len(kinds) * (1 + len(runs)), show_progress)
    for kind in kinds:
        built = {d: scene_lib.splats(count, kind, splat_depth=d) for d in ("center", "ray")}
        cameras = orbit(built["ray"], frames, step_deg)
        progress.show(f"{kind} exact")
        exact_frames = [renderer.render(built["ray"].scene, c, "abuffer") for c in cameras]
        exact = [f.image for f in exact_frames]
        covered = [f.depth_complexity > 0 for f in exact_frames]
        reference = frame_changes(exact, exact, covered)["change"]
        progress.step("exact")
        for method, depth in runs:
            progress.show(f"{kind} {method} {depth}")
            row = {"scene": "splats" if kind == "surface" else "splat_cloud", "splats": count, "size": f"{size}x{size}", "method": method,
                   "splat_depth": depth, "status": "ok", "adapter": adapter, "message": ""}
            try:
                rendered = [renderer.render(built[depth].scene, c, method) for c in cameras]
            except (RuntimeError, MemoryError, ValueError) as e:
                result.rows.append({**row, "status": "failed", "message": str(e).splitlines()[0]})
                progress.step(method)
                continue
            images = [f.image for f in rendered]
            err = [image_errors(im, ex, cov, flip=False) for im, ex, cov in zip(images, exact, covered)]
            changes = frame_changes(images, exact, covered)
            row.update(ms=float(np.median([f.stats["wall_time_ms"] for f in rendered])),
                       peak_mib=max(f.stats["peak_memory_bytes"] for f in rendered) / 2 ** 20,
                       mean_err=float(np.mean([e["mean_err"] for e in err])), max_err=max(e["max_err"] for e in err),
                       flicker=changes["flicker"], max_flicker=changes["max_flicker"],
                       flicker_ratio=changes["flicker"] / reference if reference > 0 else math.nan)
            result.rows.append(row)
            progress.step(method)
    result.notes.append(f"{count} splats a scene, {frames} frames turning {step_deg} degrees each; the exact frame is "
                        "abuffer with splat_depth='ray'")
    return result


def splat_scale(count: int = SCALE_COUNT, sizes: tuple[tuple[int, int], ...] = SCALE_SIZES, budget: int = SCALE_BUDGET,
                methods: tuple[str, ...] | None = None, quick: bool = False, show_progress: bool = True) -> Result:
    """oit.scenes.splats(count) (surface) rendered once by every bounded method (or those named)
    at each size under `budget` bytes, after a warm-up frame of 1,000 splats compiles the
    pipelines: wall time, the frame's peak memory (within the budget), its tiles, the scene's
    bytes (apart from the budget) and the deepest pixel. Slow peeling methods go last."""
    if quick:
        count, sizes = min(count, 5000), ((QUICK_SIZE, QUICK_SIZE),)
    bounded = [m["name"] for m in list_methods() if m["bounded_memory"]]
    names = [m for m in bounded if methods is None or m in methods]
    names.sort(key=lambda m: "peeling" in m)
    built, warm = scene_lib.splats(count), scene_lib.splats(1000)
    result = Result(rows=[])
    progress = Progress(len(sizes) * len(names), show_progress)
    for w, h in sizes:
        renderer = Renderer(w, h, memory_budget=budget)
        census = renderer.render(built.scene, built.camera, "unsorted", census=True)
        depth = int(census.depth_complexity.max())
        for name in names:
            progress.show(f"{w}x{h} {name}")
            row: dict[str, Any] = {"splats": count, "size": f"{w}x{h}", "method": name, "budget_mib": budget / 2 ** 20,
                                   "max_depth_complexity": depth, "status": "ok",
                                   "adapter": renderer.adapter_info["name"], "message": ""}
            try:
                renderer.render(warm.scene, warm.camera, name)
                start = time.perf_counter()
                frame = renderer.render(built.scene, built.camera, name)
                row.update(seconds=time.perf_counter() - start, peak_mib=frame.stats["peak_memory_bytes"] / 2 ** 20,
                           tiles=frame.stats["tiles"], scene_mib=frame.stats["scene_bytes"] / 2 ** 20)
            except (RuntimeError, MemoryError, ValueError) as e:
                row.update(status="failed", message=str(e).splitlines()[0])
            result.rows.append(row)
            progress.step(name)
    return result


TRADE_COLUMNS = [
    ("scene", "{}"), ("method", "{}"), ("splat_depth", "{}"), ("ms", "{:.0f}"), ("peak_mib", "{:.1f}"),
    ("mean_err", "{:.5f}"), ("max_err", "{:.3f}"), ("flicker", "{:.5f}"), ("flicker_ratio", "{:.3f}"),
    ("max_flicker", "{:.3f}"),
]
SCALE_COLUMNS = [
    ("splats", "{}"), ("size", "{}"), ("method", "{}"), ("seconds", "{:.1f}"), ("peak_mib", "{:.1f}"),
    ("tiles", "{}"), ("scene_mib", "{:.1f}"), ("max_depth_complexity", "{}"), ("status", "{}"),
]
