"""`python -m oit bench`: time, memory and error of every method against the exact A-buffer
on the built-in scenes, with the floor (one plain blended pass over the same geometry,
`unsorted`) measured in the same run, so that times compare across machines as ratios.

Methods and their parameter values come from `oit.methods()` (a few values across each
declared range), so new methods join without changes here. A method that fails (an adapter
limit, a memory budget) gives a row marked failed with the message. With pygfx or VTK installed
the same scenes go through their modes too (oit.peers): pygfx's alpha modes, VTK's depth
peeling and plain blending. The rows go to results.csv and results.md (oit.bench.cli)."""

from __future__ import annotations

import math
import os
import statistics
from functools import partial
from typing import Any

import numpy as np

from .. import peers
from .. import scenes as scene_lib
from .._api import Renderer, memory_bytes
from .harness import (
    ERRORS,
    Params,
    Progress,
    Result,
    flip_missing,
    format_params,
    image_errors,
    medians,
    method_plan,
    scene_counts,
    scene_jobs,
    timed,
)

# Markdown columns and formats; every row field goes to the CSV.
COLUMNS = [
    ("scene", "{}"), ("size", "{}"), ("method", "{}"), ("params", "{}"), ("gpu_ms", "{:.2f}"), ("x_floor", "{:.2f}"),
    ("abuffer_speedup", "{:.2f}"), ("wall_ms", "{:.1f}"), ("wall_x_floor", "{:.2f}"), ("memory_mib", "{:.2f}"),
    ("mean_err", "{:.5f}"), ("mean_err_all", "{:.5f}"), ("max_err", "{:.4f}"), ("rmse", "{:.5f}"), ("psnr", "{:.1f}"),
    ("flip", "{:.4f}"), ("max_depth", "{}"), ("overflow", "{}"),
]


def _row(scene: str, size: str, method: str, params: Params, **values: Any) -> dict:
    row = {"scene": scene, "size": size, "method": method, "params": format_params(params),
           "status": "ok", "gpu_ms": math.nan, "wall_ms": math.nan, "memory_mib": math.nan, "formula_mib": math.nan,
           "fragments": math.nan, "max_depth": math.nan, "overflow": math.nan, **dict.fromkeys(ERRORS, math.nan),
           "adapter": "", "message": ""}
    row.update(values)
    # Other work on the machine skews times: the CSV keeps the 1-minute load average at each row.
    row["load_avg"] = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    return row


def run(scenes: list[str], methods: list[str] | None = None, sizes: list[int] | None = None, repeat: int = 5,
        quick: bool = False, with_peers: bool = True, show_progress: bool = True, defaults: bool = False) -> Result:
    """Measures every method of oit.methods() (or those named) on each scene at each size
    (default: the scene's own; --quick caps it at QUICK_SIZE), over a sweep of its parameters
    or, with `defaults` (and --quick), at its default parameters only."""
    plan = method_plan(methods, quick or defaults)
    result = Result(rows=[])
    peer_modes: list[tuple[str, str]] = []
    for library, (modes, missing, _) in peers.PEERS.items() if with_peers else ():
        reason = missing()
        if reason:
            result.notes.append(f"{library} rows are missing: {reason}")
        else:
            peer_modes += [(library, mode) for mode in modes]
    if flip_missing():
        result.notes.append(flip_missing())
    progress = Progress(len(scenes) * len(sizes or [None]) * (2 + len(plan) + len(peer_modes)), show_progress)
    for scene_name, built, renderer in scene_jobs(scenes, sizes, quick):
        _run_scene(result, scene_name, built, renderer, plan, peer_modes, repeat, progress)
    return result


