"""`python -m oit bench --scale`: cost as the work grows, the hybrid paper's Figures 8 to 10 on
this engine. Three sweeps, each method at its default parameters at every point: the frame
size (hair, default strands), the triangle count (hair at 512 x 512, more strands) and the
depth complexity (per-pixel stacks at a small size, more layers). Each row has GPU and wall
time, memory (the method's and the peak), tiles, geometry chunks, fragments, depth and the
mean error against abuffer at the same point; `slopes` fits log(time) against log(x) per
method, so a slope of 1 is a cost linear in the work."""

from __future__ import annotations

import inspect
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any, Callable

import numpy as np

from .. import scenes as scene_lib
from .._api import Renderer
from .._api import methods as list_methods
from .harness import QUICK_SCENE_ARGS, Progress, Result, image_errors, markdown, medians, scene_counts, timed, write_csv, write_tables

SCALE_METHODS = ("unsorted", "abuffer", "hybrid", "hybrid64", "auto", "wboit", "stochastic")
SWEEPS = ("resolution", "triangles", "depth")
SCALE_SIZES = ((256, 256), (512, 512), (1024, 1024), (1920, 1080), (3840, 2160))
SCALE_STRANDS = (6000, 25000, 100000, 400000)  # 192 k to 12.8 M triangles
SCALE_LAYERS = (4, 40, 400, 4000)
TRIANGLES_SIZE = (512, 512)
DEPTH_SIZE = (64, 64)  # 4000 layers there are 16.4 M quads: the sweep's largest scene
# --quick: tiny values, a smoke test of the sweep's outputs (seconds), not a measurement.
QUICK_SIZES = ((16, 16), (32, 32), (64, 36))
QUICK_STRANDS = (150, 300, 600)
QUICK_LAYERS = (2, 4, 8, 16)
QUICK_TRIANGLES_SIZE = (32, 32)
QUICK_DEPTH_SIZE = (8, 8)
_HAIR = inspect.signature(scene_lib.hair).parameters
HAIR_TRIANGLES_PER_STRAND = 2 * _HAIR["segments"].default
X_NAMES = {"resolution": "pixels", "triangles": "triangles", "depth": "layers a pixel"}


@dataclass
class Point:
    """One point of a sweep: the swept quantity `x`, the frame size, and how to build the scene."""

    sweep: str
    scene: str
    x: int
    label: str
    size: tuple[int, int]
    build: Callable[[], scene_lib.BuiltScene]


def parse_size(text: str) -> tuple[int, int]:
    """'512' -> (512, 512); '1920x1080' -> (1920, 1080)."""
    w, _, h = text.lower().partition("x")
    try:
        size = (int(w), int(h or w))
    except ValueError:
        raise ValueError(f"a size is N or WxH (such as 512 or 1920x1080), got {text!r}") from None
    if min(size) <= 0:
        raise ValueError(f"a size must be positive, got {text!r}")
    return size


def points(sweeps: Sequence[str] = SWEEPS, sizes: Sequence[tuple[int, int]] | None = None,
           strands: Sequence[int] | None = None, layers: Sequence[int] | None = None, quick: bool = False) -> list[Point]:
    """The points of each sweep asked for, in order (defaults above; --quick's tiny ones)."""
    unknown = sorted(set(sweeps) - set(SWEEPS))
    if unknown:
        raise ValueError(f"unknown sweep(s) {', '.join(unknown)}; choose from {', '.join(SWEEPS)}")
    hair_strands = QUICK_SCENE_ARGS["hair"]["strands"] if quick else _HAIR["strands"].default
    out: list[Point] = []
    if "resolution" in sweeps:
        out += [Point("resolution", "hair", w * h, f"{w}x{h}", (w, h), partial(scene_lib.hair, strands=hair_strands))
                for w, h in sizes or (QUICK_SIZES if quick else SCALE_SIZES)]
    if "triangles" in sweeps:
        size = QUICK_TRIANGLES_SIZE if quick else TRIANGLES_SIZE
        out += [Point("triangles", "hair", n * HAIR_TRIANGLES_PER_STRAND, f"strands={n}", size,
                      partial(scene_lib.hair, strands=n)) for n in strands or (QUICK_STRANDS if quick else SCALE_STRANDS)]
    if "depth" in sweeps:
        size = QUICK_DEPTH_SIZE if quick else DEPTH_SIZE
        out += [Point("depth", "stacks", n, f"layers={n}", size, partial(scene_lib.stacks, layers=n, size=size))
                for n in layers or (QUICK_LAYERS if quick else SCALE_LAYERS)]
    return out


def _first_line(e: BaseException) -> str:
    return (str(e).splitlines() or [type(e).__name__])[0]


def _row(p: Point, method: str, **values: Any) -> dict:
    row = {"sweep": p.sweep, "scene": p.scene, "point": p.label, "x": p.x, "x_name": X_NAMES[p.sweep],
           "size": f"{p.size[0]}x{p.size[1]}", "triangles": math.nan, "method": method, "status": "ok",
           "gpu_ms": math.nan, "wall_ms": math.nan, "memory_mib": math.nan, "peak_mib": math.nan, "tiles": math.nan,
           "chunks": math.nan, "fragments": math.nan, "max_depth": math.nan, "mean_err": math.nan, "adapter": "",
           "message": ""}
    row.update(values)
    row["load_avg"] = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan  # other work skews times
    return row


