"""`python -m oit bench --shading-cost`: how each method's time grows with the cost of shading a
fragment. `Renderer.render(..., shading_cost=N)` makes every shaded fragment evaluate N extra
lights whose result is discarded (the image is unchanged), so the slope of time against N is
the number of fragment shadings a method does per frame: every fragment once (after an
alpha-only pass, for the two-pass methods), once a peel, or only the stored ones (deferred)."""

from __future__ import annotations

import math
from functools import partial

import numpy as np

from .harness import Progress, Result, census_count, medians, scene_jobs, timed

SHADING_METHODS = ("abuffer", "compact_abuffer", "hybrid", "ktab", "hybrid64", "wboit", "stochastic", "depth_peeling")
SHADING_COSTS = (0, 64, 256, 1024)
# How many times each method shades a fragment (docs/shading.md, "How often each method shades").
SHADINGS_PER_FRAGMENT = {"hybrid": "1 + alpha", "ktab": "1 + alpha", "stochastic": "1 + alpha", "depth_peeling": "1 a peel",
                         "dual_depth_peeling": "1 a peel", "compact_abuffer": "stored only (deferred)",
                         "auto": "estimate + its method's"}


def shading_cost(scenes: list[str], methods: list[str] | None = None, sizes: list[int] | None = None,
                 costs: tuple[int, ...] = SHADING_COSTS, repeat: int = 5, quick: bool = False,
                 show_progress: bool = True) -> Result:
    """For each scene, method (default SHADING_METHODS) and shading cost N: GPU and wall time
    (median over `repeat` after a warm-up), the time over the same method at N = 0, and the
    fitted extra milliseconds per 100 light evaluations (the slope over the costs measured),
    and whether the image stayed bit for bit the same as at N = 0."""
    methods = list(methods or SHADING_METHODS)
    costs = tuple(sorted(set(costs) | {0}))
    result = Result(rows=[])
    progress = Progress(len(scenes) * len(sizes or [None]) * len(costs) * len(methods), show_progress)
    for scene_name, built, renderer in scene_jobs(scenes, sizes, quick):
        size, adapter = f"{renderer.width}x{renderer.height}", renderer.adapter_info["name"]
        for method in methods:
            base: dict[str, float] = {}
            image0 = None
            for cost in costs:
                row = {"scene": scene_name, "size": size, "method": method, "shading_cost": cost, "status": "ok",
                       "adapter": adapter, "message": "", "shadings": SHADINGS_PER_FRAGMENT.get(method, "1"),
                       **{c: math.nan for c, _ in SHADING_COLUMNS[6:]}}
                progress.show(f"{scene_name} {size} {method} N={cost}")
                try:
                    frame, gpu, wall = timed(partial(renderer.render, built.scene, built.camera, method,
                                                     shading_cost=cost), repeat)
                except (RuntimeError, MemoryError, ValueError) as e:
                    row.update(status="failed", message=str(e).splitlines()[0])
                    result.rows.append(row)
                    progress.step(method)
                    continue
                row.update(**medians(gpu, wall), fragments=census_count(frame.stats["fragments"]))
                if cost == 0:
                    base = {k: row[k] for k in ("gpu_ms", "wall_ms")}
                    image0 = frame.image
                for k in ("gpu_ms", "wall_ms"):
                    row[f"{k}_x0"] = row[k] / base[k] if base.get(k) else math.nan
                row["same_image"] = bool(image0 is not None and np.array_equal(frame.image, image0))
                result.rows.append(row)
                progress.step(method)
        _slopes(result.rows)
    return result


def _slopes(rows: list[dict]) -> None:
    """The least-squares slope of time against N per (scene, size, method), in ms per 100
    light evaluations, written into each of its rows."""
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        groups.setdefault((r["scene"], r["size"], r["method"]), []).append(r)
    for group in groups.values():
        ok = [r for r in group if r["status"] == "ok"]
        key = "gpu_ms" if all(math.isfinite(r["gpu_ms"]) for r in ok) else "wall_ms"
        if len({r["shading_cost"] for r in ok}) < 2:
            continue
        x = np.array([r["shading_cost"] for r in ok], dtype=float)
        y = np.array([r[key] for r in ok], dtype=float)
        slope = float(np.polyfit(x, y, 1)[0]) * 100
        for r in group:
            r["ms_per_100"] = slope


SHADING_COLUMNS = [
    ("scene", "{}"), ("size", "{}"), ("method", "{}"), ("shadings", "{}"), ("shading_cost", "{}"), ("same_image", "{}"),
    ("gpu_ms", "{:.1f}"), ("gpu_ms_x0", "{:.2f}"), ("wall_ms", "{:.1f}"), ("wall_ms_x0", "{:.2f}"),
    ("ms_per_100", "{:.2f}"), ("fragments", "{:.0f}"),
]
