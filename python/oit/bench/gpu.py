"""`python -m oit bench --gpu --out DIR` (scripts/gpu-bench.sh runs it on a GPU machine without
the network): what may turn on a GPU, in one run of about six minutes on a hardware adapter. Five
parts, each stopped cleanly at its own time limit (PLANS), each row printed as it is measured:

- defaults: every method at its default parameters on every showcase scene at 512², 1080p and 4K,
  with the exact A-buffer's image (errors) and the floor (`unsorted`, ratios) at each point;
- hair: the papers' hair, 15,000 strands, every method at its defaults at 512² and 1080p;
- sweeps: k, nodes and layers of every method that has them, on that hair at 1080p;
- claims: docs/claims.md's rows that rest on GPU times (TIME_CLAIMS), each with its verdict;
- floor: the floor and the methods over it against pygfx on the same arrays (oit.bench.floor),
  when pygfx is installed.

It refuses a software adapter (lavapipe) unless `--small`, which runs the same parts on any
adapter at tiny sizes in well under a minute: a check that the run works (tests/test_gpu_bench.py),
not a measurement. DIR/gpu.md and DIR/gpu.json are rewritten after every part (and every
CHECKPOINT_S within one), so a run stopped from outside keeps what it measured."""

from __future__ import annotations

import datetime
import functools
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from typing import Any

from .. import peers
from .. import scenes as scene_lib
from .._api import Renderer
from .._api import methods as list_methods
from .claims import CLAIM_COLUMNS, run_claims
from .floor import FLOOR_COLUMNS, peers_floor
from .floor import SCENES as FLOOR_SCENES
from .harness import INT_SWEEP, Params, format_params, image_errors, markdown, medians, timed

# docs/claims.md's rows whose verdict rests on GPU times (the rest count passes, bytes or errors).
TIME_CLAIMS = ("AT-speed", "AT-stoch", "AT-nodes", "AT-rate", "HT-fig8", "HT-fig9", "HT-fig10", "HT-64bit", "HT-first-pass",
               "HT-peel-wavg", "KZ-time", "KZ-scale", "KZ-compact-time", "KZ-sbuffer", "RTR-peel-slow")
SWEPT = ("k", "nodes", "layers")  # the parameters the sweeps part varies
CHECKPOINT_S = 10.0  # the results files are rewritten at least this often during a part
ROW_COLUMNS = [
    ("scene", "{}"), ("size", "{}"), ("method", "{}"), ("params", "{}"), ("gpu_ms", "{:.3f}"), ("wall_ms", "{:.1f}"),
    ("x_floor", "{:.2f}"), ("abuffer_speedup", "{:.2f}"), ("memory_mib", "{:.2f}"), ("tiles", "{}"), ("mean_err", "{:.5f}"),
    ("max_err", "{:.4f}"),
]


@dataclass(frozen=True)
class Plan:
    """What a run measures: sizes, scene thinning, repeats, claims, floor scenes, and the time
    limit of each part in seconds."""

    sizes: tuple[tuple[int, int], ...]
    scene_args: dict[str, dict[str, Any]]
    hair_strands: int
    hair_sizes: tuple[tuple[int, int], ...]
    sweep_size: tuple[int, int]
    repeat: int
    claims: tuple[str, ...]
    floor_scenes: tuple[str, ...]
    floor_quick: bool
    limits: dict[str, float]


PLANS = {
    # About 6 minutes on a data-center GPU (the limits add up to 345 s).
    "gpu": Plan(sizes=((512, 512), (1920, 1080), (3840, 2160)), scene_args={}, hair_strands=15000,
                hair_sizes=((512, 512), (1920, 1080)), sweep_size=(1920, 1080), repeat=3, claims=TIME_CLAIMS,
                floor_scenes=FLOOR_SCENES, floor_quick=False,
                limits={"defaults": 150, "hair": 40, "sweeps": 60, "claims": 55, "floor": 40}),
    # Seconds on lavapipe: thinned scenes, tiny frames, one claim, one floor scene.
    "small": Plan(sizes=((16, 16), (32, 18), (48, 27)),
                  scene_args={"hair": {"strands": 60}, "smoke": {"particles": 30}, "foliage": {"leaves": 100},
                              "dragons": {"max_triangles": 200}, "glass": {"detail": 8}},
                  hair_strands=150, hair_sizes=((16, 16), (32, 18)), sweep_size=(32, 18), repeat=1, claims=("KZ-time",),
                  floor_scenes=("glass",), floor_quick=True,
                  limits={"defaults": 15, "hair": 8, "sweeps": 12, "claims": 10, "floor": 10}),
}


