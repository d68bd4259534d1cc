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
import uuid
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
                     if main["min"] <= v <= main["max"] and (v - main["min"]) % main.get("step", 1) == 0 and v != main["default"]]
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


SceneSource = Any  # an oit.Scene, a mesh file's path, or a function of no arguments that returns a Scene


def compare(scene: SceneSource | Sequence[SceneSource], cameras: Sequence[Camera] | Sequence[Sequence[Camera]],
            width: int = 256, height: int = 256, methods_: Sequence[str] | None = None,
            tolerance: float = DEFAULT_TOLERANCE, time_ms: float | None = None, memory: int | None = None,
            repeat: int = 1, flip: bool = True, show_progress: bool = False, client: Any = None) -> Comparison:
    """Runs `plan(methods_)` on `scene` from every camera at width x height against the exact
    frames (abuffer). `memory` (bytes) limits peak memory: every row renders with that
    `memory_budget` (frames past it are tiled) and rows whose peak passes it miss the limit.
    `repeat` timed renders per view after a warm-up (the median is kept). See `Comparison`.

    `scene` may be a list of scenes, each an oit.Scene, a file's path (`Scene.from_file`) or a
    function that builds one; `cameras` is then a list of camera lists, one per scene, and
    every row measures every (scene, view). `client` (a dask.distributed Client) sends each
    (scene, view, method, parameters) job to the cluster's workers, each keeping one renderer
    per size and its scenes and exact frames; the scenes must then be paths the workers can
    read or picklable functions (an oit.Scene lives on this machine's device). The rows equal
    a single process's, times aside."""
    several = isinstance(scene, (list, tuple))
    sources = list(scene) if several else [scene]
    views = [list(c) for c in cameras] if several else [list(cameras)]
    if several and len(views) != len(sources):
        raise ValueError(f"with {len(sources)} scenes, cameras must be {len(sources)} lists of oit.Camera, one per scene")
    for s in sources:
        if client is not None and isinstance(s, Scene):
            raise TypeError("with a client, pass each scene as a file path the workers can read or a picklable function "
                            "that builds it: an oit.Scene lives on this machine's device")
        if not isinstance(s, (Scene, str, os.PathLike)) and not callable(s):
            raise TypeError(f"scene must be an oit.Scene, a file path or a function returning one, got {type(s).__name__}")
    if not all(v and all(isinstance(c, Camera) for c in v) for v in views):
        raise ValueError("cameras must be a non-empty list of oit.Camera (oit.views.orbit_cameras places some)"
                         + (", one list per scene" if several else ""))
    if not (isinstance(tolerance, (int, float)) and tolerance >= 0):
        raise ValueError(f"tolerance must be a number >= 0 (the worst view's max RGB distance), got {tolerance!r}")
    if time_ms is not None and not time_ms > 0:
        raise ValueError(f"time_ms must be positive, got {time_ms}")
    if memory is not None and (isinstance(memory, bool) or not isinstance(memory, int) or memory <= 0):
        raise ValueError(f"memory must be a positive number of bytes, got {memory!r}")
    runs = plan(methods_)
    total = sum(len(v) for v in views)
    progress = Progress(total * (1 + len(runs)), show_progress)
    result = Comparison(rows=[], tolerance=float(tolerance), time_ms=time_ms, memory=memory)
    if flip and flip_missing() is not None:
        result.notes.append(flip_missing() or "")
        flip = False
    defaults = dict(reversed(runs))  # each method's first run: its defaults
    token = uuid.uuid4().hex  # names this call's scenes and exact frames in the workers' caches
    sources = [partial(Scene.from_file, s) if isinstance(s, (str, os.PathLike)) else s for s in sources]
    config = (width, height, memory, repeat, flip)
    jobs = [(s, v) for s in range(len(sources)) for v in range(len(views[s]))]

    def job(s: int, v: int, method: str | None = None, params: Params | None = None) -> tuple:
        keep = s == v == 0 and (method is None or params == defaults[method])
        return ((token, s), sources[s], v, views[s][v], config, method, params, keep)

    if client is None:
        state = _State()
        outcomes = {}
        for s, v in jobs:
            progress.show(f"view {v} abuffer")
            outcomes[(s, v, None)] = run_job(*job(s, v), state=state)
            progress.step("abuffer")
        for r, (method, params) in enumerate(runs):
            for i, (s, v) in enumerate(jobs):
                progress.show(f"view {v} {method} {format_params(params)}")
                outcomes[(s, v, r)] = run_job(*job(s, v, method, params), state=state)
                progress.step(method)
                if outcomes[(s, v, r)]["status"] != "ok":  # the row stops at its first failed view
                    for _ in range(total - i - 1):
                        progress.step(method)
                    break
    else:
        outcomes = _run_on(client, {(s, v, r): job(s, v, *((None, None) if r is None else runs[r]))
                                    for r in (None, *range(len(runs))) for s, v in jobs}, progress)
    result.images["abuffer"] = outcomes[(0, 0, None)]["image"]
    for r, (method, params) in enumerate(runs):
        row = {"method": method, "params": format_params(params), "status": "ok", "message": "", "views": total}
        times, errors, stats = [], [], []
        for s, v in jobs:
            out = outcomes[(s, v, r)]
            if out["status"] != "ok":
                row.update(status="failed", message=out["message"])
                break
            times.append(out["time"])
            errors.append(out["errors"])
            stats.append(out["stats"])
            if out["image"] is not None:
                result.images[method] = out["image"]
        row.update(_measures(times, errors, stats))
        result.rows.append(row)
    for r in result.rows:
        r["meets"] = "yes" if not result.misses(r) else "no"
    return result


