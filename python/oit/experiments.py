"""The bench's three experiments besides the sweep (`python -m oit bench --temporal`,
`--auto`, `--antialias`): how much each approximate method's image changes between frames of
a slow camera orbit against the exact change (`temporal`); auto at a tolerance against the
cheapest fixed k that meets it, found by search (`auto_vs_fixed`); time and memory at S
samples a pixel against one (`antialias`). They share oit.bench's timing, scenes, errors and
tables."""

from __future__ import annotations

import math
import os
import statistics
from functools import partial
from typing import Any, Callable

import numpy as np

from . import scenes as scene_lib
from ._api import Camera
from ._api import methods as list_methods
from .bench import Params, Progress, Result, format_params, image_errors, mean_rgb_distance, method_plan, scene_jobs, timed

# ---- temporal stability: a slow camera orbit, each method's change between frames against abuffer's

TEMPORAL_FRAMES = 8
TEMPORAL_STEP_DEG = 0.25


def orbit(built: scene_lib.BuiltScene, frames: int = TEMPORAL_FRAMES, step_deg: float = TEMPORAL_STEP_DEG) -> list[Camera]:
    """Cameras of a slow orbit: the scene's camera turned `step_deg` a frame about the vertical
    axis through the center of the geometry's bounding box (frame 0 is the scene's camera).
    The scene is turned the other way instead of moving the eye: view_proj @ T(c) R(-a) T(-c)."""
    points = np.concatenate([m.positions for m in built.meshes]).astype(np.float64)
    center = (points.min(0) + points.max(0)) / 2
    cameras = []
    for i in range(frames):
        a = -math.radians(step_deg * i)
        turn = np.eye(4)
        turn[0, 0], turn[0, 2], turn[2, 0], turn[2, 2] = math.cos(a), math.sin(a), -math.sin(a), math.cos(a)
        to, back = np.eye(4), np.eye(4)
        to[:3, 3], back[:3, 3] = center, -center
        cameras.append(Camera(built.camera.view_proj @ to @ turn @ back))
    return cameras


def frame_changes(images: list[np.ndarray], exact: list[np.ndarray], covered: list[np.ndarray]) -> dict[str, float]:
    """How a method's frames change against the exact frames', over the pixels covered in
    either frame of each consecutive pair (all pairs pooled): `change`, the mean RGB distance
    between consecutive frames; `flicker`, the mean RGB distance between the method's change
    and the exact change, (m' - m) - (a' - a), which is the frame-to-frame change of its error:
    the part that is not the true motion; `max_flicker`, its largest value."""
    changes, flickers = [], []
    for t in range(len(images) - 1):
        mask = covered[t] | covered[t + 1]
        dm = images[t + 1][..., :3].astype(np.float64) - images[t][..., :3]
        da = exact[t + 1][..., :3].astype(np.float64) - exact[t][..., :3]
        changes.append(np.sqrt((dm[mask] ** 2).sum(-1)))
        flickers.append(np.sqrt(((dm - da)[mask] ** 2).sum(-1)))
    change, flicker = np.concatenate(changes), np.concatenate(flickers)
    if not change.size:
        return {"change": math.nan, "flicker": math.nan, "max_flicker": math.nan}
    return {"change": float(change.mean()), "flicker": float(flicker.mean()), "max_flicker": float(flicker.max())}


def temporal(scenes: list[str], methods: list[str] | None = None, sizes: list[int] | None = None,
             frames: int = TEMPORAL_FRAMES, step_deg: float = TEMPORAL_STEP_DEG, quick: bool = False,
             show_progress: bool = True) -> Result:
    """The temporal-stability benchmark: each scene over a slow orbit (`orbit`), abuffer and
    every approximate method (or those named) at its default parameters; one row per method
    with frame_changes, `change_ratio` and `flicker_ratio` (over abuffer's change) and
    `mean_err` (against abuffer, averaged over the frames)."""
    if frames < 2:
        raise ValueError(f"the temporal benchmark needs at least 2 frames, got {frames}")
    approximate = [m["name"] for m in list_methods() if not m["exact"]]
    plan = [(m, p) for m, p, _ in method_plan(methods or approximate, quick=True) if m != "abuffer"]
    result = Result(rows=[])
    progress = Progress(len(scenes) * len(sizes or [None]) * (1 + len(plan)), show_progress)
    for scene_name, built, renderer in scene_jobs(scenes, sizes, quick):
        size, adapter = f"{renderer.width}x{renderer.height}", renderer.adapter_info["name"]
        cameras = orbit(built, frames, step_deg)
        row = partial(_temporal_row, scene_name, size, frames=frames, step_deg=step_deg, adapter=adapter)
        progress.show(f"{scene_name} {size} abuffer")
        try:
            exact_frames = [renderer.render(built.scene, c, "abuffer") for c in cameras]
        except (RuntimeError, MemoryError) as e:
            result.notes.append(f"{scene_name} {size}: no temporal rows, the exact A-buffer failed: {e}")
            progress.step("abuffer")
            continue
        exact = [f.image for f in exact_frames]
        covered = [f.depth_complexity > 0 for f in exact_frames]
        reference = frame_changes(exact, exact, covered)
        rows = [row("abuffer", {}, **reference, mean_err=0.0)]
        progress.step("abuffer")
        for method, params in plan:
            progress.show(f"{scene_name} {size} {method}")
            try:
                images = [renderer.render(built.scene, c, method, **params).image for c in cameras]
            except (RuntimeError, MemoryError, ValueError) as e:
                rows.append(row(method, params, status="failed", message=str(e).splitlines()[0]))
                progress.step(method)
                continue
            err = [image_errors(im, ex, cov, flip=False)["mean_err"] for im, ex, cov in zip(images, exact, covered)]
            rows.append(row(method, params, **frame_changes(images, exact, covered), mean_err=float(np.mean(err))))
            progress.step(method)
        for r in rows:  # a still camera (step 0) leaves abuffer's change 0: no ratios
            scale = reference["change"] if reference["change"] > 0 else math.nan
            r["change_ratio"], r["flicker_ratio"] = r["change"] / scale, r["flicker"] / scale
        result.rows += rows
    return result