def _run_scene(result: Result, scene_name: str, built: scene_lib.BuiltScene, renderer: Renderer,
               plan: list[tuple[str, Params, bool]], peer_modes: list[tuple[str, str]], repeat: int, progress: Progress) -> None:
    w, h = renderer.width, renderer.height
    size = f"{w}x{h}"
    adapter = renderer.adapter_info["name"]
    progress.show(f"{scene_name} {size} abuffer (reference)")
    try:
        exact_frame = renderer.render(built.scene, built.camera, "abuffer")
        exact, covered = exact_frame.image, exact_frame.depth_complexity > 0
    except (RuntimeError, MemoryError) as e:
        exact, covered = None, None
        result.notes.append(f"{scene_name} {size}: no errors, the exact A-buffer failed: {e}")
    progress.step(f"{scene_name} {size} floor")
    floor = {"gpu_ms": math.nan, "wall_ms": math.nan}
    try:
        _, floor_gpu, floor_wall = timed(lambda: renderer.render(built.scene, built.camera, "unsorted"), repeat)
        floor = {"gpu_ms": statistics.median(floor_gpu) if floor_gpu else math.nan, "wall_ms": statistics.median(floor_wall)}
    except RuntimeError as e:
        result.notes.append(f"{scene_name} {size}: no ratios to the floor, `unsorted` failed: {e}")
    progress.step(f"{scene_name} {size}")
    rows: list[dict] = []
    sheet = {} if exact is None else {"abuffer": exact}
    for method, params, is_default in plan:
        progress.show(f"{scene_name} {size} {method} {' '.join(map(str, params.values()))}")
        try:
            frame, gpu, wall = timed(partial(renderer.render, built.scene, built.camera, method, **params), repeat)
        except (RuntimeError, MemoryError, ValueError) as e:
            rows.append(_row(scene_name, size, method, params, status="failed", adapter=adapter, message=str(e).splitlines()[0]))
            progress.step(method)
            continue
        s = frame.stats
        formula = memory_bytes(method, w, h, **params)
        row = _row(scene_name, size, method, params, **medians(gpu, wall), memory_mib=s["memory_bytes"] / 2 ** 20,
                   formula_mib=math.nan if formula is None else formula / 2 ** 20,
                   **scene_counts(s, None if exact is None else exact_frame.stats), overflow=s["overflow_fragments"], adapter=adapter)
        if exact is not None:
            row.update(image_errors(frame.image, exact, covered))
            if is_default:
                sheet[method] = frame.image
        rows.append(row)
        progress.step(method)
    peer_exact, peer_covered = exact, covered
    if peer_modes and exact is not None and scene_lib.is_lit(built):
        # The peers draw vertex colors: their error is against the A-buffer of the same input.
        plain = scene_lib.unlit(built)
        frame = renderer.render(plain.scene, plain.camera, "abuffer")
        peer_exact, peer_covered = frame.image, frame.depth_complexity > 0
        result.notes.append(f"{scene_name} {size}: the peers draw the meshes unlit (vertex colors): their errors are "
                            "against the A-buffer of the same meshes unlit")
    for library, mode in peer_modes:
        progress.show(f"{scene_name} {size} {library} {mode}")
        rows.append(_peer_row(scene_name, built, w, h, library, mode, repeat, peer_exact, peer_covered, sheet))
        progress.step(f"{library} {mode}")
    for row in rows:
        row["x_floor"] = row["gpu_ms"] / floor["gpu_ms"]
        row["wall_x_floor"] = row["wall_ms"] / floor["wall_ms"]
    abuffer = next((r for r in rows if r["method"] == "abuffer" and r["status"] == "ok"), None)
    for row in rows:
        row["abuffer_speedup"] = abuffer["gpu_ms"] / row["gpu_ms"] if abuffer else math.nan
    result.rows += rows
    result.sheets[(scene_name, size)] = sheet


def _peer_row(scene_name: str, built: scene_lib.BuiltScene, w: int, h: int, library: str, mode: str, repeat: int,
              exact: np.ndarray | None, covered: np.ndarray | None, sheet: dict[str, np.ndarray]) -> dict:
    """One row for `library`'s `mode` (peers.PEERS): the median wall time of `repeat` renders
    after a warm-up, errors against the exact image; failed, with the message, when it raises."""
    label = f"{library}-{mode}"
    try:
        peer = peers.PEERS[library][2](w, h)
        peer.render(built, mode)  # warm-up: shaders and pipelines
        wall, image = [], None
        for _ in range(repeat):
            image, ms = peer.render(built, mode)
            wall.append(ms)
    except Exception as e:  # a third-party renderer fails in its own ways; the row says how
        return _row(scene_name, f"{w}x{h}", label, {}, status="failed", message=f"{type(e).__name__}: {e}".splitlines()[0])
    row = _row(scene_name, f"{w}x{h}", label, {}, wall_ms=statistics.median(wall), adapter=peer.adapter)
    if exact is not None:
        row.update(image_errors(image, exact, covered))
        sheet[label] = image
    return row