@dataclass
class Part:
    """One part's outcome: its rows and notes, how far it got, and in how long."""

    name: str
    title: str
    limit_s: float
    columns: list[tuple[str, str]]
    rows: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    status: str = "not run"
    done: int = 0
    total: int = 0
    elapsed_s: float = 0.0
    start: float = 0.0

    def over(self) -> bool:
        return time.perf_counter() - self.start > self.limit_s

    def stop(self) -> None:
        self.status = f"stopped at its time limit ({self.limit_s:.0f} s)"
        print(f"[{self.name}] {self.status} after {self.done} of {self.total}", flush=True)


@dataclass
class Job:
    """A scene at a size and the (method, parameters) runs measured on it."""

    scene: str
    size: tuple[int, int]
    build: Callable[[], scene_lib.BuiltScene]
    runs: list[tuple[str, Params]]


def _defaults(method: dict) -> Params:
    return {p["name"]: p["default"] for p in method["params"]}


def _swept(method: dict) -> list[Params]:
    """The method's parameter sets that vary one of SWEPT over INT_SWEEP (and its default)."""
    out = []
    for p in method["params"]:
        if p["name"] in SWEPT:
            on_step = {v for v in INT_SWEEP if p["min"] <= v <= p["max"] and (v - p["min"]) % p.get("step", 1) == 0}
            for v in sorted(on_step | {p["default"]}):
                out.append({**_defaults(method), p["name"]: v})
    return out


def _build(name: str, plan: Plan, **kwargs: Any) -> scene_lib.BuiltScene:
    return _scene(name, tuple(sorted({**plan.scene_args.get(name, {}), **kwargs}.items())))


@functools.cache
def _scene(name: str, args: tuple[tuple[str, Any], ...]) -> scene_lib.BuiltScene:
    """A showcase scene, built once for every size and part (the dragons' decimation takes seconds)."""
    return scene_lib.SCENES[name](**dict(args))


def jobs(part: str, plan: Plan) -> list[Job]:
    """The scenes, sizes and runs of a method part, smallest frames first (a part stopped at its
    limit has every scene at the small sizes)."""
    infos = list_methods()
    at_defaults = [(m["name"], _defaults(m)) for m in infos]
    if part == "defaults":
        return [Job(s, size, partial(_build, s, plan), at_defaults) for size in plan.sizes for s in scene_lib.SHOWCASE]
    hair = partial(_build, "hair", plan, strands=plan.hair_strands)
    if part == "hair":
        return [Job(f"hair {plan.hair_strands}", size, hair, at_defaults) for size in plan.hair_sizes]
    return [Job(f"hair {plan.hair_strands}", plan.sweep_size, hair, [(m["name"], p) for m in infos for p in _swept(m)])]


def _row(job: Job, method: str, params: Params, **values: Any) -> dict:
    row = {"scene": job.scene, "size": f"{job.size[0]}x{job.size[1]}", "method": method, "params": format_params(params),
           "status": "ok", "message": "", "gpu_ms": math.nan, "wall_ms": math.nan, "x_floor": math.nan,
           "abuffer_speedup": math.nan, "memory_mib": math.nan, "tiles": math.nan, "mean_err": math.nan, "max_err": math.nan}
    row.update(values)
    return row


def _first_line(e: BaseException) -> str:
    return (str(e).splitlines() or [type(e).__name__])[0]


def measure_jobs(part: Part, job_list: list[Job], plan: Plan, checkpoint: Callable[[], None]) -> None:
    """Each job's runs: median GPU and wall time of plan.repeat renders after a warm-up, memory,
    tiles, errors against the A-buffer's image and the ratio to the floor's GPU time at the same
    point. Stops at the part's limit, between rows."""
    part.total = sum(len(j.runs) for j in job_list)
    renderer: Renderer | None = None
    for job in job_list:
        if part.over():
            return part.stop()
        try:
            built = job.build()
            if renderer is None or (renderer.width, renderer.height) != job.size:
                renderer = None  # the last size's buffers go first
                renderer = Renderer(*job.size)
            exact = renderer.render(built.scene, built.camera, "abuffer")
            _, floor_gpu, floor_wall = timed(partial(renderer.render, built.scene, built.camera, "unsorted"), plan.repeat)
            floor = medians(floor_gpu, floor_wall)
        except (RuntimeError, MemoryError, ValueError) as e:
            part.notes.append(f"{job.scene} {job.size[0]}x{job.size[1]}: no scene, reference or floor: {_first_line(e)}")
            part.done += len(job.runs)
            continue
        supported = renderer.adapter_info["methods"]
        rows = []
        for method, params in job.runs:
            if part.over():
                part.rows += rows
                return part.stop()
            part.done += 1
            if method not in supported:
                rows.append(_row(job, method, params, status="skipped", message="the adapter lacks its features"))
                continue
            try:
                frame, gpu, wall = timed(partial(renderer.render, built.scene, built.camera, method, **params), plan.repeat)
            except (RuntimeError, MemoryError, ValueError) as e:
                rows.append(_row(job, method, params, status="failed", message=_first_line(e)))
                print(f"[{part.name} {part.done}/{part.total}] {job.scene} {job.size[0]}x{job.size[1]} {method}: failed: "
                      f"{_first_line(e)}", flush=True)
                continue
            s = frame.stats
            errors = image_errors(frame.image, exact.image, exact.depth_complexity > 0, flip=False)
            t = medians(gpu, wall)
            rows.append(_row(job, method, params, **t, x_floor=t["gpu_ms"] / floor["gpu_ms"], memory_mib=s["memory_bytes"] / 2 ** 20,
                             tiles=s["tiles"], mean_err=errors["mean_err"], max_err=errors["max_err"]))
            print(f"[{part.name} {part.done}/{part.total} {time.perf_counter() - part.start:.0f}s] {job.scene} "
                  f"{job.size[0]}x{job.size[1]} {method} {format_params(params)}: {t['gpu_ms']:.3f} ms GPU, "
                  f"{t['wall_ms']:.1f} ms wall", flush=True)
            checkpoint()
        abuffer = next((r["gpu_ms"] for r in rows if r["method"] == "abuffer" and r["status"] == "ok"), math.nan)
        for r in rows:
            r["abuffer_speedup"] = abuffer / r["gpu_ms"]
        part.rows += rows
        del built, exact
    part.status = "done"


