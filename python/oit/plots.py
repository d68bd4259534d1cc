"""Plots of a bench run (matplotlib, an optional dependency: `pip install matplotlib`):
per scene and size, the speed-accuracy trade (mean error against GPU time, wall time and
memory, with the Pareto front marked) and an image sheet (each method's picture above its
error heatmap, beside the exact A-buffer); the experiments' figures (temporal stability, and
time against the work on log-log axes for --scale)."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from .imageio import linear_to_srgb

# Axes of the trade-off panels: (row field, axis label, log scale).
TRADE_AXES = (
    ("gpu_ms", "GPU time (ms)", True),
    ("wall_ms", "wall time per frame (ms)", True),
    ("memory_mib", "memory the method allocated (MiB)", False),
)
# Errors below this are float32 rounding of an exact method: drawn on this line, marked "exact".
EXACT_BELOW = 1e-5
# The heatmaps' fixed logarithmic scale, the same on every sheet: 1e-3 (black) is a quarter of
# an 8-bit step, 1 (white) a fully wrong pixel.
HEAT_RANGE = (1e-3, 1.0)
SHEET_COLUMNS = 7
SHEET_TILE = 256  # largest tile side on an image sheet, in pixels


def matplotlib_missing() -> str | None:
    """Why the plots cannot be drawn here, or None when they can."""
    try:
        import matplotlib  # noqa: F401
    except ImportError as e:
        return f"matplotlib is not installed ({e}); `pip install matplotlib` adds it"
    return None


def pareto_front(points: Sequence[tuple[float, float]]) -> list[int]:
    """Indices of the points no other point beats on both coordinates (smaller is better),
    in increasing x: the best error reachable at each cost."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], math.inf
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def _label_value(params: str) -> str:
    """The first parameter's value (k, nodes, samples, layers) as a short point label."""
    value = params.split(" ")[0].partition("=")[2]
    try:
        return f"{float(value):.3g}"
    except ValueError:
        return value


# Where a point's label may go, in points from the point, tried in order.
LABEL_OFFSETS = ((4, 3), (4, -9), (-10, 3), (-10, -9), (4, 10), (4, -16), (-16, 10), (-16, -16))


def _place_labels(ax: Any, labels: list[tuple[float, float, str]]) -> None:
    """Writes each (x, y, text) beside its point at the first of LABEL_OFFSETS where it overlaps
    no label placed before it and stays inside the axes; a label with no such place is left out
    (its point keeps its color in the legend)."""
    renderer = ax.figure.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    taken: list[Any] = []
    for x, y, text in labels:
        for offset in LABEL_OFFSETS:
            t = ax.annotate(text, (x, y), textcoords="offset points", xytext=offset, fontsize=7)
            box = t.get_window_extent(renderer)
            inside = frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
            if inside and not any(box.overlaps(b) for b in taken):
                taken.append(box)
                break
            t.remove()