def scale(sweeps: Sequence[str] = SWEEPS, methods: Sequence[str] | None = None,
          sizes: Sequence[tuple[int, int]] | None = None, strands: Sequence[int] | None = None,
          layers: Sequence[int] | None = None, repeat: int = 3, quick: bool = False, show_progress: bool = True) -> Result:
    """Every method (default SCALE_METHODS) at every point of the sweeps: the median GPU and
    wall time over `repeat` renders after a warm-up, and the frame's stats. abuffer runs first
    at each point, as the reference of the others' mean error (over covered pixels). A method
    that fails gives a failed row with the message; one the adapter lacks features for is
    skipped with a note."""
    methods = list(methods or SCALE_METHODS)
    unknown = sorted(set(methods) - {m["name"] for m in list_methods()})
    if unknown:
        raise ValueError(f"unknown method(s) {', '.join(unknown)}; `python -m oit methods` lists them")
    plan = points(sweeps, sizes, strands, layers, quick)
    result = Result(rows=[])
    probe = Renderer(1, 1).adapter_info
    for m in methods:
        if m not in probe["methods"]:
            result.notes.append(f"{m} skipped: {probe['name']} lacks the features it needs (`python -m oit methods`)")
    run = sorted((m for m in methods if m in probe["methods"]), key=lambda m: m != "abuffer")  # the reference first
    progress = Progress(len(plan) * len(run), show_progress)
    renderer: Renderer | None = None
    for p in plan:
        progress.show(f"{p.sweep} {p.label}: building")
        try:
            built = p.build()
            if renderer is None or (renderer.width, renderer.height) != p.size:
                renderer = None  # its buffers go before the next size's
                renderer = Renderer(*p.size)
        except (MemoryError, RuntimeError, ValueError) as e:
            for m in run:
                result.rows.append(_row(p, m, status="failed", message=f"no scene or renderer: {_first_line(e)}"))
                progress.step(m)
            continue
        triangles = built.scene.triangle_count
        exact = None
        for m in run:
            progress.show(f"{p.sweep} {p.label} {m}")
            try:
                frame, gpu, wall = timed(partial(renderer.render, built.scene, built.camera, m), repeat)
            except (MemoryError, RuntimeError, ValueError) as e:
                result.rows.append(_row(p, m, triangles=triangles, status="failed", adapter=probe["name"],
                                        message=_first_line(e)))
                progress.step(m)
                continue
            s = frame.stats
            if m == "abuffer":
                exact = frame
            row = _row(p, m, triangles=triangles, **medians(gpu, wall), memory_mib=s["memory_bytes"] / 2 ** 20,
                       peak_mib=s["peak_memory_bytes"] / 2 ** 20, tiles=s["tiles"], chunks=s["geometry_chunks"],
                       **scene_counts(s, None if exact is None else exact.stats), adapter=s["adapter"])
            if exact is not None:
                row["mean_err"] = image_errors(frame.image, exact.image, exact.depth_complexity > 0, flip=False)["mean_err"]
            result.rows.append(row)
            progress.step(m)
        del built, exact  # the largest scenes hold gigabytes
    return result


def fit_slope(xs: Sequence[float], ys: Sequence[float]) -> float:
    """Least-squares slope of log(y) against log(x) over the points with both positive and
    finite; NaN with fewer than two distinct x."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if 0 < x < math.inf and 0 < y < math.inf]
    if len({x for x, _ in pts}) < 2:
        return math.nan
    lx, ly = np.array(pts).T
    return float(np.polyfit(lx, ly, 1)[0])


def slopes(rows: list[dict]) -> list[dict]:
    """Per sweep and method: the fitted slope of GPU time (`slope`) and of wall time
    (`wall_slope`) against x over its successful points (`points`: those with a GPU time)."""
    out = []
    for sweep, method in dict.fromkeys((r["sweep"], r["method"]) for r in rows):
        ok = [r for r in rows if (r["sweep"], r["method"]) == (sweep, method) and r["status"] == "ok"]
        timed_ok = [r for r in ok if 0 < r["gpu_ms"] < math.inf]
        out.append({"sweep": sweep, "scene": ok[0]["scene"] if ok else "", "method": method, "points": len(timed_ok),
                    "x_name": X_NAMES[sweep], "slope": fit_slope([r["x"] for r in ok], [r["gpu_ms"] for r in ok]),
                    "wall_slope": fit_slope([r["x"] for r in ok], [r["wall_ms"] for r in ok]), "status": "ok", "message": ""})
    return out


SCALE_COLUMNS = [
    ("sweep", "{}"), ("scene", "{}"), ("point", "{}"), ("x", "{}"), ("method", "{}"), ("gpu_ms", "{:.2f}"),
    ("wall_ms", "{:.1f}"), ("memory_mib", "{:.2f}"), ("peak_mib", "{:.2f}"), ("tiles", "{}"), ("chunks", "{}"),
    ("fragments", "{}"), ("max_depth", "{}"), ("mean_err", "{:.5f}"),
]
SLOPE_COLUMNS = [("sweep", "{}"), ("x_name", "{}"), ("method", "{}"), ("points", "{}"), ("slope", "{:.2f}"),
                 ("wall_slope", "{:.2f}")]
SLOPE_NOTE = ("slope: the least-squares slope of log(GPU time) against log(x) over a method's successful points "
              "(wall_slope: of wall time); 1 is a cost linear in x, 0 a cost that does not grow.")


def write_scale(out: str, result: Result) -> list[dict]:
    """scale.csv and scale.md (write_tables), then the slopes: scale-slopes.csv and a section
    of scale.md; returns the slope rows."""
    write_tables(out, "scale", result, SCALE_COLUMNS)
    fits = slopes(result.rows)
    write_csv(os.path.join(out, "scale-slopes.csv"), fits)
    table = markdown(fits, SLOPE_COLUMNS)
    with open(os.path.join(out, "scale.md"), "a") as f:
        f.write(f"\n## Slopes\n\n{SLOPE_NOTE}\n\n{table}\n")
    print(f"\n{SLOPE_NOTE}\n{table}")
    return fits
