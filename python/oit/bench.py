"""`python -m oit bench`: time, memory and error of every method against the exact A-buffer
on the built-in scenes, with the floor (one plain blended pass over the same geometry)
measured in the same run, so that times compare across machines as ratios."""

from __future__ import annotations

import argparse
import csv
import os
import statistics
import sys
import time
from typing import Any

import numpy as np

from . import scenes as scene_lib
from ._api import Renderer

# Parameter sweeps per method (one row per value).
SWEEPS: dict[str, list[dict[str, Any]]] = {
    "abuffer": [{}],
    "unsorted": [{}],
    "sorted": [{}],
    "hybrid": [{"k": k} for k in (1, 2, 4, 8, 16, 32)],
    "ktab": [{"k": k} for k in (4, 8, 16, 32)],
    "wavg": [{}],
    "wsum": [{}],
    "wboit": [{"weight": "eq10"}, {"weight": "eq7"}],
    "adaptive": [{"nodes": n} for n in (4, 8, 16)],
}
QUICK_SWEEPS: dict[str, list[dict[str, Any]]] = {
    "abuffer": [{}], "unsorted": [{}], "hybrid": [{"k": 4}, {"k": 8}], "ktab": [{"k": 8}],
    "wavg": [{}], "wboit": [{}], "adaptive": [{"nodes": 8}],
}


def rgb_errors(image: np.ndarray, exact: np.ndarray, mask: np.ndarray) -> dict[str, float]:
    """Per-pixel RGB distance (the hybrid paper's measure) over the pixels with at least one
    transparent fragment: mean and max, RMSE over channels, PSNR (peak 1); `mean_err_all`
    is the mean over every pixel of the frame (background pixels count as 0 error)."""
    d = image[..., :3].astype(np.float64) - exact[..., :3].astype(np.float64)
    full = np.sqrt((d ** 2).sum(-1))
    dist = full[mask]
    if dist.size == 0:
        return {"mean_err": 0.0, "mean_err_all": 0.0, "max_err": 0.0, "rmse": 0.0, "psnr": float("inf")}
    rmse = float(np.sqrt((d[mask] ** 2).mean()))
    return {
        "mean_err": float(dist.mean()),
        "mean_err_all": float(full.mean()),
        "max_err": float(dist.max()),
        "rmse": rmse,
        "psnr": float("inf") if rmse == 0 else float(20 * np.log10(1.0 / rmse)),
    }


def measure(renderer: Renderer, built: scene_lib.BuiltScene, method: str, params: dict, repeat: int) -> tuple[Any, dict]:
    """Renders once to warm up (pipelines, pool sizes), then `repeat` times; returns the last
    frame and the medians of GPU and wall time."""
    frame = renderer.render(built.scene, built.camera, method, **params)
    gpu, wall = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        frame = renderer.render(built.scene, built.camera, method, **params)
        wall.append((time.perf_counter() - t0) * 1e3)
        if frame.stats["gpu_time_ms"] is not None:
            gpu.append(frame.stats["gpu_time_ms"])
    return frame, {
        "gpu_ms": statistics.median(gpu) if gpu else float("nan"),
        "wall_ms": statistics.median(wall),
    }


def progress(i: int, n: int, label: str) -> None:
    width = 28
    done = int(width * i / max(n, 1))
    sys.stderr.write(f"\r[{'#' * done}{'.' * (width - done)}] {i}/{n} {label[:40]:<40}")
    sys.stderr.flush()
    if i == n:
        sys.stderr.write("\n")