# ---- jobs: one (scene, view, method, parameters) render, here or on a Dask worker

_STATS = ("peak_memory_bytes", "memory_bytes", "gpu_time_ms", "wall_time_ms", "tiles")
_KEEP_SCENES, _KEEP_EXACT = 4, 256  # what a worker keeps between jobs (oldest dropped first)


class _State:
    """What a process (or a Dask worker) keeps between jobs: one renderer per size and memory
    budget, the last scenes built and the exact frames rendered."""

    def __init__(self) -> None:
        self.renderers: dict[tuple, Renderer] = {}
        self.scenes: dict[tuple, Scene] = {}
        self.exact: dict[tuple, Any] = {}

    def renderer(self, width: int, height: int, memory: int | None) -> Renderer:
        key = (width, height, memory)
        if key not in self.renderers:
            self.renderers[key] = Renderer(width, height, memory_budget=memory)
        return self.renderers[key]

    def scene(self, key: tuple, source: Any) -> Scene:
        if key not in self.scenes:
            while len(self.scenes) >= _KEEP_SCENES:
                self.scenes.pop(next(iter(self.scenes)))
            self.scenes[key] = source if isinstance(source, Scene) else source()
        return self.scenes[key]


def _worker_state() -> _State:
    """The calling Dask worker's state (kept on the worker), or a fresh one outside a worker."""
    try:
        from distributed import get_worker

        worker = get_worker()
    except (ImportError, ValueError):
        return _State()
    if not hasattr(worker, "_oit_compare"):
        worker._oit_compare = _State()
    return worker._oit_compare


def run_job(key: tuple, source: Any, view: int, camera: Camera, config: tuple, method: str | None, params: Params | None,
            keep: bool, state: _State | None = None) -> dict[str, Any]:
    """One job: the exact frame of (scene `key`, `view`) (rendered once per state), then, with a
    method, that method's timed render and its errors against it. Returns status and message,
    the time, the errors, the stats the row needs and, with `keep`, the image."""
    state = state or _worker_state()
    width, height, memory, repeat, flip = config
    renderer, scene = state.renderer(width, height, memory), state.scene(key, source)
    exact_key = (key, view, config[:3])
    if exact_key not in state.exact:
        while len(state.exact) >= _KEEP_EXACT:
            state.exact.pop(next(iter(state.exact)))
        state.exact[exact_key] = renderer.render(scene, camera, "abuffer")
    ex = state.exact[exact_key]
    if method is None:
        return {"status": "ok", "image": ex.image if keep else None}
    try:
        frame, gpu, wall = timed(partial(renderer.render, scene, camera, method, **(params or {})), repeat)
    except (RuntimeError, MemoryError, ValueError) as e:
        return {"status": "failed", "message": str(e).splitlines()[0]}
    return {"status": "ok", "time": statistics.median(gpu) if gpu else statistics.median(wall),
            "errors": image_errors(frame.image, ex.image, ex.depth_complexity > 0, flip=flip),
            "stats": {k: frame.stats.get(k) for k in _STATS}, "image": frame.image if keep else None}


