"""`oit.compare(scene, cameras)` and `python -m oit compare FILE`: the speed-accuracy trade on
the caller's own content. Every method at its defaults and over a small sweep of its main
parameter (`oit.methods()[i]["main"]`: k, nodes, layers, samples, buckets) renders every view;
each row gets its median time, its memory and its error against the exact frame (abuffer)
of each view. `Comparison.best` names the cheapest row that meets the limits. The bench's
harness (oit.bench.harness) times, measures and writes the tables; oit.plots draws."""

from __future__ import annotations

import html
import math
import os
import statistics
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import numpy as np

from ._api import Camera, Renderer, Scene, methods
from .bench.harness import INT_SWEEP, Params, Progress, flip_missing, format_params, image_errors, markdown, timed, write_csv

# The worst view's largest per-pixel RGB distance a row may have (the default --tolerance):
# about five 8-bit steps of one channel.
DEFAULT_TOLERANCE = 0.02
COLUMNS = [
    ("method", "{}"), ("params", "{}"), ("time_ms", "{:.3f}"), ("memory_mib", "{:.2f}"), ("peak_mib", "{:.2f}"),
    ("mean_err", "{:.5f}"), ("max_err", "{:.4f}"), ("flip", "{:.4f}"), ("tiles", "{:.0f}"), ("meets", "{}"),
]


def plan(names: Sequence[str] | None = None) -> list[tuple[str, Params]]:
    """(method, parameters) to run: each method (all, or those named) at its defaults, then its
    main parameter over INT_SWEEP within its range."""
    known = methods()
    if names is not None:
        unknown = sorted(set(names) - {m["name"] for m in known})
        if unknown:
            raise ValueError(f"unknown method(s) {', '.join(unknown)}; `python -m oit methods` lists them")
    runs = []
    for m in known:
        if names is not None and m["name"] not in names:
            continue
        defaults = {p["name"]: p["default"] for p in m["params"]}
        runs.append((m["name"], defaults))
        main = next((p for p in m["params"] if p["name"] == m["main"]), None)
        if main is not None:
            runs += [(m["name"], {**defaults, main["name"]: v}) for v in INT_SWEEP
                     if main["min"] <= v <= main["max"] and v != main["default"]]
    return runs


@dataclass
class Comparison:
    """One row per method and parameters (`rows`: time_ms the median over views of the GPU
    time, or of the wall time where the adapter has no timestamps; memory_bytes and
    peak_memory_bytes the largest over views; mean_err the mean and max_err the worst view's
    largest RGB distance to the exact frame over covered pixels; flip the mean FLIP), `images`
    (the first view: the exact frame and each method at its defaults, for the sheet) and the
    limits the comparison was asked for (`best()` with no arguments uses them)."""

    rows: list[dict]
    images: dict[str, np.ndarray] = field(default_factory=dict)
    tolerance: float = DEFAULT_TOLERANCE
    time_ms: float | None = None
    memory: int | None = None
    notes: list[str] = field(default_factory=list)

    def _limits(self, tolerance: float | None, time_ms: float | None, memory: int | None) -> tuple[float, float, float]:
        """The limits asked for, each falling back to the comparison's (no limit: inf)."""
        tol = self.tolerance if tolerance is None else tolerance
        budget = self.time_ms if time_ms is None else time_ms
        mem = self.memory if memory is None else memory
        return tol, math.inf if budget is None else budget, math.inf if mem is None else mem

    def misses(self, row: dict, tolerance: float | None = None, time_ms: float | None = None,
               memory: int | None = None) -> list[str]:
        """The limits `row` misses, each as 'what it has > the limit' (empty: it meets them all)."""
        tol, budget, mem = self._limits(tolerance, time_ms, memory)
        if row["status"] != "ok":
            return [f"failed: {row['message']}"]
        out = []
        if not row["max_err"] <= tol:
            out.append(f"max error {row['max_err']:.4g} > {tol:g}")
        if not row["time_ms"] <= budget:
            out.append(f"time {row['time_ms']:.3g} ms > {budget:g} ms")
        if not row["peak_memory_bytes"] <= mem:
            out.append(f"peak memory {row['peak_memory_bytes'] / 2**20:.3g} MiB > {mem / 2**20:.3g} MiB")
        return out

    def best(self, tolerance: float | None = None, time_ms: float | None = None, memory: int | None = None) -> dict | None:
        """The cheapest row that meets the limits: the least median time among the rows whose
        worst view's max error is at most `tolerance`, whose time is at most `time_ms` and whose
        peak memory at most `memory` bytes, ties broken by memory; None when no row does
        (`summary()` says which limit each missed). Defaults: the comparison's limits."""
        ok = [r for r in self.rows if not self.misses(r, tolerance, time_ms, memory)]
        return min(ok, key=lambda r: (r["time_ms"], r["peak_memory_bytes"])) if ok else None

    def summary(self, tolerance: float | None = None, time_ms: float | None = None, memory: int | None = None) -> str:
        """The recommendation in words: the best row, or that none meets the limits and why."""
        tol, budget, mem = self._limits(tolerance, time_ms, memory)
        limits = f"max error <= {tol:g}" + (f", time <= {budget:g} ms" if math.isfinite(budget) else "") \
            + (f", peak memory <= {mem / 2**20:.3g} MiB" if math.isfinite(mem) else "")
        b = self.best(tolerance, time_ms, memory)
        if b is not None:
            return (f"cheapest within {limits}: {b['method']} {b['params']}".rstrip() +
                    f" ({b['time_ms']:.3g} ms, peak memory {b['peak_memory_bytes'] / 2**20:.3g} MiB, max error {b['max_err']:.3g})")
        lines = [f"no method meets {limits}:"]
        lines += [f"  {r['method']} {r['params']}: {'; '.join(self.misses(r, tolerance, time_ms, memory))}" for r in self.rows]
        return "\n".join(lines)

    def markdown(self) -> str:
        return markdown(self.rows, COLUMNS)

    def _repr_html_(self) -> str:
        """The table and the recommendation, for Jupyter."""
        head = "".join(f"<th>{html.escape(c)}</th>" for c, _ in COLUMNS)
        cell = lambda v, f: "" if v is None or (isinstance(v, float) and math.isnan(v)) else html.escape(f.format(v))  # noqa: E731
        body = "".join("<tr>" + "".join(f"<td>{cell(r[c], f)}</td>" for c, f in COLUMNS) + "</tr>" for r in self.rows)
        return f"<p>{html.escape(self.summary())}</p><table><tr>{head}</tr>{body}</table>"

    def write(self, out: str, title: str = "comparison", plots: bool = True) -> list[str]:
        """compare.md (limits, notes, table, recommendation), compare.csv and, with matplotlib,
        tradeoff.png (error against time and memory, the Pareto front) and sheet.png (the first
        view's images and error heatmaps); returns the paths."""
        from . import plots as plot_lib

        os.makedirs(out, exist_ok=True)
        paths = [os.path.join(out, "compare.md"), os.path.join(out, "compare.csv")]
        notes = "".join(f"Note: {n}\n" for n in self.notes)
        with open(paths[0], "w") as f:
            f.write(f"# {title}\n\n{notes}\n{self.markdown()}\n\n{self.summary()}\n")
        write_csv(paths[1], self.rows)
        why = plot_lib.matplotlib_missing()
        if plots and why is None:
            paths.append(os.path.join(out, "tradeoff.png"))
            plot_lib.tradeoff(self.rows, title, paths[-1])
            if "abuffer" in self.images:
                paths.append(os.path.join(out, "sheet.png"))
                plot_lib.image_sheet(self.images, f"{title}: each method (default parameters) and its error", paths[-1])
        elif plots:
            self.notes.append(f"no plots: {why}")
        return paths


