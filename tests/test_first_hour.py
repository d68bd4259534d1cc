"""What a newcomer sees in the first hour: the command line checks its optional dependencies
before it renders, its lines say one consistent thing (alpha, counts by primitive kind, where
the tables went, which memory figure a summary quotes), the trade plot's labels do not overlap,
and the demo needs nothing outside the package."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import oit
from oit import cli
from oit.comparison import Comparison


def run_oit(*args: str, cwd: Path, block: str = "") -> subprocess.CompletedProcess:
    """`python -m oit ARGS`; `block` names modules made unimportable first (an install without them)."""
    code = f"import sys\nfor m in {block.split()!r}: sys.modules[m] = None\nfrom oit.cli import main\nsys.exit(main(sys.argv[1:]))"
    return subprocess.run([sys.executable, "-c", code, *args], cwd=cwd, capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize(("output", "block", "install"), [("x.gif", "PIL", "pip install pillow"),
                                                         ("x.mp4", "imageio_ffmpeg", "pip install imageio imageio-ffmpeg")])
def test_orbit_checks_its_writer_before_rendering(tmp_path, box_obj, output, block, install):
    done = run_oit("render", str(box_obj), "--orbit", "2", "--size", "16", "16", "-o", output, cwd=tmp_path, block=block)
    assert done.returncode != 0
    assert install in done.stderr and "oit[video]" in done.stderr, done.stderr
    assert "triangles" not in done.stdout, "it rendered before saying what is missing"
    assert not (tmp_path / output).exists()


def test_render_says_one_alpha(tmp_path, box_obj):
    done = run_oit("render", str(box_obj), "--size", "16", "16", "-o", "x.png", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "nothing in the file is transparent" in done.stdout
    assert "the file's alpha" not in done.stdout and "every mesh at alpha 0.4" in done.stdout, done.stdout
    assert "1 mesh (12 triangles)" in done.stdout, done.stdout


def test_render_counts_a_point_cloud_in_particles(tmp_path):
    rng = np.random.default_rng(1)
    rows = "".join(f"{x:.4f} {y:.4f} {z:.4f} 200 100 50 128\n" for x, y, z in rng.uniform(-1, 1, (500, 3)))
    head = ("ply\nformat ascii 1.0\nelement vertex 500\nproperty float x\nproperty float y\nproperty float z\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\nend_header\n")
    (tmp_path / "cloud.ply").write_text(head + rows)
    done = run_oit("render", "cloud.ply", "--size", "16", "16", "-o", "x.png", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    line = next(x for x in done.stdout.splitlines() if "method abuffer" in x)
    assert line.startswith("cloud.ply: 500 particles, ") and "triangles" not in line, done.stdout


def test_contents_by_primitive_kind():
    scene = oit.Scene()
    scene.add_particles(np.zeros((500, 3)), 0.05, (1, 0, 0, 0.5))
    scene.add_strands(np.zeros((12, 3)), np.array([4, 4, 4]), 0.01, (1, 0, 0, 0.5))
    m = scene.add_mesh(np.eye(3, dtype=np.float32), np.array([[0, 1, 2]]), (1, 0, 0, 0.5))
    scene.set_instances(m, np.stack([np.eye(4)] * 3))
    assert cli.describe_contents(scene) == "1 mesh (3 triangles), 500 particles, 3 strands (12 points)"


def test_bench_quick_says_where_its_tables_are(tmp_path, capsys):
    from oit.bench.harness import Result, write_tables

    write_tables(str(tmp_path), "results", Result(rows=[], notes=[]), [("method", "{}")])
    assert f"wrote {tmp_path / 'results.md'} and {tmp_path / 'results.csv'}" in capsys.readouterr().out


def test_compare_summary_quotes_the_peak_memory_it_says():
    row = {"method": "hybrid", "params": "k=8", "status": "ok", "message": "", "time_ms": 5.0, "max_err": 0.001,
           "memory_bytes": 2**20, "peak_memory_bytes": 3 * 2**20, "memory_mib": 1.0, "peak_mib": 3.0}
    result = Comparison(rows=[row], memory=2 * 2**20)
    assert "peak memory 3 MiB > 2 MiB" in result.summary()
    result.memory = None
    assert "peak memory 3 MiB" in result.summary()


# ---- the demo: generated, the README's picture, its blends visibly different


@pytest.fixture(scope="module")
def demo_result():
    from oit import demo, scenes

    def no_data() -> None:
        raise AssertionError("the demo looked for files outside the package")

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(scenes, "shared_data_dir", no_data)
        return demo.run()  # the size `make demo` renders


def test_the_demo_blends_differ_visibly(demo_result):
    sorted_, unsorted = (demo_result.frames[m].image[..., :3] for m in ("sorted", "unsorted"))
    assert np.abs(sorted_ - unsorted).max(-1).mean() > 0.01
    assert demo_result.errors["sorted"].mean() < 0.7 * demo_result.errors["unsorted"].mean()
    assert demo_result.errors["hybrid"].max() < 0.01


def test_the_readme_caption_quotes_the_run(demo_result):
    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text()
    caption = readme[readme.index("![A lit transparent"):readme.index("Order-independent transparency methods")]
    assert f"white {demo_result.vmax:.2f}" in caption, caption
    assert f"hybrid's max {float(demo_result.errors['hybrid'].max()):.4f}" in caption, caption


def test_the_readme_picture_is_the_demo_s(demo_result, tmp_path):
    image = pytest.importorskip("PIL.Image")
    from oit.imageio import write_png

    write_png(tmp_path / "demo.png", demo_result.mosaic)
    ours = np.asarray(image.open(tmp_path / "demo.png").convert("RGB"), dtype=np.float64)
    shown = np.asarray(image.open(Path(__file__).resolve().parent.parent / "docs" / "img" / "demo.png").convert("RGB"),
                       dtype=np.float64)
    assert ours.shape == shown.shape
    # 8-bit steps; a hardware adapter's float rounding moves a few pixels by one.
    assert np.abs(ours - shown).mean() < 0.5, "docs/img/demo.png is not what `make demo` draws: run it and copy out/demo.png"


# ---- the trade plot


def _trade_rows() -> list[dict]:
    """Rows as crowded as a compare run's: a sweep per method near one time, exact ones on the floor."""
    rng = np.random.default_rng(2)
    rows = []
    for i, method in enumerate(["abuffer", "sbuffer", "pall", "depth_peeling", "hybrid", "ktab", "mlab", "adaptive",
                                "wboit", "unsorted", "sorted", "stochastic", "auto"]):
        exact = i < 4
        for k in (1, 2, 4, 8, 16, 32):
            t = 0.3 + 0.05 * rng.random()
            rows.append({"method": method, "params": f"k={k} tail=exact", "status": "ok", "gpu_ms": t, "wall_ms": 2 * t,
                         "memory_mib": 0.5 + 0.02 * rng.random(), "mean_err": 0.0 if exact else 3e-3 * (1 + 0.1 * rng.random())})
    return rows


