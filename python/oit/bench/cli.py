"""The bench's command line (`python -m oit bench`, also `python -m oit.bench`): the main sweep
(oit.bench.results) or, instead of it, the experiments (--temporal, --auto, --antialias, --scale,
--shading-cost, --load, --fuzz-load, --gpu) or every command of docs/results.md (--report), and
the tables and plots they write into --out."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from .. import scenes as scene_lib
from .antialias import AA_COLUMNS, AA_METHODS, AA_SAMPLES, antialias
from .auto import AUTO_COLUMNS, AUTO_MAX_K, AUTO_TOLERANCES, auto_vs_fixed
from .claims import CLAIM_COLUMNS, run_claims
from .figure7 import figure7_table
from .floor import BASELINE, FLOOR_COLUMNS, GROWTH, load_baseline, peers_floor, write_baseline
from .floor import SCENES as FLOOR_SCENE_NAMES
from .gpu import run_gpu
from .harness import QUICK_SIZE, write_tables
from .load import LOAD_COLUMNS, LOAD_TRIANGLES, TARGET_TRIANGLES_PER_S, fuzz_load, load_speed
from .results import COLUMNS, run
from .scale import SCALE_METHODS, SWEEPS, parse_size, scale, write_scale
from .shading import SHADING_COLUMNS, SHADING_COSTS, SHADING_METHODS, shading_cost
from .splats import SCALE_COLUMNS as SPLAT_SCALE_COLUMNS
from .splats import SPLAT_COUNT, TRADE_COLUMNS, TRADE_METHODS, splat_scale, splat_trade
from .strands import STRAND_COLUMNS, STRAND_COUNTS, strands_vs_ribbons
from .strands import STRAND_METHODS as STRAND_METHODS_DEFAULT
from .temporal import TEMPORAL_COLUMNS, TEMPORAL_FRAMES, TEMPORAL_STEP_DEG, temporal


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--scenes", nargs="+", default=list(scene_lib.SHOWCASE), choices=sorted(scene_lib.SCENES),
                    help="scenes to run (default: %(default)s)")
    ap.add_argument("--methods", nargs="+", default=None,
                    help="methods to run (default: every method of `oit methods`; with --temporal every approximate one)")
    ap.add_argument("--sizes", type=int, nargs="+", default=None, help="square frame sizes (default: each scene's own)")
    ap.add_argument("--repeat", type=int, default=5, help="timed renders per row after one warm-up (median)")
    ap.add_argument("--out", default="out/bench", help="directory for the tables and the plots")
    ap.add_argument("--quick", action="store_true",
                    help=f"default parameters only, one timed render, frames of at most {QUICK_SIZE} pixels: a smoke test")
    ap.add_argument("--defaults", action="store_true",
                    help="each method at its default parameters only, at the full frame size (--quick also shrinks the frames)")
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
    ap.add_argument("--scale", action="store_true",
                    help="instead of the method sweep: cost as the work grows (the hybrid paper's Figures 8 to 10), "
                         f"{', '.join(SCALE_METHODS)} against frame size, triangles and layers (scale.csv, scale.md, "
                         "scale-slopes.csv, scale-<sweep>.png)")
    ap.add_argument("--scale-sweeps", nargs="+", default=list(SWEEPS), choices=SWEEPS,
                    help="--scale: the sweeps to run (default: %(default)s)")
    ap.add_argument("--scale-sizes", type=_size, nargs="+", default=None, metavar="N|WxH",
                    help="--scale: frame sizes of the resolution sweep (default: 256 512 1024 1920x1080 3840x2160)")
    ap.add_argument("--scale-strands", type=int, nargs="+", default=None,
                    help="--scale: hair strands of the triangle sweep, 32 triangles each (default: 6000 25000 100000 400000)")
    ap.add_argument("--shading-cost", action="store_true",
                    help="instead of the method sweep: time as shading a fragment costs more, each method (default: "
                         f"{', '.join(SHADING_METHODS)}) at --costs extra light evaluations per shaded fragment "
                         "(shading.csv, shading.md, shading.png; docs/shading.md)")
    ap.add_argument("--costs", type=int, nargs="+", default=list(SHADING_COSTS),
                    help="--shading-cost: extra light evaluations per fragment (default: %(default)s; 0 is always added)")
    ap.add_argument("--claims", action="store_true",
                    help="instead of the method sweep: the seeds' claims measured on this engine, each with a verdict "
                         "(claims.csv, claims.md; docs/claims.md); the quick ones only unless --full")
    ap.add_argument("--full", action="store_true", help="--claims: also the claims that need full-size scenes (minutes)")
    ap.add_argument("--only", nargs="+", default=None, metavar="ID",
                    help="--claims: just these claims, quick or full (ids as in docs/claims.md)")
    ap.add_argument("--peers-floor", action="store_true",
                    help="instead of the method sweep: the floor and the methods over it against pygfx on the same fixed "
                         "arrays, unlit and lit, as ratios to pygfx in this run, each against its target and against the "
                         f"baseline in {BASELINE.name} (floor.csv, floor.md); exits 1 when a ratio grew by more than "
                         f"{GROWTH * 100:.0f}%%")
    ap.add_argument("--update-baseline", action="store_true",
                    help="--peers-floor: keep this run's ratios as the new baseline (after a change that is meant to cost "
                         "time); it is the package's file, so run from an editable install (scripts/dev-install.sh) "
                         "to change the repository's")
    ap.add_argument("--strands", action="store_true",
                    help="instead of the method sweep: hair as a strand set against the same hair as triangle ribbons, "
                         "upload bytes, upload time and frame time of the floor and the methods over it (strands.csv, "
                         f"strands.md); --strand-counts sets the hair sizes (default: {' '.join(map(str, STRAND_COUNTS))})")
    ap.add_argument("--strand-counts", type=int, nargs="+", default=list(STRAND_COUNTS), help=argparse.SUPPRESS)
    ap.add_argument("--scale-layers", type=int, nargs="+", default=None,
                    help="--scale: layers of the depth sweep's stacks (default: 4 40 400 4000)")
    ap.add_argument("--splats", action="store_true",
                    help="instead of the method sweep: on Gaussian splats (oit.scenes.splats, surface and cloud), each "
                         "method's time, memory, error and flicker over an orbit against abuffer with splat_depth='ray', "
                         "with both depth choices (splats.csv, splats.md, splats.png)")
    ap.add_argument("--splat-count", type=int, default=SPLAT_COUNT, help="--splats: splats a scene (default: %(default)s)")
    ap.add_argument("--splat-scale", action="store_true",
                    help="instead of the method sweep: a million splats rendered by every bounded method at 512² and "
                         "1920x1080 under a 256 MiB memory_budget (splat-scale.csv, splat-scale.md)")
    ap.add_argument("--load", action="store_true",
                    help=f"instead of the method sweep: a {LOAD_TRIANGLES / 1e6:.1f} M-triangle mesh as OBJ, GLB, binary PLY "
                         "and binary STL, each loaded by Scene.from_file in a fresh interpreter: triangles a second "
                         f"(target {TARGET_TRIANGLES_PER_S / 1e6:.0f} M) and peak resident memory (load.csv, load.md)")
    ap.add_argument("--load-triangles", type=int, default=LOAD_TRIANGLES, help=argparse.SUPPRESS)
    ap.add_argument("--fuzz-load", action="store_true",
                    help="instead of the method sweep: mutated files of every format loaded for --seconds from --seed; "
                         "exits 1 on anything but a scene, ValueError or OSError (a panic, another exception, a hang, "
                         "runaway memory), keeping the failing files in --out")
    ap.add_argument("--seconds", type=float, default=60.0, help="--fuzz-load: how long to run (default: %(default)s)")
    ap.add_argument("--seed", type=int, default=0, help="--fuzz-load: the random seed (default: %(default)s)")
    ap.add_argument("--fuzz-cases", type=int, default=None, help=argparse.SUPPRESS)
    ap.add_argument("--gpu", action="store_true",
                    help="instead of the method sweep: what may turn on a GPU, about 6 minutes on a hardware adapter (never "
                         "lavapipe), each part under a time limit (gpu.md, gpu.json; scripts/gpu-bench.sh, oit.bench.gpu)")
    ap.add_argument("--small", action="store_true", help="--gpu: the same on any adapter at tiny sizes (seconds)")
    ap.add_argument("--report", action="store_true",
                    help="instead of the method sweep: every command docs/results.md prints above its tables, each "
                         "into <out>/NN/ (default out: out/report); with --quick at the smoke test's sizes")
    ap.add_argument("--list", "--dry-run", dest="list_only", action="store_true",
                    help="--report: only print the commands")
    ap.add_argument("--doc", default=None, help="--report: the results doc (default: the repository's docs/results.md)")


def _size(text: str) -> tuple[int, int]:
    try:
        return parse_size(text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def _plot(a: argparse.Namespace, name: str, draw: str, rows: list) -> None:
    """Draws `rows` with `plots.<draw>` into `<out>/<name>.png`, unless the plots are skipped."""
    if _plots_missing(a):
        return
    from .. import plots

    path = os.path.join(a.out, f"{name}.png")
    getattr(plots, draw)(rows, path)
    print(f"wrote {path}")


def _plots_missing(a: argparse.Namespace) -> bool:
    """True (and says why) when the plots are to be skipped."""
    if a.no_plots:
        return True
    from .. import plots

    missing = plots.matplotlib_missing()
    if missing:
        print(f"note: no plots: {missing}")
    return missing is not None


def run_cli(a: argparse.Namespace) -> int:
    repeat = 1 if a.quick else max(1, a.repeat)
    if a.report:
        from .report import run_report

        ap = argparse.ArgumentParser(prog="python -m oit bench", exit_on_error=False)
        add_arguments(ap)
        a.out = "out/report" if a.out == "out/bench" else a.out
        return run_report(a, ap, run_cli)
    if a.gpu:
        return run_gpu(a.out, a.small)
    if a.load or a.fuzz_load:
        if a.load:
            write_tables(a.out, "load", load_speed(a.load_triangles), LOAD_COLUMNS)
        if a.fuzz_load:
            report = fuzz_load(a.seconds, a.seed, a.out, a.fuzz_cases)
            for f in report.failures:
                print(f"error: {f}", file=sys.stderr)
            print(report.summary())
            return 1 if report.failures else 0
        return 0
    if a.peers_floor:
        # The floor's scenes among --scenes (by default all three of them).
        scenes = tuple(s for s in FLOOR_SCENE_NAMES if s in a.scenes) or FLOOR_SCENE_NAMES
        result = peers_floor(scenes, repeat, a.quick, baseline=load_baseline())
        write_tables(a.out, "floor", result, FLOOR_COLUMNS)
        missed = [r for r in result.rows if r["meets"] == "no"]
        for r in missed:
            print(f"note: {r['scene']} {r['shading']} {r['method']} is {r['ratio']:.2f}x pygfx, past its target {r['target']:.1f}x")
        slower = [r for r in result.rows if r["flag"]]
        for r in slower:
            print(f"error: {r['scene']} {r['shading']} {r['method']}: {r['ratio']:.2f}x pygfx against {r['baseline']:.2f}x in "
                  f"the baseline ({r['growth']:+.0%})", file=sys.stderr)
        if a.update_baseline and not a.quick:
            write_baseline(result)
            print(f"wrote {BASELINE}")
            return 0
        return 1 if slower else 0
    if a.strands:
        methods = tuple(a.methods) if a.methods else None
        result = strands_vs_ribbons(tuple(a.strand_counts), methods or STRAND_METHODS_DEFAULT, repeat, a.quick)
        write_tables(a.out, "strands", result, STRAND_COLUMNS)
        return 0
    if a.claims:
        write_tables(a.out, "claims", run_claims(full=a.full, only=a.only), CLAIM_COLUMNS)
        return 0
    if a.splats or a.splat_scale:
        methods = tuple(a.methods) if a.methods else None
        if a.splats:
            size = a.sizes[0] if a.sizes else 256
            result = splat_trade(methods=methods or TRADE_METHODS, count=a.splat_count, size=size,
                                 frames=a.frames, step_deg=a.step, quick=a.quick)
            write_tables(a.out, "splats", result, TRADE_COLUMNS)
            _plot(a, "splats", "splat_trade", result.rows)
        if a.splat_scale:
            write_tables(a.out, "splat-scale", splat_scale(methods=methods, quick=a.quick), SPLAT_SCALE_COLUMNS)
        return 0
    if a.temporal or a.auto or a.antialias or a.scale or a.shading_cost:
        if a.shading_cost:
            if any(c < 0 for c in a.costs):
                raise ValueError(f"--costs must be >= 0, got {a.costs}")
            result = shading_cost(a.scenes, a.methods, a.sizes, tuple(a.costs), repeat, a.quick)
            write_tables(a.out, "shading", result, SHADING_COLUMNS)
            _plot(a, "shading", "shading_cost", result.rows)
        if a.scale:
            result = scale(a.scale_sweeps, a.methods, a.scale_sizes, a.scale_strands, a.scale_layers, repeat, a.quick)
            fits = write_scale(a.out, result)
            if not _plots_missing(a):
                from .. import plots

                for path in plots.write_scale(result.rows, fits, a.out):
                    print(f"wrote {path}")
        if a.antialias:
            result = antialias(a.scenes, a.methods, a.sizes, tuple(a.aa_samples), repeat, a.quick)
            write_tables(a.out, "antialias", result, AA_COLUMNS)
        if a.temporal:
            result = temporal(a.scenes, a.methods, a.sizes, a.frames, a.step, a.quick)
            write_tables(a.out, "temporal", result, TEMPORAL_COLUMNS)
            _plot(a, "temporal", "temporal", result.rows)
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
    result = run(a.scenes, a.methods, a.sizes, repeat, a.quick, with_peers=not a.no_peers, defaults=a.defaults)
    write_tables(a.out, "results", result, COLUMNS)
    if not _plots_missing(a):
        from .. import plots

        for path in plots.write_all(result, a.out):
            print(f"wrote {path}")
    if a.figure7:
        fig7 = figure7_table()
        with open(os.path.join(a.out, "figure7.md"), "w") as f:
            f.write(fig7 + "\n")
        print("\nFigure 7 (mean per-pixel RGB distance to the A-buffer, 400 stacks):")
        print(fig7)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """`python -m oit.bench`, the same as `python -m oit bench`."""
    ap = argparse.ArgumentParser(prog="python -m oit bench",
                                 description="time, memory and error of every method against the exact A-buffer")
    add_arguments(ap)
    return run_cli(ap.parse_args(argv))
