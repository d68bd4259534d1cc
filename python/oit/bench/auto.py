"""`python -m oit bench --auto`: auto at a tolerance against the cheapest fixed k that meets
it, found by search."""

from __future__ import annotations

import math
import os
from functools import partial
from typing import Any, Callable

import numpy as np

from .harness import Progress, Result, image_errors, medians, scene_jobs, timed

AUTO_TOLERANCES = (1 / 255, 4 / 255, 16 / 255)
AUTO_MAX_K = 32


def max_abs_error(image: np.ndarray, exact: np.ndarray) -> float:
    """Largest |image - exact| over every pixel and RGB channel: what auto's tolerance bounds
    (its error bound holds for each channel, docs/methods.md)."""
    return float(np.abs(image[..., :3].astype(np.float64) - exact[..., :3]).max())


def smallest_k(error: Callable[[int], float], tolerance: float, max_k: int = AUTO_MAX_K) -> int | None:
    """The smallest k in 1..max_k whose measured error is at most `tolerance`, scanning upward
    and stopping at the first (hybrid's error is not monotone in k, so no bisection); None when
    none is."""
    return next((k for k in range(1, max_k + 1) if error(k) <= tolerance), None)


def auto_vs_fixed(scenes: list[str], sizes: list[int] | None = None, tolerances: tuple[float, ...] = AUTO_TOLERANCES,
                  repeat: int = 5, max_k: int = AUTO_MAX_K, quick: bool = False, show_progress: bool = True) -> Result:
    """For each scene and tolerance t: `auto` at t (GPU and wall time, median over `repeat`
    after a warm-up; memory; what it chose; its measured error against abuffer) beside the
    cheapest fixed-k hybrid that meets t as measured (smallest_k over 1..max_k, each k rendered
    once, its errors shared by every t), timed the same way. `within_t` says whether auto's
    largest per-channel error is at most t (it must be)."""
    result = Result(rows=[])
    progress = Progress(len(scenes) * len(sizes or [None]) * (1 + 2 * len(tolerances)), show_progress)
    for scene_name, built, renderer in scene_jobs(scenes, sizes, quick):
        size, adapter = f"{renderer.width}x{renderer.height}", renderer.adapter_info["name"]
        render = partial(renderer.render, built.scene, built.camera)
        progress.show(f"{scene_name} {size} abuffer")
        try:
            exact_frame = render("abuffer")
        except (RuntimeError, MemoryError) as e:
            result.notes.append(f"{scene_name} {size}: no auto rows, the exact A-buffer failed: {e}")
            progress.step("abuffer")
            continue
        exact, covered = exact_frame.image, exact_frame.depth_complexity > 0
        progress.step("abuffer")
        fixed_errors: dict[int, float] = {}  # k -> measured max error, shared by every t

        def fixed_error(k: int, fixed_errors=fixed_errors, render=render, exact=exact, label=f"{scene_name} {size}") -> float:
            if k not in fixed_errors:
                progress.show(f"{label} hybrid k={k} (search)")
                fixed_errors[k] = max_abs_error(render("hybrid", k=k).image, exact)
            return fixed_errors[k]

        for t in tolerances:
            row = {"scene": scene_name, "size": size, "tolerance": t, "status": "ok", **_AUTO_EMPTY, "adapter": adapter,
                   "message": ""}
            progress.show(f"{scene_name} {size} auto t={t:.4g}")
            try:
                frame, gpu, wall = timed(partial(render, "auto", tolerance=t), repeat)
                row.update(_measured("auto", frame, gpu, wall, exact, covered))
                row.update({key: {**frame.stats, **frame.stats["extra"]}.get(key, math.nan) for key in AUTO_STATS})
                row["within_t"] = row["auto_max_abs"] <= t
                progress.step("auto")
                k = smallest_k(fixed_error, t, max_k)
                row["fixed_k"] = "none" if k is None else k
                if k is not None:
                    progress.show(f"{scene_name} {size} hybrid k={k} (timed)")
                    row.update(_measured("fixed", *timed(partial(render, "hybrid", k=k), repeat), exact, covered))
                    for what in ("gpu_ms", "wall_ms", "mib"):
                        row[f"{what}_ratio"] = row[f"auto_{what}"] / row[f"fixed_{what}"]
                progress.step("hybrid")
            except (RuntimeError, MemoryError, ValueError) as e:
                row.update(status="failed", message=str(e).splitlines()[0])
            row["load_avg"] = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan  # as _row keeps it
            result.rows.append(row)
    return result


# Stats that auto reports beside the image (docs/methods.md, "Error bounds per pixel, and auto").
AUTO_STATS = ("auto_k", "auto_mean_k", "auto_slots", "auto_predicted_k", "auto_exact", "auto_attempts", "auto_moments",
              "error_bound_max")
_AUTO_EMPTY = {**{f"{who}_{what}": math.nan for who in ("auto", "fixed") for what in
                  ("gpu_ms", "wall_ms", "mib", "max_abs", "max_err", "max_err_all", "mean_err")},
               **dict.fromkeys(AUTO_STATS, math.nan), "within_t": None, "fixed_k": "",
               "gpu_ms_ratio": math.nan, "wall_ms_ratio": math.nan, "mib_ratio": math.nan}


def _measured(who: str, frame: Any, gpu: list[float], wall: list[float], exact: np.ndarray,
              covered: np.ndarray) -> dict[str, float]:
    e = image_errors(frame.image, exact, covered, flip=False)
    all_pixels = float(np.sqrt(((frame.image[..., :3].astype(np.float64) - exact[..., :3]) ** 2).sum(-1)).max())
    return {**{f"{who}_{k}": v for k, v in medians(gpu, wall).items()}, f"{who}_mib": frame.stats["memory_bytes"] / 2 ** 20,
            f"{who}_max_abs": max_abs_error(frame.image, exact), f"{who}_max_err": e["max_err"], f"{who}_max_err_all": all_pixels,
            f"{who}_mean_err": e["mean_err"]}


AUTO_COLUMNS = [
    ("scene", "{}"), ("size", "{}"), ("tolerance", "{:.5f}"), ("auto_k", "{:.0f}"), ("auto_mean_k", "{:.1f}"),
    ("auto_exact", "{:.0f}"), ("auto_moments", "{:.0f}"),
    ("auto_attempts", "{:.0f}"), ("auto_gpu_ms", "{:.1f}"), ("auto_wall_ms", "{:.1f}"), ("auto_mib", "{:.2f}"),
    ("auto_max_abs", "{:.5f}"), ("auto_max_err", "{:.5f}"), ("auto_max_err_all", "{:.5f}"), ("within_t", "{}"),
    ("fixed_k", "{}"),
    ("fixed_gpu_ms", "{:.1f}"), ("fixed_wall_ms", "{:.1f}"), ("fixed_mib", "{:.2f}"), ("fixed_max_abs", "{:.5f}"),
    ("gpu_ms_ratio", "{:.2f}"), ("wall_ms_ratio", "{:.2f}"), ("mib_ratio", "{:.2f}"),
]