def test_the_trade_plot_s_labels_do_not_overlap():
    pytest.importorskip("matplotlib")
    import matplotlib.pyplot as plt
    from matplotlib.text import Text

    from oit import plots

    fig = plots.tradeoff_figure(_trade_rows(), "crowded")
    fig.canvas.draw()  # every tick and label where the PNG has it
    renderer = fig.canvas.get_renderer()
    boxes = []
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            boxes += [t.get_window_extent(renderer) for tick in axis.get_major_ticks() + axis.get_minor_ticks()
                      if lo <= tick.get_loc() <= hi for t in (tick.label1,) if t.get_visible() and t.get_text()]
            boxes.append(axis.label.get_window_extent(renderer))
        boxes += [t.get_window_extent(renderer) for t in ax.texts]
    boxes += [t.get_window_extent(renderer) for legend in fig.legends for t in legend.texts]
    boxes += [t.get_window_extent(renderer) for t in fig.texts if isinstance(t, Text) and t.get_text()]
    annotations = sum(len(ax.texts) for ax in fig.axes)
    plt.close(fig)
    assert annotations > 3 * 10, "the labels were all left out"
    overlaps = [(a, b) for i, a in enumerate(boxes) for b in boxes[i + 1:] if a.overlaps(b)
                and min(a.x1, b.x1) - max(a.x0, b.x0) > 0.5 and min(a.y1, b.y1) - max(a.y0, b.y0) > 0.5]
    assert not overlaps, f"{len(overlaps)} overlapping label boxes, e.g. {overlaps[:3]}"


# ---- setup's progress


def test_setup_prints_a_status_line_while_a_long_step_runs(tmp_path):
    script = (Path(__file__).resolve().parent.parent / "scripts" / "setup.sh").read_text()
    helpers = "\n".join(script[script.index(f"{name}() {{"):].split("\n}\n")[0] + "\n}" for name in ("with_status", "wait_for"))
    (tmp_path / "step.sh").write_text("for i in 1 2 3; do echo \"   Compiling crate$i\"; sleep 1; done\n")
    done = subprocess.run(["bash", "-c", f"set -euo pipefail\n{helpers}\nwith_status building bash {tmp_path / 'step.sh'}"],
                          env={"PATH": "/usr/bin:/bin", "SETUP_STATUS_EVERY": "1"}, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) >= 2 and all(line.startswith("setup: building: ") for line in lines), done.stdout
    assert "crates compiled so far" in lines[-1]
    failed = subprocess.run(["bash", "-c", f"set -euo pipefail\n{helpers}\nwith_status building bash -c 'echo boom; exit 3'"],
                            capture_output=True, text=True, timeout=60)
    assert failed.returncode == 3 and "boom" in failed.stderr and "building failed (exit 3)" in failed.stderr
