"""The bench's harness, under the main sweep (oit.bench.results) and every experiment: what
runs (each method's parameter sets, the scenes at their sizes), timing, the progress line,
errors against the exact image, and the tables (CSV and Markdown). It imports nothing of
oit.bench."""

from __future__ import annotations

import csv
import inspect
import itertools
import math
import os
import statistics
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from .. import scenes as scene_lib
from .._api import Renderer
from .._api import methods as list_methods
from ..imageio import linear_to_srgb

# Values tried for integer parameters (k, nodes, samples, layers), clipped to the declared range.
INT_SWEEP = (1, 2, 4, 8, 16, 32)
QUICK_SIZE = 64  # --quick caps frames at this size: a smoke test of the bench, not a measurement
# --quick also thins the scenes: depth peeling costs a geometry pass per layer, so a full hair
# (192,000 triangles, 340 layers) takes 25 s even at 64 x 64 on lavapipe.
QUICK_SCENE_ARGS: dict[str, dict[str, Any]] = {
    "hair": {"strands": 600}, "smoke": {"particles": 150}, "foliage": {"leaves": 1500}, "dragons": {"max_triangles": 800},
    "splats": {"count": 2000}, "splat_cloud": {"count": 2000},
}
# Parameters that choose a random stream rather than a point on the speed-accuracy trade.
HELD_AT_DEFAULT = ("seed",)
ERRORS = ("mean_err", "mean_err_all", "max_err", "rmse", "psnr", "flip")
Params = dict[str, Any]


def sweep(method: dict, quick: bool = False) -> list[Params]:
    """Parameter sets to run for one entry of oit.methods(): each parameter varied alone over
    its range, the others at their defaults (ints: INT_SWEEP within [min, max]; choices: all;
    floats: min and max), always including the default. --quick runs the defaults only."""
    defaults = {p["name"]: p["default"] for p in method["params"]}
    if quick or not method["params"]:
        return [defaults]
    runs: list[Params] = []
    for p in method["params"]:
        if p["name"] in HELD_AT_DEFAULT:
            continue
        if p["type"] == "choice":
            values = list(p["choices"])
        elif p["type"] == "int":
            values = sorted({v for v in INT_SWEEP if p["min"] <= v <= p["max"] and (v - p["min"]) % p.get("step", 1) == 0}
                            | {p["default"]})
        else:
            values = sorted({p["min"], p["default"], p["max"]})
        runs += [run for run in ({**defaults, p["name"]: v} for v in values) if run not in runs]
    return runs


def _build(name: str, size: int | None, quick: bool) -> scene_lib.BuiltScene:
    """Builds a scene (thinned for --quick); one whose geometry depends on the frame (stacks:
    one stack per pixel) is built for the size."""
    builder = scene_lib.SCENES[name]
    kwargs = dict(QUICK_SCENE_ARGS.get(name, {})) if quick else {}
    if size and "size" in inspect.signature(builder).parameters:
        kwargs["size"] = (size, size)
    return builder(**kwargs)


def method_plan(methods: list[str] | None = None, quick: bool = False) -> list[tuple[str, Params, bool]]:
    """What the bench runs on each scene: (method, parameters, whether they are the method's
    defaults: those rows go on the image sheet) for every method of oit.methods() or those
    named, in that order."""
    known = list_methods()
    if methods is not None:
        unknown = sorted(set(methods) - {m["name"] for m in known})
        if unknown:
            raise ValueError(f"unknown method(s) {', '.join(unknown)}; `python -m oit methods` lists them")
    infos = [m for m in known if methods is None or m["name"] in methods]
    return [(m["name"], p, p == sweep(m, quick=True)[0]) for m in infos for p in sweep(m, quick)]


def scene_jobs(scenes: list[str], sizes: list[int] | None, quick: bool) -> Iterator[tuple[str, scene_lib.BuiltScene, Renderer]]:
    """(name, built scene, renderer) for each scene at each size (default: the scene's own;
    --quick caps it at QUICK_SIZE), with one renderer per size: pipelines compile once."""
    renderers: dict[tuple[int, int], Renderer] = {}
    for scene_name in scenes:
        for size in sizes or [None]:
            built = _build(scene_name, size, quick)
            w, h = (size, size) if size else built.size
            if quick:
                w, h = min(w, QUICK_SIZE), min(h, QUICK_SIZE)
            if (w, h) not in renderers:
                renderers[(w, h)] = Renderer(w, h)
            yield scene_name, built, renderers[(w, h)]


def flip_missing() -> str | None:
    """Why mean FLIP cannot be computed here, or None when it can."""
    try:
        import flip_evaluator  # noqa: F401
    except ImportError as e:
        return f"the flip column is empty: flip-evaluator is not installed ({e}); `pip install flip-evaluator` adds it"
    return None


def image_errors(image: np.ndarray, exact: np.ndarray, covered: np.ndarray, flip: bool = True) -> dict[str, float]:
    """Errors of `image` against `exact` (both linear): the per-pixel RGB distance (the hybrid
    paper's measure) averaged (`mean_err`) and maximized (`max_err`) over the pixels with at
    least one transparent fragment (`covered`), its mean over every pixel (`mean_err_all`),
    RMSE over channels of covered pixels, PSNR (peak 1), and the mean FLIP of the sRGB-encoded
    images over the whole frame (NaN without flip-evaluator)."""
    d = image[..., :3].astype(np.float64) - exact[..., :3].astype(np.float64)
    full = np.sqrt((d ** 2).sum(-1))
    out = {"mean_err": 0.0, "mean_err_all": float(full.mean()), "max_err": 0.0, "rmse": 0.0, "psnr": math.inf}
    if covered.any():
        rmse = float(np.sqrt((d[covered] ** 2).mean()))
        out.update(mean_err=float(full[covered].mean()), max_err=float(full[covered].max()), rmse=rmse,
                   psnr=math.inf if rmse == 0 else float(20 * np.log10(1.0 / rmse)))
    out["flip"] = flip_error(image, exact) if flip and flip_missing() is None else math.nan
    return out