def run(scenes: list[str], methods: list[str] | None, size: int | None, repeat: int, quick: bool) -> list[dict]:
    sweeps = QUICK_SWEEPS if quick else SWEEPS
    chosen = [m for m in sweeps if methods is None or m in methods]
    rows: list[dict] = []
    jobs = [(s, m, p) for s in scenes for m in chosen for p in sweeps[m]]
    done = 0
    for scene_name in scenes:
        kwargs = {"strands": 1500} if quick and scene_name == "hair" else {}
        built = scene_lib.SCENES[scene_name](**kwargs)
        w, h = (size, size) if size else built.size
        if quick:
            w, h = min(w, 192), min(h, 192)
        renderer = Renderer(w, h)
        exact, _ = measure(renderer, built, "abuffer", {}, 1)
        covered = exact.depth_complexity > 0
        _, floor = measure(renderer, built, "unsorted", {}, repeat)
        for method in chosen:
            for params in sweeps[method]:
                progress(done, len(jobs), f"{scene_name} {method} {params}")
                frame, t = measure(renderer, built, method, params, repeat)
                s = frame.stats
                row = {
                    "scene": scene_name, "size": f"{w}x{h}", "method": method,
                    "params": " ".join(f"{k}={v}" for k, v in params.items()),
                    "gpu_ms": t["gpu_ms"], "wall_ms": t["wall_ms"],
                    "x_floor": t["gpu_ms"] / floor["gpu_ms"],
                    "memory_mib": s["memory_bytes"] / 2 ** 20,
                    "fragments": s["fragments"], "max_depth": s["max_depth_complexity"],
                    "overflow": s["overflow_fragments"],
                    **rgb_errors(frame.image, exact.image, covered),
                    "adapter": s["adapter"],
                }
                rows.append(row)
                done += 1
    progress(done, len(jobs), "done")
    abuffer_ms = {r["scene"]: r["gpu_ms"] for r in rows if r["method"] == "abuffer"}
    for r in rows:
        r["abuffer_speedup"] = abuffer_ms.get(r["scene"], float("nan")) / r["gpu_ms"]
    return rows


FIGURE7_KS = (1, 2, 4, 8, 16)


def mean_rgb_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Mean over pixels of the RGB distance between two images."""
    return float(np.sqrt(((a[..., :3].astype(np.float64) - b[..., :3]) ** 2).sum(-1)).mean())


def figure7_errors(renderer: Renderer, layers: int, alphas: str, seed: int = 0) -> dict[tuple[str, int], float]:
    """The hybrid paper's Figure 7 on the GPU: one stack per pixel of the renderer's frame
    (oit.scenes.stacks, black background), mean RGB distance to the exact A-buffer for wavg
    (k = 0) and for hybrid, ktab and adaptive at each k in FIGURE7_KS."""
    built = scene_lib.stacks(layers=layers, alphas=alphas, size=(renderer.width, renderer.height), seed=seed)
    render = lambda m, **p: renderer.render(built.scene, built.camera, m, background=(0.0, 0.0, 0.0), **p).image
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


COLUMNS = [
    ("scene", "{}"), ("size", "{}"), ("method", "{}"), ("params", "{}"), ("gpu_ms", "{:.2f}"),
    ("x_floor", "{:.2f}"), ("abuffer_speedup", "{:.2f}"), ("wall_ms", "{:.1f}"), ("memory_mib", "{:.2f}"),
    ("mean_err", "{:.5f}"), ("mean_err_all", "{:.5f}"), ("max_err", "{:.4f}"), ("rmse", "{:.5f}"), ("psnr", "{:.1f}"), ("overflow", "{}"),
]


def markdown(rows: list[dict]) -> str:
    head = "| " + " | ".join(c for c, _ in COLUMNS) + " |"
    sep = "|" + "|".join("---" for _ in COLUMNS) + "|"
    lines = [head, sep]
    for r in rows:
        lines.append("| " + " | ".join(f.format(r[c]) for c, f in COLUMNS) + " |")
    return "\n".join(lines)


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--scenes", nargs="+", default=["hair"], choices=sorted(scene_lib.SCENES))
    ap.add_argument("--methods", nargs="+", default=None, help="methods to run (default: all)")
    ap.add_argument("--sizes", type=int, default=None, help="square frame size (default: the scene's)")
    ap.add_argument("--repeat", type=int, default=5, help="timed renders per row after one warm-up (median)")
    ap.add_argument("--out", default="out/bench", help="directory for results.csv and results.md")
    ap.add_argument("--quick", action="store_true", help="small frames and few rows: a smoke test of the bench")
    ap.add_argument("--figure7", action="store_true", help="also run the hybrid paper's Figure 7 experiment (400 stacks)")


def run_cli(a: argparse.Namespace) -> int:
    rows = run(a.scenes, a.methods, a.sizes, 1 if a.quick else max(1, a.repeat), a.quick)
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "results.csv"), "w", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=list(rows[0]))
        wr.writeheader()
        wr.writerows(rows)
    table = markdown(rows)
    with open(os.path.join(a.out, "results.md"), "w") as f:
        f.write(f"Adapter: {rows[0]['adapter']}\n\n{table}\n")
    print(f"adapter: {rows[0]['adapter']}")
    print(table)
    if a.figure7:
        fig7 = figure7_table()
        with open(os.path.join(a.out, "figure7.md"), "w") as f:
            f.write(fig7 + "\n")
        print("\nFigure 7 (mean per-pixel RGB distance to the A-buffer, 400 stacks):")
        print(fig7)
    return 0
