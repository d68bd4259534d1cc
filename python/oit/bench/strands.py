"""`python -m oit bench --strands`: hair as a strand set (ribbons built on the GPU from the
points) against the same hair as triangle ribbons built on the CPU, at the same look
(`oit.scenes.hair(primitive=...)`): the bytes each uploads (and the strands' GPU bytes with their
corners), the time the upload takes, and the frame time of the floor and the methods over it,
as ratios of strands to ribbons in one run, the two rendered in turn; and the strands under a
camera that moves every frame, which builds their corners every frame (a still camera keeps
them)."""

from __future__ import annotations

import math
import statistics
import time
from functools import partial

import numpy as np

from .. import scenes as scene_lib
from .._api import Camera, Renderer
from .harness import QUICK_SIZE, Progress, Result, medians

STRAND_METHODS = ("unsorted", "hybrid64", "hybrid", "abuffer")
STRAND_COUNTS = (6000, 15000)
STRAND_COLUMNS = [("strands", "{}"), ("method", "{}"), ("ribbons_mib", "{:.2f}"), ("strands_mib", "{:.2f}"),
                  ("bytes_x", "{:.2f}"), ("strands_gpu_mib", "{:.2f}"), ("ribbons_upload_ms", "{:.1f}"),
                  ("strands_upload_ms", "{:.1f}"), ("ribbons_wall_ms", "{:.1f}"), ("strands_wall_ms", "{:.1f}"),
                  ("wall_x", "{:.2f}"), ("moving_wall_ms", "{:.1f}"), ("moving_x", "{:.2f}"), ("expand_ms", "{:.1f}"),
                  ("ribbons_gpu_ms", "{:.1f}"), ("strands_gpu_ms", "{:.1f}"), ("gpu_x", "{:.2f}")]
# How far the camera of the "moving" strands turns each frame.
TURN_DEGREES = 0.5
# Upload time is measured on frames this small, where the frame itself costs next to nothing.
UPLOAD_SIZE = 16


def _upload_ms(renderer: Renderer, build, repeat: int) -> float:
    """What the first render of a freshly built copy of the scene costs over a render of a scene
    already uploaded (the pipelines warm, a frame of UPLOAD_SIZE pixels a side): the upload,
    the median of `repeat` first renders less the median of `repeat` second renders (medians of
    each, not of their differences, which the frame's own noise can make negative). The second
    render turns the camera, so that both build the strands' corners."""
    warm = build()
    renderer.render(warm.scene, warm.camera, "unsorted")
    first, again = [], []
    for _ in range(repeat):
        copy = build()
        t0 = time.perf_counter()
        renderer.render(copy.scene, copy.camera, "unsorted")
        t1 = time.perf_counter()
        # A turned camera, so that strands build their corners in this frame too.
        renderer.render(copy.scene, _turned(copy.camera), "unsorted")
        first.append((t1 - t0) * 1e3)
        again.append((time.perf_counter() - t1) * 1e3)
    return statistics.median(first) - statistics.median(again)


def _turned(camera: Camera, degrees: float = TURN_DEGREES) -> Camera:
    """`camera` orbited by `degrees` about the world's y axis (the scene turned the other way)."""
    a = math.radians(degrees)
    turn = np.array([[math.cos(a), 0, math.sin(a), 0], [0, 1, 0, 0], [-math.sin(a), 0, math.cos(a), 0], [0, 0, 0, 1]])
    return Camera(np.asarray(camera.view_proj, np.float64) @ turn)


def _alternating(renderer: Renderer, built: dict, method: str, repeat: int) -> dict[str, tuple[float, float, dict]]:
    """Each primitive's median GPU and wall time of `method` and its last stats, the two scenes
    rendered in turn (after a warm-up each), so that drift in the machine's speed falls on both;
    and "moving": the strands under a camera that turns TURN_DEGREES every frame, so that each
    frame builds its corners again (a still camera keeps them; the CPU ribbons face one camera
    whatever it does)."""
    times: dict[str, tuple[list[float], list[float]]] = {p: ([], []) for p in (*built, "moving")}
    stats: dict[str, dict] = {}
    for b in built.values():
        renderer.render(b.scene, b.camera, method)
    # Neither is the still camera, whose corners the strands' own frames keep.
    cameras = (_turned(built["strands"].camera), _turned(built["strands"].camera, -TURN_DEGREES))
    for i in range(repeat):
        turns = [(p, b.scene, b.camera) for p, b in built.items()] + [("moving", built["strands"].scene, cameras[i % 2])]
        for p, scene, camera in turns:
            t0 = time.perf_counter()
            frame = renderer.render(scene, camera, method)
            times[p][1].append((time.perf_counter() - t0) * 1e3)
            if frame.stats.get("gpu_time_ms") is not None:
                times[p][0].append(frame.stats["gpu_time_ms"])
            stats[p] = frame.stats
    out = {}
    for p, (gpu, wall) in times.items():
        m = medians(gpu, wall)
        out[p] = (m["gpu_ms"], m["wall_ms"], stats[p])
    return out


def strands_vs_ribbons(counts: tuple[int, ...] = STRAND_COUNTS, methods: tuple[str, ...] = STRAND_METHODS,
                       repeat: int = 5, quick: bool = False, show_progress: bool = True) -> Result:
    """One row per strand count and method: both primitives' uploaded bytes (and the strands'
    GPU bytes, their corners included), upload time, and frame times (medians over `repeat`,
    the two rendered in turn), and strands over ribbons."""
    size = QUICK_SIZE if quick else 512
    counts = (300,) if quick else counts
    renderer, small = Renderer(size, size), Renderer(UPLOAD_SIZE, UPLOAD_SIZE)
    result = Result(rows=[], notes=[f"{size} x {size}; the same polylines, widths and colors drawn both ways; "
                                    f"uploads timed on {UPLOAD_SIZE} x {UPLOAD_SIZE} frames"])
    progress = Progress(len(counts) * (len(methods) + 2), show_progress)
    for n in counts:
        built = {p: scene_lib.hair(strands=n, primitive=p) for p in ("ribbons", "strands")}
        upload = {}
        for p in built:
            progress.show(f"hair {n} {p} upload")
            upload[p] = _upload_ms(small, partial(scene_lib.hair, strands=n, primitive=p), repeat)
            progress.step("upload")
        for m in methods:
            progress.show(f"hair {n} {m}")
            t = _alternating(renderer, built, m, repeat)
            row = {"strands": n, "method": m, "status": "ok", "message": "", "adapter": renderer.adapter_info["name"]}
            gpu, wall, stats = t.pop("moving")
            row.update({"moving_wall_ms": wall, "moving_x": wall / t["ribbons"][1],
                        "expand_ms": stats["pass_times_ms"].get("expand", math.nan)})
            for p, (gpu, wall, stats) in t.items():
                uploaded = stats["scene_bytes"] - stats["expanded_bytes"]
                row.update({f"{p}_mib": uploaded / 2**20, f"{p}_upload_ms": upload[p], f"{p}_wall_ms": wall, f"{p}_gpu_ms": gpu})
                if p == "strands":
                    row["strands_gpu_mib"] = stats["scene_bytes"] / 2**20
            row["bytes_x"] = row["ribbons_mib"] / row["strands_mib"]
            row["wall_x"] = row["strands_wall_ms"] / row["ribbons_wall_ms"]
            row["gpu_x"] = row["strands_gpu_ms"] / row["ribbons_gpu_ms"] if row["ribbons_gpu_ms"] else math.nan
            result.rows.append(row)
            progress.step(m)
    return result