def flip_error(image: np.ndarray, exact: np.ndarray) -> float:
    """Mean FLIP (LDR) of the two images, sRGB-encoded as a display would show them."""
    import flip_evaluator

    srgb = lambda a: np.ascontiguousarray(linear_to_srgb(a[..., :3]), dtype=np.float32)  # noqa: E731
    return float(flip_evaluator.evaluate(srgb(exact), srgb(image), "LDR", inputsRGB=True, applyMagma=False)[1])


def timed(render: Callable[[], Any], repeat: int) -> tuple[Any, list[float], list[float]]:
    """Renders once to warm up (pipelines, pool sizes), then `repeat` times; returns the last
    frame, the GPU times (where the adapter has timestamps) and the wall times in ms."""
    frame = render()
    gpu, wall = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        frame = render()
        wall.append((time.perf_counter() - t0) * 1e3)
        if frame.stats.get("gpu_time_ms") is not None:
            gpu.append(frame.stats["gpu_time_ms"])
    return frame, gpu, wall


def medians(gpu: list[float], wall: list[float]) -> dict[str, float]:
    """`timed`'s GPU and wall times as their medians, `gpu_ms` and `wall_ms` (gpu_ms NaN where
    the adapter has no timestamp queries)."""
    return {"gpu_ms": statistics.median(gpu) if gpu else math.nan, "wall_ms": statistics.median(wall)}


def census_count(value: int | None) -> float:
    """A census count (stats "fragments", "max_depth_complexity") for a table: NaN where the
    frame ran no census."""
    return math.nan if value is None else value


def scene_counts(stats: dict, exact_stats: dict | None) -> dict[str, float]:
    """A row's `fragments` and `max_depth`: the frame's census, or for a method that ran none
    (and was timed without one) the scene's, from its exact frame's; NaN without either."""
    counted = stats if stats["census"] or exact_stats is None else exact_stats
    return {"fragments": census_count(counted["fragments"]), "max_depth": census_count(counted["max_depth_complexity"])}


def mean_rgb_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Mean over pixels of the RGB distance between two images."""
    return float(np.sqrt(((a[..., :3].astype(np.float64) - b[..., :3]) ** 2).sum(-1)).mean())


class Progress:
    """A one-line progress bar on stderr: done/total, elapsed time, the current row."""

    def __init__(self, total: int, enabled: bool = True) -> None:
        self.total, self.done, self.enabled, self.start = total, 0, enabled, time.perf_counter()

    def show(self, label: str) -> None:
        if not self.enabled:
            return
        width = 28
        filled = int(width * self.done / max(self.total, 1))
        elapsed = time.perf_counter() - self.start
        sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total} {elapsed:6.0f}s {label[:44]:<44}")
        sys.stderr.flush()

    def step(self, label: str) -> None:
        self.done += 1
        self.show(label)
        if self.done == self.total and self.enabled:
            sys.stderr.write("\n")


@dataclass
class Result:
    """A bench run: one row per scene x size x method x parameter set (peers included), and
    for the image sheets the exact image and each method's default-parameter image."""

    rows: list[dict]
    sheets: dict[tuple[str, str], dict[str, np.ndarray]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def format_params(params: Params) -> str:
    """'k=8', 'samples=8 seed=0', 'tolerance=0.00392157' (floats to 6 significant digits)."""
    return " ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in params.items())


def _cell(value: Any, fmt: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return fmt.format(value)


def markdown(rows: list[dict], columns: list[tuple[str, str]]) -> str:
    """The rows as a Markdown table; failed rows carry their message in the last column."""
    head = "| " + " | ".join(c for c, _ in columns) + " | note |"
    sep = "|" + "---|" * (len(columns) + 1)
    lines = [head, sep]
    for r in rows:
        note = f"failed: {r['message']}" if r["status"] != "ok" else ""
        lines.append("| " + " | ".join(_cell(r[c], f) for c, f in columns) + f" | {note} |")
    return "\n".join(lines)


def write_csv(path: str, rows: list[dict]) -> None:
    fields = list(dict.fromkeys(itertools.chain.from_iterable(rows)))
    with open(path, "w", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=fields)
        wr.writeheader()
        wr.writerows({k: ("" if isinstance(v, float) and math.isnan(v) else v) for k, v in r.items()} for r in rows)


def write_tables(out: str, name: str, result: Result, columns: list[tuple[str, str]]) -> None:
    """<out>/<name>.csv (every field) and <name>.md (the adapter, the notes, the table), and the
    table on stdout."""
    os.makedirs(out, exist_ok=True)
    write_csv(os.path.join(out, f"{name}.csv"), result.rows)
    adapters = ", ".join(dict.fromkeys(r["adapter"] for r in result.rows if r["adapter"]))
    notes = "".join(f"Note: {n}\n" for n in result.notes)
    table = markdown(result.rows, columns)
    with open(os.path.join(out, f"{name}.md"), "w") as f:
        f.write(f"Adapter: {adapters}\n\n{notes}\n{table}\n")
    print(f"adapter: {adapters}")
    for n in result.notes:
        print(f"note: {n}")
    print(table)
    print(f"wrote {os.path.join(out, f'{name}.md')} and {os.path.join(out, f'{name}.csv')}")