def compare(scene: Scene, cameras: Sequence[Camera], width: int = 256, height: int = 256,
            methods_: Sequence[str] | None = None, tolerance: float = DEFAULT_TOLERANCE, time_ms: float | None = None,
            memory: int | None = None, repeat: int = 1, flip: bool = True, show_progress: bool = False) -> Comparison:
    """Runs `plan(methods_)` on `scene` from every camera at width x height against the exact
    frames (abuffer). `memory` (bytes) limits peak memory: every row renders with that
    `memory_budget` (frames past it are tiled) and rows whose peak passes it miss the limit.
    `repeat` timed renders per view after a warm-up (the median is kept). See `Comparison`."""
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be an oit.Scene, got {type(scene).__name__}")
    cameras = list(cameras)
    if not cameras or not all(isinstance(c, Camera) for c in cameras):
        raise ValueError("cameras must be a non-empty list of oit.Camera (oit.views.orbit_cameras places some)")
    if not (isinstance(tolerance, (int, float)) and tolerance >= 0):
        raise ValueError(f"tolerance must be a number >= 0 (the worst view's max RGB distance), got {tolerance!r}")
    if time_ms is not None and not time_ms > 0:
        raise ValueError(f"time_ms must be positive, got {time_ms}")
    if memory is not None and (isinstance(memory, bool) or not isinstance(memory, int) or memory <= 0):
        raise ValueError(f"memory must be a positive number of bytes, got {memory!r}")
    runs = plan(methods_)
    renderer = Renderer(width, height, memory_budget=memory)
    progress = Progress(len(cameras) * (1 + len(runs)), show_progress)
    exact = []
    for i, camera in enumerate(cameras):
        progress.show(f"view {i} abuffer")
        exact.append(renderer.render(scene, camera, "abuffer"))
        progress.step("abuffer")
    result = Comparison(rows=[], tolerance=float(tolerance), time_ms=time_ms, memory=memory)
    result.images["abuffer"] = exact[0].image
    if flip and flip_missing() is not None:
        result.notes.append(flip_missing() or "")
        flip = False
    defaults = dict(reversed(runs))  # each method's first run: its defaults
    for method, params in runs:
        row = {"method": method, "params": format_params(params), "status": "ok", "message": "", "views": len(cameras)}
        times, errors, stats = [], [], []
        try:
            for i, (camera, ex) in enumerate(zip(cameras, exact)):
                progress.show(f"view {i} {method} {row['params']}")
                frame, gpu, wall = timed(partial(renderer.render, scene, camera, method, **params), repeat)
                errors.append(image_errors(frame.image, ex.image, ex.depth_complexity > 0, flip=flip))
                times.append(statistics.median(gpu) if gpu else statistics.median(wall))
                stats.append(frame.stats)
                if i == 0 and params == defaults[method]:
                    result.images[method] = frame.image
                progress.step(method)
        except (RuntimeError, MemoryError, ValueError) as e:
            row.update(status="failed", message=str(e).splitlines()[0])
            for _ in range(len(cameras) - len(stats)):
                progress.step(method)
        row.update(_measures(times, errors, stats))
        result.rows.append(row)
    for r in result.rows:
        r["meets"] = "yes" if not result.misses(r) else "no"
    return result