def _temporal_row(scene: str, size: str, method: str, params: Params, frames: int, step_deg: float, adapter: str,
                  **values: Any) -> dict:
    row = {"scene": scene, "size": size, "method": method, "params": format_params(params), "status": "ok",
           "frames": frames, "step_deg": step_deg, "change": math.nan, "change_ratio": math.nan, "flicker": math.nan,
           "flicker_ratio": math.nan, "max_flicker": math.nan, "mean_err": math.nan, "adapter": adapter, "message": ""}
    row.update(values)
    return row


TEMPORAL_COLUMNS = [
    ("scene", "{}"), ("size", "{}"), ("method", "{}"), ("params", "{}"), ("change", "{:.5f}"),
    ("change_ratio", "{:.3f}"), ("flicker", "{:.5f}"), ("flicker_ratio", "{:.3f}"), ("max_flicker", "{:.4f}"),
    ("mean_err", "{:.5f}"),
]


# ---- accuracy on demand: auto against the cheapest fixed k that meets the same tolerance

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
                row.update({key: frame.stats.get(key, math.nan) for key in AUTO_STATS})
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
AUTO_STATS = ("auto_k", "auto_mean_k", "auto_slots", "auto_predicted_k", "auto_exact", "auto_attempts", "error_bound_max")
_AUTO_EMPTY = {**{f"{who}_{what}": math.nan for who in ("auto", "fixed") for what in
                  ("gpu_ms", "wall_ms", "mib", "max_abs", "max_err", "max_err_all", "mean_err")},
               **dict.fromkeys(AUTO_STATS, math.nan), "within_t": None, "fixed_k": "",
               "gpu_ms_ratio": math.nan, "wall_ms_ratio": math.nan, "mib_ratio": math.nan}


def _measured(who: str, frame: Any, gpu: list[float], wall: list[float], exact: np.ndarray,
              covered: np.ndarray) -> dict[str, float]:
    e = image_errors(frame.image, exact, covered, flip=False)
    all_pixels = float(np.sqrt(((frame.image[..., :3].astype(np.float64) - exact[..., :3]) ** 2).sum(-1)).max())
    return {f"{who}_gpu_ms": statistics.median(gpu) if gpu else math.nan, f"{who}_wall_ms": statistics.median(wall),
            f"{who}_mib": frame.stats["memory_bytes"] / 2 ** 20, f"{who}_max_abs": max_abs_error(frame.image, exact),
            f"{who}_max_err": e["max_err"], f"{who}_max_err_all": all_pixels, f"{who}_mean_err": e["mean_err"]}


AUTO_COLUMNS = [
    ("scene", "{}"), ("size", "{}"), ("tolerance", "{:.5f}"), ("auto_k", "{:.0f}"), ("auto_mean_k", "{:.1f}"),
    ("auto_exact", "{:.0f}"),
    ("auto_attempts", "{:.0f}"), ("auto_gpu_ms", "{:.1f}"), ("auto_wall_ms", "{:.1f}"), ("auto_mib", "{:.2f}"),
    ("auto_max_abs", "{:.5f}"), ("auto_max_err", "{:.5f}"), ("auto_max_err_all", "{:.5f}"), ("within_t", "{}"),
    ("fixed_k", "{}"),
    ("fixed_gpu_ms", "{:.1f}"), ("fixed_wall_ms", "{:.1f}"), ("fixed_mib", "{:.2f}"), ("fixed_max_abs", "{:.5f}"),
    ("gpu_ms_ratio", "{:.2f}"), ("wall_ms_ratio", "{:.2f}"), ("mib_ratio", "{:.2f}"),
]


