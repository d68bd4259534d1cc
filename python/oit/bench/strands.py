"""`python -m oit bench --strands`: hair as a strand set (ribbons built on the GPU from the
points) against the same hair as triangle ribbons built on the CPU, at the same look
(`oit.scenes.hair(primitive=...)`): the bytes each uploads, the time the upload takes, and the
frame time of the floor and the methods over it, as ratios of strands to ribbons in one run."""

from __future__ import annotations

import math
import statistics
import time
from functools import partial

from .. import scenes as scene_lib
from .._api import Renderer
from .harness import QUICK_SIZE, Progress, Result, medians, timed

STRAND_METHODS = ("unsorted", "hybrid64", "hybrid", "abuffer")
STRAND_COUNTS = (6000, 15000)
STRAND_COLUMNS = [("strands", "{}"), ("method", "{}"), ("ribbons_mib", "{:.2f}"), ("strands_mib", "{:.2f}"),
                  ("bytes_x", "{:.2f}"), ("ribbons_upload_ms", "{:.1f}"), ("strands_upload_ms", "{:.1f}"),
                  ("ribbons_wall_ms", "{:.1f}"), ("strands_wall_ms", "{:.1f}"), ("wall_x", "{:.2f}"),
                  ("ribbons_gpu_ms", "{:.1f}"), ("strands_gpu_ms", "{:.1f}"), ("gpu_x", "{:.2f}")]


def _upload_ms(renderer: Renderer, build, repeat: int) -> float:
    """The wall time a first render of a freshly built copy of the scene adds over a render of
    one already uploaded (the pipelines warm): the upload, median over `repeat` copies."""
    built = build()
    _, _, warm = timed(partial(renderer.render, built.scene, built.camera, "unsorted"), repeat)
    extra = []
    for _ in range(repeat):
        copy = build()
        t0 = time.perf_counter()
        renderer.render(copy.scene, copy.camera, "unsorted")
        extra.append((time.perf_counter() - t0) * 1e3 - statistics.median(warm))
    return statistics.median(extra)


def strands_vs_ribbons(counts: tuple[int, ...] = STRAND_COUNTS, methods: tuple[str, ...] = STRAND_METHODS,
                       repeat: int = 5, quick: bool = False, show_progress: bool = True) -> Result:
    """One row per strand count and method: both primitives' scene bytes, upload time and frame
    times (median over `repeat` after a warm-up), and strands over ribbons."""
    size = QUICK_SIZE if quick else 512
    counts = (300,) if quick else counts
    renderer = Renderer(size, size)
    result = Result(rows=[], notes=[f"{size} x {size}; the same polylines, widths and colors drawn both ways"])
    progress = Progress(len(counts) * (len(methods) + 1) * 2, show_progress)
    for n in counts:
        row_of = {m: {"strands": n, "method": m, "status": "ok", "message": "", "adapter": renderer.adapter_info["name"]}
                  for m in methods}
        for primitive in ("ribbons", "strands"):
            build = partial(scene_lib.hair, strands=n, primitive=primitive)
            progress.show(f"hair {n} {primitive} upload")
            upload = _upload_ms(renderer, build, repeat)
            progress.step("upload")
            built = build()
            for m in methods:
                progress.show(f"hair {n} {primitive} {m}")
                frame, gpu, wall = timed(partial(renderer.render, built.scene, built.camera, m), repeat)
                t = medians(gpu, wall)
                row_of[m].update({f"{primitive}_mib": frame.stats["scene_bytes"] / 2**20, f"{primitive}_upload_ms": upload,
                                  f"{primitive}_wall_ms": t["wall_ms"], f"{primitive}_gpu_ms": t["gpu_ms"]})
                progress.step(m)
        for row in row_of.values():
            row["bytes_x"] = row["ribbons_mib"] / row["strands_mib"]
            row["wall_x"] = row["strands_wall_ms"] / row["ribbons_wall_ms"]
            ratio = row["strands_gpu_ms"] / row["ribbons_gpu_ms"] if row["ribbons_gpu_ms"] else math.nan
            row["gpu_x"] = ratio
            result.rows.append(row)
    return result
