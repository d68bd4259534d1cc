"""`python -m oit bench --antialias`: time and memory at S samples a pixel against one, and
the error against the exact antialiased image."""

from __future__ import annotations

import math
from functools import partial
from typing import Any

import numpy as np

from .._api import constants
from .._api import methods as list_methods
from .harness import Progress, Result, mean_rgb_distance, medians, scene_jobs, timed

AA_METHODS = ("abuffer", "hybrid", "hybrid64", "wboit", "unsorted")
AA_SAMPLES = (1, 4, 8)
# Methods and the sample count of antialias_mode="coverage", as the core declares them.
COVERAGE_METHODS = tuple(m["name"] for m in list_methods() if "coverage" in m["antialias_modes"])
COVERAGE_SAMPLES = constants()["COVERAGE_SAMPLES"]


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
                row.update(**medians(gpu, wall), mib=frame.stats["memory_bytes"] / 2 ** 20)
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
