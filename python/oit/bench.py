"""`python -m oit bench`: time, memory and error of every method against the exact A-buffer
on the built-in scenes, with the floor (one plain blended pass over the same geometry,
`unsorted`) measured in the same run, so that times compare across machines as ratios.

Methods and their parameter values come from `oit.methods()` (a few values across each
declared range), so new methods join without changes here. A method that fails (an adapter
limit, a memory budget) gives a row marked failed with the message. With pygfx or VTK installed
the same scenes go through their modes too (oit.peers): pygfx's alpha modes, VTK's depth
peeling and plain blending. Writes results.csv, results.md, and
with matplotlib the plots of oit.plots into --out.

Three other experiments run instead of the sweep, `--temporal`, `--auto` and `--antialias`
(oit.experiments)."""

from __future__ import annotations

import argparse
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
from functools import partial
from typing import Any, Callable

import numpy as np

from . import formulas, peers
from . import scenes as scene_lib
from ._api import Renderer
from ._api import methods as list_methods
from .imageio import linear_to_srgb

# Values tried for integer parameters (k, nodes, samples, layers), clipped to the declared range.
INT_SWEEP = (1, 2, 4, 8, 16, 32)
QUICK_SIZE = 64  # --quick caps frames at this size: a smoke test of the bench, not a measurement
# --quick also thins the scenes: depth peeling costs a geometry pass per layer, so a full hair
# (192,000 triangles, 340 layers) takes 25 s even at 64 x 64 on lavapipe.
QUICK_SCENE_ARGS: dict[str, dict[str, Any]] = {
    "hair": {"strands": 600}, "smoke": {"particles": 150}, "foliage": {"leaves": 1500}, "dragons": {"max_triangles": 800},
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
            values = sorted({v for v in INT_SWEEP if p["min"] <= v <= p["max"]} | {p["default"]})
        else:
            values = sorted({p["min"], p["default"], p["max"]})
        runs += [run for run in ({**defaults, p["name"]: v} for v in values) if run not in runs]
    return runs


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


def _row(scene: str, size: str, method: str, params: Params, **values: Any) -> dict:
    row = {"scene": scene, "size": size, "method": method, "params": format_params(params),
           "status": "ok", "gpu_ms": math.nan, "wall_ms": math.nan, "memory_mib": math.nan, "formula_mib": math.nan,
           "fragments": math.nan, "max_depth": math.nan, "overflow": math.nan, **dict.fromkeys(ERRORS, math.nan),
           "adapter": "", "message": ""}
    row.update(values)
    # Other work on the machine skews times: the CSV keeps the 1-minute load average at each row.
    row["load_avg"] = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    return row


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


def run(scenes: list[str], methods: list[str] | None = None, sizes: list[int] | None = None, repeat: int = 5,
        quick: bool = False, with_peers: bool = True, show_progress: bool = True) -> Result:
    """Measures every method of oit.methods() (or those named) on each scene at each size
    (default: the scene's own; --quick caps it at QUICK_SIZE)."""
    plan = method_plan(methods, quick)
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
        formula = formulas.memory_bytes(method, w, h, **params)
        row = _row(scene_name, size, method, params, gpu_ms=statistics.median(gpu) if gpu else math.nan,
                   wall_ms=statistics.median(wall), memory_mib=s["memory_bytes"] / 2 ** 20,
                   formula_mib=math.nan if formula is None else formula / 2 ** 20, fragments=s["fragments"],
                   max_depth=s["max_depth_complexity"], overflow=s["overflow_fragments"], adapter=adapter)
        if exact is not None:
            row.update(image_errors(frame.image, exact, covered))
            if is_default:
                sheet[method] = frame.image
        rows.append(row)
        progress.step(method)
    for library, mode in peer_modes:
        progress.show(f"{scene_name} {size} {library} {mode}")
        rows.append(_peer_row(scene_name, built, w, h, library, mode, repeat, exact, covered, sheet))
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


FIGURE7_KS = (1, 2, 4, 8, 16)


def mean_rgb_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Mean over pixels of the RGB distance between two images."""
    return float(np.sqrt(((a[..., :3].astype(np.float64) - b[..., :3]) ** 2).sum(-1)).mean())


def figure7_errors(renderer: Renderer, layers: int, alphas: str, seed: int = 0) -> dict[tuple[str, int], float]:
    """The hybrid paper's Figure 7 on the GPU: one stack per pixel of the renderer's frame
    (oit.scenes.stacks, black background), mean RGB distance to the exact A-buffer for wavg
    (k = 0) and for hybrid, ktab and adaptive at each k in FIGURE7_KS."""
    built = scene_lib.stacks(layers=layers, alphas=alphas, size=(renderer.width, renderer.height), seed=seed)
    render = lambda m, **p: renderer.render(built.scene, built.camera, m, background=(0.0, 0.0, 0.0), **p).image  # noqa: E731
    exact = render("abuffer")
    errors = {("wavg", 0): mean_rgb_distance(render("wavg"), exact)}
    for k in FIGURE7_KS:
        errors[("hybrid", k)] = mean_rgb_distance(render("hybrid", k=k), exact)
        errors[("ktab", k)] = mean_rgb_distance(render("ktab", k=k), exact)
        errors[("adaptive", k)] = mean_rgb_distance(render("adaptive", nodes=k), exact)
    return errors


def figure7_table(size: int = 20) -> str:
    """Markdown table of figure7_errors for 20 and 100 fragments and every distribution."""
    r = Renderer(size, size)
    lines = ["| layers | alphas | wavg | " + " | ".join(f"{m} k={k}" for k in FIGURE7_KS for m in ("hybrid", "ktab", "adaptive")) + " |"]
    lines.append("|" + "---|" * (3 + 3 * len(FIGURE7_KS)))
    for layers in (20, 100):
        for alphas in scene_lib.ALPHA_KINDS:
            e = figure7_errors(r, layers, alphas, seed=layers + len(alphas))
            cells = [f"{e[(m, k)]:.4f}" for k in FIGURE7_KS for m in ("hybrid", "ktab", "adaptive")]
            lines.append(f"| {layers} | {alphas} | {e[('wavg', 0)]:.4f} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


# Markdown columns and formats; every row field goes to the CSV.
COLUMNS = [
    ("scene", "{}"), ("size", "{}"), ("method", "{}"), ("params", "{}"), ("gpu_ms", "{:.2f}"), ("x_floor", "{:.2f}"),
    ("abuffer_speedup", "{:.2f}"), ("wall_ms", "{:.1f}"), ("wall_x_floor", "{:.2f}"), ("memory_mib", "{:.2f}"),
    ("mean_err", "{:.5f}"), ("mean_err_all", "{:.5f}"), ("max_err", "{:.4f}"), ("rmse", "{:.5f}"), ("psnr", "{:.1f}"),
    ("flip", "{:.4f}"), ("max_depth", "{}"), ("overflow", "{}"),
]


def _cell(value: Any, fmt: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return fmt.format(value)


def markdown(rows: list[dict], columns: list[tuple[str, str]] = COLUMNS) -> str:
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


def add_arguments(ap: argparse.ArgumentParser) -> None:
    from .experiments import AA_METHODS, AA_SAMPLES, AUTO_MAX_K, AUTO_TOLERANCES, TEMPORAL_FRAMES, TEMPORAL_STEP_DEG

    ap.add_argument("--scenes", nargs="+", default=list(scene_lib.SHOWCASE), choices=sorted(scene_lib.SCENES),
                    help="scenes to run (default: %(default)s)")
    ap.add_argument("--methods", nargs="+", default=None,
                    help="methods to run (default: every method of `oit methods`; with --temporal every approximate one)")
    ap.add_argument("--sizes", type=int, nargs="+", default=None, help="square frame sizes (default: each scene's own)")
    ap.add_argument("--repeat", type=int, default=5, help="timed renders per row after one warm-up (median)")
    ap.add_argument("--out", default="out/bench", help="directory for the tables and the plots")
    ap.add_argument("--quick", action="store_true",
                    help=f"default parameters only, one timed render, frames of at most {QUICK_SIZE} pixels: a smoke test")
    ap.add_argument("--no-peers", action="store_true", help="skip the peers (pygfx, VTK) even when installed")
    ap.add_argument("--no-plots", action="store_true", help="skip the matplotlib plots")
    ap.add_argument("--figure7", action="store_true", help="also run the hybrid paper's Figure 7 experiment (400 stacks)")
    ap.add_argument("--temporal", action="store_true",
                    help="instead of the method sweep: the change between frames of a slow camera orbit, each approximate "
                         "method against abuffer (temporal.csv, temporal.md, temporal.png)")
    ap.add_argument("--frames", type=int, default=TEMPORAL_FRAMES, help="--temporal: frames of the orbit (default: %(default)s)")
    ap.add_argument("--step", type=float, default=TEMPORAL_STEP_DEG,
                    help="--temporal: degrees the camera turns a frame (default: %(default)s)")
    ap.add_argument("--auto", action="store_true",
                    help="instead of the method sweep: auto against the cheapest fixed-k hybrid that meets each tolerance, "
                         "found by search (auto.csv, auto.md)")
    ap.add_argument("--tolerances", type=float, nargs="+", default=list(AUTO_TOLERANCES),
                    help="--auto: tolerances (default: 1/255 4/255 16/255)")
    ap.add_argument("--max-k", type=int, default=AUTO_MAX_K, help="--auto: the largest k searched (default: %(default)s)")
    ap.add_argument("--antialias", action="store_true",
                    help="run the antialiasing benchmark instead: time and memory of each method (default: "
                         f"{', '.join(AA_METHODS)}) at --aa-samples samples a pixel against one (antialias.csv, .md)")
    ap.add_argument("--aa-samples", type=int, nargs="+", default=list(AA_SAMPLES),
                    help="--antialias: samples a pixel to measure (default: %(default)s; 1 is always added)")


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


def _plots_missing(a: argparse.Namespace) -> bool:
    """True (and says why) when the plots are to be skipped."""
    if a.no_plots:
        return True
    from . import plots

    missing = plots.matplotlib_missing()
    if missing:
        print(f"note: no plots: {missing}")
    return missing is not None


def run_cli(a: argparse.Namespace) -> int:
    from .experiments import AA_COLUMNS, AUTO_COLUMNS, TEMPORAL_COLUMNS, antialias, auto_vs_fixed, temporal

    repeat = 1 if a.quick else max(1, a.repeat)
    if a.temporal or a.auto or a.antialias:
        if a.antialias:
            result = antialias(a.scenes, a.methods, a.sizes, tuple(a.aa_samples), repeat, a.quick)
            write_tables(a.out, "antialias", result, AA_COLUMNS)
        if a.temporal:
            result = temporal(a.scenes, a.methods, a.sizes, a.frames, a.step, a.quick)
            write_tables(a.out, "temporal", result, TEMPORAL_COLUMNS)
            if not _plots_missing(a):
                from . import plots

                path = os.path.join(a.out, "temporal.png")
                plots.temporal(result.rows, path)
                print(f"wrote {path}")
        if a.auto:
            if a.methods is not None:
                print("note: --auto compares auto with hybrid; --methods is ignored")
            result = auto_vs_fixed(a.scenes, a.sizes, tuple(a.tolerances), repeat, a.max_k, a.quick)
            write_tables(a.out, "auto", result, AUTO_COLUMNS)
            over = [r for r in result.rows if r["within_t"] is False]
            for r in over:
                print(f"error: auto exceeded its tolerance on {r['scene']} {r['size']}: measured {r['auto_max_abs']:.6f} "
                      f"> t = {r['tolerance']:.6f}", file=sys.stderr)
            if over:
                return 1
        return 0
    result = run(a.scenes, a.methods, a.sizes, repeat, a.quick, with_peers=not a.no_peers)
    write_tables(a.out, "results", result, COLUMNS)
    if not _plots_missing(a):
        from . import plots

        for path in plots.write_all(result, a.out):
            print(f"wrote {path}")
    if a.figure7:
        fig7 = figure7_table()
        with open(os.path.join(a.out, "figure7.md"), "w") as f:
            f.write(fig7 + "\n")
        print("\nFigure 7 (mean per-pixel RGB distance to the A-buffer, 400 stacks):")
        print(fig7)
    return 0