# ---- antialiasing: time and memory of S samples a pixel against one, error against the exact
# antialiased image

AA_METHODS = ("abuffer", "hybrid", "hybrid64", "wboit", "unsorted")
AA_SAMPLES = (1, 4, 8)
# Methods and the sample count of antialias_mode="coverage" (oit_core::renderer).
COVERAGE_METHODS = ("abuffer",)
COVERAGE_SAMPLES = 4


def antialias(scenes: list[str], methods: list[str] | None = None, sizes: list[int] | None = None,
              samples: tuple[int, ...] = AA_SAMPLES, repeat: int = 5, quick: bool = False,
              show_progress: bool = True) -> Result:
    """For each scene, method (default AA_METHODS) and sample count S: GPU and wall time (median
    over `repeat` after a warm-up) and memory, as ratios to the same method at one sample;
    the mean and largest error against abuffer at the same S (the method's own error), and the
    mean error against abuffer at the largest S asked for (what is left of the aliasing). The
    COVERAGE_METHODS also get a row in antialias_mode "coverage" at COVERAGE_SAMPLES."""
    methods = list(methods or AA_METHODS)
    samples = tuple(sorted(set(samples) | {1}))
    result = Result(rows=[])
    progress = Progress(len(scenes) * len(sizes or [None]) * len(samples) * (1 + len(methods)), show_progress)
    for scene_name, built, renderer in scene_jobs(scenes, sizes, quick):
        size, adapter = f"{renderer.width}x{renderer.height}", renderer.adapter_info["name"]
        exact: dict[int, Any] = {}
        for s_count in samples:
            progress.show(f"{scene_name} {size} abuffer x{s_count}")
            try:
                exact[s_count] = renderer.render(built.scene, built.camera, "abuffer", antialias=s_count)
            except (RuntimeError, MemoryError) as e:
                result.notes.append(f"{scene_name} {size}: no errors at {s_count} samples, abuffer failed: {e}")
            progress.step("abuffer")
        finest = exact.get(max(samples))
        for method in methods:
            one: dict[str, float] = {}
            runs = [(s_count, "frames") for s_count in samples]
            if method in COVERAGE_METHODS and COVERAGE_SAMPLES in samples:
                runs.append((COVERAGE_SAMPLES, "coverage"))
            for s_count, mode in runs:
                row = {"scene": scene_name, "size": size, "method": method, "antialias": s_count, "mode": mode,
                       "status": "ok", "adapter": adapter, "message": "", **{c: math.nan for c, _ in AA_COLUMNS[5:]}}
                progress.show(f"{scene_name} {size} {method} x{s_count} {mode}")
                try:
                    frame, gpu, wall = timed(partial(renderer.render, built.scene, built.camera, method, antialias=s_count,
                                                   antialias_mode=mode), repeat)
                except (RuntimeError, MemoryError, ValueError) as e:
                    row.update(status="failed", message=str(e).splitlines()[0])
                    result.rows.append(row)
                    progress.step(method)
                    continue
                row.update(gpu_ms=statistics.median(gpu) if gpu else math.nan, wall_ms=statistics.median(wall),
                           mib=frame.stats["memory_bytes"] / 2 ** 20)
                if s_count == 1:
                    one = {k: row[k] for k in ("gpu_ms", "wall_ms", "mib")}
                for k in ("gpu_ms", "wall_ms", "mib"):
                    row[f"{k}_x1"] = row[k] / one[k] if one.get(k) else math.nan
                if s_count in exact:
                    diff = frame.image[..., :3].astype(np.float64) - exact[s_count].image[..., :3]
                    row["mean_err"] = float(np.sqrt((diff ** 2).sum(-1)).mean())
                    row["max_abs"] = float(np.abs(diff).max())
                if finest is not None:
                    row["mean_err_vs_finest"] = mean_rgb_distance(frame.image, finest.image)
                result.rows.append(row)
                progress.step(method)
    return result


AA_COLUMNS = [
    ("scene", "{}"), ("size", "{}"), ("method", "{}"), ("antialias", "{}"), ("mode", "{}"), ("gpu_ms", "{:.1f}"),
    ("gpu_ms_x1", "{:.2f}"),
    ("wall_ms", "{:.1f}"), ("wall_ms_x1", "{:.2f}"), ("mib", "{:.2f}"), ("mib_x1", "{:.2f}"), ("mean_err", "{:.5f}"),
    ("max_abs", "{:.5f}"), ("mean_err_vs_finest", "{:.5f}"),
]
