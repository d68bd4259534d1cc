"""`python -m oit bench --temporal`: how much each approximate method's image changes between
frames of a slow camera orbit, against the exact change."""

from __future__ import annotations

import math
from functools import partial
from typing import Any

import numpy as np

from .. import scenes as scene_lib
from .._api import Camera
from .._api import methods as list_methods
from .harness import Params, Progress, Result, format_params, image_errors, method_plan, scene_jobs

TEMPORAL_FRAMES = 8
TEMPORAL_STEP_DEG = 0.25


def orbit(built: scene_lib.BuiltScene, frames: int = TEMPORAL_FRAMES, step_deg: float = TEMPORAL_STEP_DEG) -> list[Camera]:
    """Cameras of a slow orbit: the scene's camera turned `step_deg` a frame about the vertical
    axis through the center of the geometry's bounding box (frame 0 is the scene's camera).
    The scene is turned the other way instead of moving the eye: view_proj @ T(c) R(-a) T(-c)."""
    points = np.concatenate([m.positions for m in built.drawn_meshes()]).astype(np.float64)
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