def tradeoff_figure(rows: list[dict], title: str) -> Any:
    """The figure of `tradeoff`: mean error (over covered pixels) against each of TRADE_AXES,
    one marker color per method (named in one legend below the panels), parameter values beside
    their points where they fit without overlapping, the Pareto front as a dashed step line.
    Rows below EXACT_BELOW sit on that line, which is labelled 'exact' once."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    ok = [r for r in rows if r["status"] == "ok" and math.isfinite(r["mean_err"])]
    methods = list(dict.fromkeys(r["method"] for r in ok))
    palette = [plt.get_cmap(name)(i) for name in ("tab20", "tab20b") for i in range(20)]
    colors = {m: palette[i % len(palette)] for i, m in enumerate(methods)}
    legend_rows = -(-(len(methods) + 1) // 8)
    fig, axes = plt.subplots(1, len(TRADE_AXES), figsize=(6 * len(TRADE_AXES), 5 + 0.25 * legend_rows))
    handles: dict[str, Any] = {}
    for ax, (key, xlabel, log_x) in zip(axes, TRADE_AXES):
        pts = [(r[key], max(r["mean_err"], EXACT_BELOW), r) for r in ok if math.isfinite(r[key])]
        for m in methods:
            mine = [(x, y, r) for x, y, r in pts if r["method"] == m]
            if mine:
                handles[m] = ax.scatter([p[0] for p in mine], [p[1] for p in mine], color=colors[m], label=m, s=30,
                                        zorder=3, marker="^" if m.startswith(("pygfx-", "vtk-")) else "o")
        front = [pts[i] for i in pareto_front([(p[0], p[1]) for p in pts])]
        if front:
            handles["Pareto front"] = ax.step([p[0] for p in front], [p[1] for p in front], where="post", color="0.4",
                                              linestyle="--", linewidth=1, label="Pareto front", zorder=2)[0]
        if any(r["mean_err"] < EXACT_BELOW for _, _, r in pts):
            ax.axhline(EXACT_BELOW, color="0.6", linestyle=":", linewidth=1, zorder=1)
            ax.annotate(f"exact (error < {EXACT_BELOW:g})", (0.01, EXACT_BELOW), xycoords=("axes fraction", "data"),
                        textcoords="offset points", xytext=(0, -11), fontsize=7, color="0.3")
        ax.set_yscale("log")
        if log_x:
            ax.set_xscale("log")
            ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels crowd a short log axis
        ax.set_xlabel(xlabel)
        ax.set_ylabel("mean RGB distance to abuffer (covered pixels)")
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(title)
    fig.legend(list(handles.values()), list(handles), loc="lower center", ncol=8, fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0.03 * legend_rows + 0.01, 1, 1))
    # Labels last, once the layout has fixed where every axes is.
    for ax, (key, _, _) in zip(axes, TRADE_AXES):
        _place_labels(ax, [(r[key], max(r["mean_err"], EXACT_BELOW), _label_value(r["params"])) for r in ok
                           if math.isfinite(r[key]) and r["mean_err"] >= EXACT_BELOW and _label_value(r["params"])])
    return fig


def tradeoff(rows: list[dict], title: str, path: str) -> None:
    """`tradeoff_figure` as a PNG at `path`."""
    import matplotlib.pyplot as plt

    fig = tradeoff_figure(rows, title)
    fig.savefig(path, dpi=80)
    plt.close(fig)


def image_sheet(images: dict[str, np.ndarray], title: str, path: str) -> None:
    """Each image (linear RGBA, first the exact `abuffer`) above its per-pixel RGB distance to
    the exact image, on the fixed logarithmic scale HEAT_RANGE. The tiles go into one array
    drawn by a single imshow, with the labels as text: one axes keeps this fast."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    exact = images["abuffer"][..., :3].astype(np.float64)
    f = max(1, exact.shape[1] // SHEET_TILE)
    h, w = exact.shape[0] // f, exact.shape[1] // f
    # Tiles are box-filtered to at most SHEET_TILE pixels a side (errors before filtering).
    shrink = lambda a: a[:h * f, :w * f].reshape(h, f, w, f, *a.shape[2:]).mean((1, 3))  # noqa: E731
    names = list(images)
    cols = min(SHEET_COLUMNS, len(names))
    lines = -(-len(names) // cols)
    gap = max(6, w // 10)
    norm, cmap = LogNorm(*HEAT_RANGE, clip=True), plt.get_cmap("magma")
    sheet = np.ones((2 * lines * (h + gap), cols * (w + gap), 3))
    ppi = min(100.0, (w + gap) / 1.9)  # pixels per inch: columns at least 1.9 inches wide, for the labels
    fig, ax = plt.subplots(figsize=(sheet.shape[1] / ppi + 1.5, sheet.shape[0] / ppi + 0.5))
    for i, name in enumerate(names):
        y, x = 2 * (i // cols) * (h + gap) + gap, (i % cols) * (w + gap)
        sheet[y:y + h, x:x + w] = linear_to_srgb(shrink(images[name][..., :3]))
        ax.text(x + w / 2, y - gap / 2, name, ha="center", va="center", fontsize=7)
        if name != "abuffer":
            dist = np.sqrt(((images[name][..., :3] - exact) ** 2).sum(-1))
            sheet[y + h:y + 2 * h, x:x + w] = cmap(norm(np.maximum(shrink(dist), HEAT_RANGE[0])))[..., :3]
            ax.text(x + w / 2, y + 2 * h + gap / 2, f"frame mean {dist.mean():.4f}", ha="center", va="center", fontsize=6)
    ax.imshow(sheet, interpolation="nearest")
    ax.axis("off")
    fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.5, label="RGB distance to abuffer")
    ax.set_title(title, fontsize=9, pad=12)
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)


def write_all(result: Any, out: str) -> list[str]:
    """The trade-off plot and the image sheet of every scene and size of an oit.bench.harness.Result, as
    PNGs in `out`; returns their paths."""
    paths = []
    for scene, size in dict.fromkeys((r["scene"], r["size"]) for r in result.rows):
        rows = [r for r in result.rows if r["scene"] == scene and r["size"] == size]
        adapter = next((r["adapter"] for r in rows if r["adapter"]), "")
        path = os.path.join(out, f"tradeoff-{scene}-{size}.png")
        tradeoff(rows, f"{scene} {size} on {adapter}", path)
        paths.append(path)
        sheet = result.sheets.get((scene, size), {})
        if "abuffer" in sheet:
            path = os.path.join(out, f"sheet-{scene}-{size}.png")
            image_sheet(sheet, f"{scene} {size}: each method (default parameters) and its error", path)
            paths.append(path)
    return paths


TEMPORAL_CLIP = 4.0  # bars of the temporal figure stop here, with their value written beside them


def temporal(rows: list[dict], path: str, columns: int = 3) -> None:
    """The temporal-stability figure of oit.bench.temporal.temporal: one panel per scene and size, a pair of
    bars per method — its mean change between consecutive frames and its flicker (the change
    of its error), both over abuffer's change — with abuffer's change (1) as a dashed line.
    A method that follows the motion exactly has bars at 1 and 0."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = list(dict.fromkeys((r["scene"], r["size"]) for r in rows))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    cols = min(columns, len(panels))
    lines = -(-len(panels) // cols)
    fig, axes = plt.subplots(lines, cols, figsize=(4.2 * cols, lines * (0.9 + 0.22 * len(methods)) + 0.6),
                             squeeze=False, sharey=True)
    y = np.arange(len(methods))
    for ax, (scene, size) in zip(axes.flat, panels):
        mine = {r["method"]: r for r in rows if (r["scene"], r["size"]) == (scene, size) and r["status"] == "ok"}
        for dy, key, color, label in ((-0.2, "change_ratio", "tab:blue", "mean change / abuffer's"),
                                      (0.2, "flicker_ratio", "tab:red", "flicker / abuffer's change")):
            values = np.array([mine[m][key] if m in mine else math.nan for m in methods], dtype=float)
            ax.barh(y + dy, np.minimum(values, TEMPORAL_CLIP), height=0.4, color=color, label=label)
            for yy, v in zip(y + dy, values):
                if v > TEMPORAL_CLIP:  # the unbounded sums (wsum, additive) would squash every other bar
                    ax.text(TEMPORAL_CLIP, yy, f" {v:.1f}", va="center", fontsize=6, color=color)
        ax.set_xlim(0, TEMPORAL_CLIP * 1.12)
        ax.axvline(1.0, color="0.3", linestyle="--", linewidth=1)
        ax.set_title(f"{scene} {size}", fontsize=9)
        ax.set_xlabel("over abuffer's mean change between frames", fontsize=8)
        ax.grid(True, axis="x", alpha=0.3)
        ax.set_yticks(y, methods, fontsize=8)
        ax.tick_params(axis="y", labelleft=True)
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    axes[0][0].invert_yaxis()
    first = rows[0]
    adapter = next((r["adapter"] for r in rows if r["adapter"]), "")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper right", fontsize=8, ncol=2)
    fig.suptitle(f"Temporal stability: {first['frames']} frames, camera orbit {first['step_deg']:g}° a frame, "
                 f"on {adapter}", fontsize=10, x=0.02, ha="left")
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    fig.savefig(path, dpi=90)
    plt.close(fig)


def scale(rows: list[dict], fits: list[dict], path: str, title: str) -> None:
    """One sweep of oit.bench.scale on log-log axes: GPU time against the swept quantity (wall
    time where no row has a GPU time: an adapter without timestamps), one line per method,
    labeled with its fitted slope (`fits`, oit.bench.scale.slopes); failed points are left out."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = [r for r in rows if r["status"] == "ok"]
    key = "gpu_ms" if any(0 < r["gpu_ms"] < math.inf for r in ok) else "wall_ms"
    slope = {f["method"]: f["slope" if key == "gpu_ms" else "wall_slope"] for f in fits}
    fig, ax = plt.subplots(figsize=(6.5, 4.8))
    for method in dict.fromkeys(r["method"] for r in rows):
        pts = sorted((r["x"], r[key]) for r in ok if r["method"] == method and 0 < r[key] < math.inf)
        s = slope.get(method, math.nan)
        label = f"{method} (slope {s:.2f})" if math.isfinite(s) else method
        if pts:
            ax.plot([x for x, _ in pts], [y for _, y in pts], marker="o", markersize=4, label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(rows[0]["x_name"] if rows else "x")
    ax.set_ylabel("GPU time (ms)" if key == "gpu_ms" else "wall time per frame (ms)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def write_scale(rows: list[dict], fits: list[dict], out: str) -> list[str]:
    """scale-<sweep>.png in `out` for each sweep of oit.bench.scale's rows; returns the paths."""
    paths = []
    for sweep in dict.fromkeys(r["sweep"] for r in rows):
        mine = [r for r in rows if r["sweep"] == sweep]
        adapter = next((r["adapter"] for r in mine if r["adapter"]), "")
        path = os.path.join(out, f"scale-{sweep}.png")
        scale(mine, [f for f in fits if f["sweep"] == sweep], path,
              f"{sweep} sweep ({mine[0]['scene']}): time against {mine[0]['x_name']}, on {adapter}")
        paths.append(path)
    return paths


def shading_cost(rows: list[dict], path: str) -> None:
    """oit.bench.shading's figure: one panel per scene and size, each method's time against the
    shading cost N (extra light evaluations per shaded fragment), labelled with its slope."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = [r for r in rows if r["status"] == "ok"]
    key = "gpu_ms" if ok and all(math.isfinite(r["gpu_ms"]) for r in ok) else "wall_ms"
    panels = list(dict.fromkeys((r["scene"], r["size"]) for r in rows))
    fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 4.4), squeeze=False)
    for ax, (scene, size) in zip(axes.flat, panels):
        for method in dict.fromkeys(r["method"] for r in rows):
            pts = sorted((r["shading_cost"], r[key]) for r in ok if (r["scene"], r["size"], r["method"]) == (scene, size, method))
            if not pts:
                continue
            slope = next(r["ms_per_100"] for r in ok if (r["scene"], r["size"], r["method"]) == (scene, size, method))
            ax.plot([x for x, _ in pts], [y for _, y in pts], marker="o", markersize=4,
                    label=f"{method} ({slope:.2f} ms / 100)")
        ax.set_xlabel("shading cost N (extra light evaluations a shaded fragment)")
        ax.set_ylabel("GPU time (ms, log)" if key == "gpu_ms" else "wall time per frame (ms, log)")
        ax.set_yscale("log")  # peeling's many passes would squash the other lines
        ax.set_title(f"{scene} {size}", fontsize=9)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    adapter = next((r["adapter"] for r in rows if r["adapter"]), "")
    fig.suptitle(f"Shading cost: time as each shaded fragment costs more, on {adapter}", fontsize=10, x=0.02, ha="left")
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(path, dpi=90)
    plt.close(fig)


def splat_trade(rows: list[dict], path: str) -> None:
    """The splat trade of oit.bench.splats.splat_trade: one panel per scene, each method a point
    at its mean error against the exact frame (x) and its flicker over abuffer-with-ray's
    change between frames (y), a circle with splat_depth="center", a triangle with "ray", the
    area growing with its time. Both logarithmic; the exact answer sits at the lower left."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = [r for r in rows if r["status"] == "ok"]
    scenes = list(dict.fromkeys(r["scene"] for r in ok))
    fig, axes = plt.subplots(1, len(scenes), figsize=(5.4 * len(scenes), 4.4), squeeze=False)
    methods = list(dict.fromkeys(r["method"] for r in ok))
    colors = {m: plt.get_cmap("tab10")(i % 10) for i, m in enumerate(methods)}
    fastest = min(r["ms"] for r in ok)
    for ax, scene in zip(axes[0], scenes):
        for r in (r for r in ok if r["scene"] == scene):
            # Zero error or flicker (the exact frame itself) drawn at the axis' floor.
            x, y = max(r["mean_err"], 1e-6), max(r["flicker_ratio"], 1e-4)
            marker = "o" if r["splat_depth"] == "center" else "^"
            ax.scatter(x, y, s=30 * math.sqrt(r["ms"] / fastest), marker=marker, color=colors[r["method"]], alpha=0.8)
            ax.annotate(f"{r['method']} {r['splat_depth'][0]}", (x, y), fontsize=6, xytext=(3, 2), textcoords="offset points")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(scene, fontsize=9)
        ax.set_xlabel("mean error against abuffer (ray)", fontsize=8)
        ax.set_ylabel("flicker / exact change between frames", fontsize=8)
        ax.grid(True, alpha=0.3, which="both")
    first = ok[0] if ok else {"splats": 0, "size": "", "adapter": ""}
    fig.suptitle(f"Gaussian splats: error and flicker ({first['splats']} splats, {first['size']}; o center, ^ ray; "
                 f"area ~ time; {first['adapter']})", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