def measure_claims(part: Part, plan: Plan, checkpoint: Callable[[], None]) -> None:
    """The time claims one at a time (each prints its verdict), stopping at the part's limit."""
    part.total = len(plan.claims)
    for cid in plan.claims:
        if part.over():
            return part.stop()
        part.rows += run_claims(only=[cid]).rows
        part.done += 1
        checkpoint()
    part.status = "done"


def measure_floor(part: Part, plan: Plan, checkpoint: Callable[[], None]) -> None:
    """The floor against pygfx, one scene at a time; skipped, saying why, without pygfx."""
    missing = peers.pygfx_missing()
    if missing:
        part.status = f"skipped: {missing} (scripts/gpu-prepare.sh prepares its wheels for Python 3.11 and later)"
        print(f"[{part.name}] {part.status}", flush=True)
        return
    part.notes.append(f"the peer: {peers.pygfx_renderer(8, 8).adapter}")
    part.notes.append("ratios are not held against floor_baseline.json, which was measured on lavapipe")
    part.total = len(plan.floor_scenes)
    for name in plan.floor_scenes:
        if part.over():
            return part.stop()
        part.rows += peers_floor((name,), repeat=plan.repeat, quick=plan.floor_quick, show_progress=False).rows
        part.done += 1
        print(f"[{part.name} {part.done}/{part.total} {time.perf_counter() - part.start:.0f}s] {name}: "
              + ", ".join(f"{r['shading']} {r['method']} {r['ratio']:.2f}x" for r in part.rows if r["scene"] == name), flush=True)
        checkpoint()
    part.status = "done"


PARTS: list[tuple[str, str, list[tuple[str, str]]]] = [
    ("defaults", "every method at its default parameters, every showcase scene, three frame sizes", ROW_COLUMNS),
    ("hair", "the papers' hair (15,000 strands in the full run), every method at its defaults", ROW_COLUMNS),
    ("sweeps", "k, nodes and layers of every method that has them, on that hair", ROW_COLUMNS),
    ("claims", "docs/claims.md's rows that rest on GPU times", CLAIM_COLUMNS),
    ("floor", "the floor and the methods over it against pygfx on the same arrays", FLOOR_COLUMNS),
]


def _nvidia_smi() -> str:
    """The GPU and driver as nvidia-smi reports them, or '' without it."""
    if shutil.which("nvidia-smi") is None:
        return ""
    try:
        out = subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version,memory.total", "--format=csv,noheader"],
                             capture_output=True, text=True, timeout=20)
    except (OSError, subprocess.TimeoutExpired):
        return ""
    return out.stdout.strip().replace("\n", "; ")