def _run_on(client: Any, jobs: dict[tuple, tuple], progress: Progress) -> dict[tuple, dict]:
    """Every job on the client's workers (the exact frames first, so that each worker renders
    each view's once), with the progress bar as they finish."""
    from distributed import as_completed

    order = sorted(jobs, key=lambda k: (k[2] is not None, -1 if k[2] is None else k[2], k[0], k[1]))
    futures = {client.submit(run_job, *jobs[k], pure=False): k for k in order}
    out = {}
    for future in as_completed(list(futures)):
        k = futures[future]
        out[k] = future.result()
        progress.step("abuffer" if k[2] is None else jobs[k][5])
    return out


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
    p.add_argument("--dask", nargs="?", const="local", default=None, metavar="local|tcp://ADDRESS",
                   help="send the jobs to a Dask cluster: 'local' starts one worker a core here, an address joins a "
                        "running scheduler whose workers can read the files (pip install 'oit[dask]')")


def cli_scene(path: str, alpha: float | None, shading: str, specular: float, lights: Sequence[Sequence[float]],
              ambient: Sequence[float]) -> Scene:
    """A FILE of `compare` as `views.load_for_viewing` loads it (for the Dask workers: picklable
    through functools.partial, and silent)."""
    from ._api import load_file

    scene, _ = load_file(path, alpha, shading=shading, specular=specular, viewing=True)
    for light in lights:
        scene.add_light(light)
    scene.ambient = tuple(ambient)
    return scene


def dask_client(address: str) -> Any:
    """A dask.distributed Client: 'local' starts a LocalCluster of one single-threaded worker a
    core; anything else is a scheduler's address."""
    try:
        from distributed import Client, LocalCluster
    except ImportError as e:
        raise ValueError(f"--dask needs dask.distributed ({e}): pip install 'oit[dask]'") from None
    if address == "local":
        cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
        return Client(LocalCluster(n_workers=cores, threads_per_worker=1, processes=True, dashboard_address=None))
    return Client(address)


def run_cli(args: Any, scenes: Sequence[Scene]) -> int:
    """`compare` on the loaded scenes (one per FILE): the progress bar on stderr, the table,
    the files written and the recommendation on stdout."""
    from .views import scene_views

    w, h = args.size
    if w <= 0 or h <= 0 or args.repeat <= 0 or (args.views is not None and args.views <= 0):
        raise ValueError("--size, --views and --repeat must be positive")
    files = list(args.file) if isinstance(args.file, (list, tuple)) else [args.file]
    cameras = [scene_views(scene, args.views, aspect=w / h) for scene in scenes]
    limits = (args.methods, args.tolerance, args.time_ms, args.memory, args.repeat)
    if args.dask is None:
        result = compare(scenes[0] if len(scenes) == 1 else list(scenes), cameras[0] if len(scenes) == 1 else cameras,
                         w, h, *limits, show_progress=True)
    else:
        sources = [partial(cli_scene, os.path.abspath(f), args.alpha, args.shading, args.specular,
                           [tuple(v) for v in getattr(args, "light", [])], tuple(getattr(args, "ambient", (0.1, 0.1, 0.1))))
                   for f in files]
        with dask_client(args.dask) as client:
            result = compare(sources, cameras, w, h, *limits, show_progress=True, client=client)
    stems = [os.path.splitext(os.path.basename(f))[0] for f in files]
    out = args.out or os.path.join("out", f"compare-{stems[0]}" + (f"-and-{len(stems) - 1}-more" if len(stems) > 1 else ""))
    views = sum(len(c) for c in cameras)
    title = (f"{os.path.basename(files[0])}, {views} views at {w} x {h}" if len(files) == 1 else
             f"{', '.join(os.path.basename(f) for f in files)}: {views} views at {w} x {h}")
    paths = result.write(out, title, plots=not args.no_plots)
    for n in result.notes:
        print(f"note: {n}")
    print(result.markdown())
    print(f"wrote {', '.join(paths)}")
    print(result.summary())
    return 0