def _measures(times: list[float], errors: list[dict], stats: list[dict]) -> dict[str, Any]:
    """A row's figures over its views (NaN where none rendered)."""
    if not stats:
        figures = ("time_ms", "gpu_ms", "wall_ms", "memory_mib", "peak_mib", "mean_err", "max_err", "flip", "tiles")
        return {**dict.fromkeys(figures, math.nan), "memory_bytes": 0, "peak_memory_bytes": 0}
    peak = max(s["peak_memory_bytes"] for s in stats)
    gpu = [s["gpu_time_ms"] for s in stats if s.get("gpu_time_ms") is not None]
    return {
        "time_ms": statistics.median(times), "gpu_ms": statistics.median(gpu) if gpu else math.nan,
        "wall_ms": statistics.median(s["wall_time_ms"] for s in stats),
        "memory_bytes": max(s["memory_bytes"] for s in stats), "peak_memory_bytes": peak,
        "memory_mib": max(s["memory_bytes"] for s in stats) / 2**20, "peak_mib": peak / 2**20,
        "mean_err": float(np.mean([e["mean_err"] for e in errors])), "max_err": max(e["max_err"] for e in errors),
        "flip": float(np.mean([e["flip"] for e in errors])), "tiles": max(s["tiles"] for s in stats),
    }


# ---- the command line: `python -m oit compare FILE ...` (oit.cli adds and runs it)


def parse_bytes(text: str) -> int:
    """'64M', '1.5G', '512K' (powers of 1024) or a plain number of bytes."""
    import argparse

    scale = {"K": 2**10, "M": 2**20, "G": 2**30}.get(text[-1:].upper(), 1)
    try:
        value = float(text[:-1] if scale > 1 else text) * scale
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected bytes such as 64M, 1.5G or 1000000, got {text!r}") from None
    if not value >= 1:
        raise argparse.ArgumentTypeError(f"expected a positive memory size, got {text!r}")
    return int(value)


def add_arguments(p: Any) -> None:
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), default=(256, 256), help="frame size (default: 256 256)")
    p.add_argument("--views", type=int, default=None,
                   help="views around the scene (default: the file's cameras, else 3)")
    p.add_argument("--tolerance", type=float, default=DEFAULT_TOLERANCE,
                   help="the worst view's largest RGB distance to the exact frame a method may have (default: %(default)s)")
    p.add_argument("--time-ms", type=float, default=None, help="the median time a method may take (default: no limit)")
    p.add_argument("--memory", type=parse_bytes, default=None,
                   help="peak memory a method may hold, e.g. 64M; rows render with this memory_budget (default: no limit)")
    p.add_argument("--methods", nargs="+", default=None, help="methods to compare (default: every method)")
    p.add_argument("--repeat", type=int, default=1, help="timed renders per view after one warm-up (default: %(default)s)")
    p.add_argument("--out", default=None, help="directory for the table, plot and sheet (default: out/compare-<file stem>)")
    p.add_argument("--no-plots", action="store_true", help="skip the matplotlib plot and sheet")


def run_cli(args: Any, scene: Scene) -> int:
    """`compare` on the loaded `scene`: the progress bar on stderr, the table, the files written
    and the recommendation on stdout."""
    from .views import scene_views

    w, h = args.size
    if w <= 0 or h <= 0 or args.repeat <= 0 or (args.views is not None and args.views <= 0):
        raise ValueError("--size, --views and --repeat must be positive")
    cameras = scene_views(scene, args.views, aspect=w / h)
    result = compare(scene, cameras, w, h, args.methods, args.tolerance, args.time_ms, args.memory, args.repeat,
                     show_progress=True)
    out = args.out or os.path.join("out", f"compare-{os.path.splitext(os.path.basename(args.file))[0]}")
    title = f"{os.path.basename(args.file)}, {len(cameras)} views at {w} x {h}"
    paths = result.write(out, title, plots=not args.no_plots)
    for n in result.notes:
        print(f"note: {n}")
    print(result.markdown())
    print(f"wrote {', '.join(paths)}")
    print(result.summary())
    return 0