def _version(name: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(name)
    except PackageNotFoundError:
        return "not installed"


def environment(info: dict, small: bool) -> dict[str, Any]:
    """What the results were measured on and with."""
    return {
        "adapter": info["name"], "backend": info["backend"], "device_type": info["device_type"], "driver": info["driver"],
        "driver_info": info["driver_info"], "timestamps": info["timestamps"], "nvidia_smi": _nvidia_smi(),
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"), "host": platform.node(),
        "python": platform.python_version(), "oit": _version("oit"), "numpy": _version("numpy"), "pygfx": _version("pygfx"),
        "source": os.environ.get("OIT_BUILD_SOURCE", ""), "small": small,
        "command": "python -m oit bench --gpu" + (" --small" if small else ""),
    }


def _plain(value: Any) -> Any:
    """JSON-safe: NaN and infinities become null, numpy scalars Python numbers."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if hasattr(value, "item") and not isinstance(value, (str, bytes)):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def report_markdown(env: dict[str, Any], parts: list[Part]) -> str:
    """gpu.md: the adapter, driver and date, then each part's status and table."""
    small = " (--small: tiny frames, a check that the run works, not a measurement)" if env["small"] else ""
    lines = [
        f"# oit on {env['adapter']}{small}", "",
        f"- adapter: {env['adapter']} ({env['backend']}, {env['device_type']}); driver: {env['driver']} {env['driver_info']}",
        f"- nvidia-smi: {env['nvidia_smi'] or 'not available'}",
        f"- date: {env['date']}; host {env['host']}; Python {env['python']}, oit {env['oit']}, numpy {env['numpy']}, "
        f"pygfx {env['pygfx']}" + (f"; built from {env['source']}" if env["source"] else ""),
        f"- command: `{env['command']}` (scripts/gpu-bench.sh); GPU times are medians of timestamp queries after a warm-up, "
        "errors are mean and max per-pixel RGB distance to the A-buffer over covered pixels, x_floor is the GPU time over "
        "`unsorted`'s at the same point",
    ]
    for p in parts:
        lines += ["", f"## {p.name}: {p.title}", "", f"{p.status}: {p.done} of {p.total} in {p.elapsed_s:.0f} s "
                  f"(limit {p.limit_s:.0f} s)", ""]
        lines += [f"Note: {n}" for n in p.notes] + ([""] if p.notes else [])
        if p.rows:
            lines.append(markdown(p.rows, p.columns))
    return "\n".join(lines) + "\n"


def write_report(out: str, env: dict[str, Any], parts: list[Part]) -> None:
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "gpu.md.tmp"), "w") as f:
        f.write(report_markdown(env, parts))
    data = {"environment": env, "parts": [{k: v for k, v in vars(p).items() if k != "start"} for p in parts]}
    with open(os.path.join(out, "gpu.json.tmp"), "w") as f:
        json.dump(_plain(data), f, indent=1)
        f.write("\n")
    for name in ("gpu.md", "gpu.json"):
        os.replace(os.path.join(out, name + ".tmp"), os.path.join(out, name))


def run_gpu(out: str, small: bool = False) -> int:
    """Runs every part (PLANS["small"] with `small`) and writes out/gpu.md and out/gpu.json;
    returns 3, having said why, when the adapter is a software one and `small` is not set."""
    plan = PLANS["small" if small else "gpu"]
    try:
        info = Renderer(1, 1).adapter_info
    except RuntimeError as e:  # no Vulkan loader or driver at all
        print(f"error: no adapter: {_first_line(e)}", file=sys.stderr)
        return 3
    print(f"adapter: {info['name']} ({info['backend']}, {info['device_type']}); driver: {info['driver']} {info['driver_info']}",
          flush=True)
    if not small and info["device_type"] == "Cpu":
        print(f"error: no hardware adapter: the best one found is {info['name']}, a software rasterizer; the GPU bench "
              "measures GPUs only (scripts/gpu-bench.sh points the Vulkan loader at the NVIDIA driver; `--small` runs on "
              "any adapter)", file=sys.stderr)
        return 3
    env = environment(info, small)
    parts = [Part(name, title, plan.limits[name], columns) for name, title, columns in PARTS]
    last = [time.perf_counter()]

    def checkpoint() -> None:
        if time.perf_counter() - last[0] > CHECKPOINT_S:
            write_report(out, env, parts)
            last[0] = time.perf_counter()

    for part in parts:
        print(f"[{part.name}] {part.title} (limit {part.limit_s:.0f} s)", flush=True)
        part.start = time.perf_counter()
        try:
            if part.name in ("defaults", "hair", "sweeps"):
                measure_jobs(part, jobs(part.name, plan), plan, checkpoint)
            elif part.name == "claims":
                measure_claims(part, plan, checkpoint)
            else:
                measure_floor(part, plan, checkpoint)
        except Exception as e:  # one part's fault (a device loss, a peer's error) must not cost the others
            part.status = f"failed: {type(e).__name__}: {_first_line(e)}"
            print(f"[{part.name}] {part.status}", file=sys.stderr, flush=True)
        part.elapsed_s = time.perf_counter() - part.start
        write_report(out, env, parts)
    print(f"wrote {os.path.join(out, 'gpu.md')} and gpu.json: "
          + ", ".join(f"{p.name} {p.done}/{p.total} in {p.elapsed_s:.0f} s" for p in parts), flush=True)
    return 0
