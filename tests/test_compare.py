"""`oit.compare` and `python -m oit compare FILE`: every method and its main parameter's sweep
on the caller's file, the tables, plot and sheet, and `Comparison.best` naming the cheapest
row that meets the limits (or saying which limit each missed)."""

from __future__ import annotations

import csv
import math
import subprocess
import sys

import pytest

import oit
from files import box_and_panel_glb
from oit.comparison import Comparison, plan
from oit.views import orbit_cameras

SIZE = 32
METHODS = ["abuffer", "wavg", "hybrid"]


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    # Everything at alpha 0.5: the box's front face (its back faces are culled) over the panel.
    scene = oit.Scene.from_file(box_and_panel_glb(tmp_path_factory.mktemp("cmp") / "two.glb"), alpha=0.5)
    return oit.compare(scene, orbit_cameras(scene, 2), SIZE, SIZE, METHODS, flip=False)


def test_the_plan_sweeps_each_main_parameter():
    runs = plan(["hybrid", "wavg"])
    hybrid = [p for m, p in runs if m == "hybrid"]
    k = next(p for p in next(m for m in oit.methods() if m["name"] == "hybrid")["params"] if p["name"] == "k")
    assert hybrid[0] == {"k": k["default"], "tail": "exact"}, "the defaults come first"
    assert sorted(p["k"] for p in hybrid) == sorted({v for v in (1, 2, 4, 8, 16, 32) if k["min"] <= v <= k["max"]} | {k["default"]})
    assert [p for m, p in runs if m == "wavg"] == [{}]
    with pytest.raises(ValueError, match="unknown method"):
        plan(["hybird"])


def test_rows_measure_every_view_against_the_exact_frame(result):
    assert [r["method"] for r in result.rows].count("hybrid") > 1
    by = {(r["method"], r["params"]): r for r in result.rows}
    assert all(r["status"] == "ok" and r["views"] == 2 for r in result.rows)
    assert by[("abuffer", "")]["max_err"] == 0
    assert by[("wavg", "")]["max_err"] > by[("wavg", "")]["mean_err"] > 0
    assert set(result.images) == set(METHODS)


def test_best_is_the_cheapest_row_that_meets_the_limits(result):
    for tol in (0.0, 0.05, 1.0):
        best = result.best(tolerance=tol)
        meeting = [r for r in result.rows if r["max_err"] <= tol]
        assert best in meeting and best["time_ms"] == min(r["time_ms"] for r in meeting)
        assert f"cheapest within max error <= {tol:g}: {best['method']}" in result.summary(tolerance=tol)
    assert result.best(tolerance=0.0, memory=1) is None
    text = result.summary(tolerance=0.0, time_ms=1e-9)
    assert text.startswith("no method meets") and "time" in text and "wavg : max error" in text.replace("  ", " ")
    assert "<table>" in result._repr_html_()


def test_ties_in_time_go_to_the_smaller_memory():
    row = {"status": "ok", "max_err": 0.0, "time_ms": 1.0, "method": "m", "params": ""}
    c = Comparison(rows=[{**row, "peak_memory_bytes": 200, "params": "a"}, {**row, "peak_memory_bytes": 100, "params": "b"},
                         {**row, "time_ms": 2.0, "peak_memory_bytes": 1, "params": "c"}])
    assert c.best()["params"] == "b"
    assert c.best(memory=50)["params"] == "c"


def test_a_memory_limit_renders_with_that_budget(tmp_path):
    scene = oit.Scene.from_file(box_and_panel_glb(tmp_path / "two.glb"), alpha=0.5)
    c = oit.compare(scene, orbit_cameras(scene, 1), SIZE, SIZE, ["hybrid"], memory=60_000, flip=False)
    default = c.rows[0]
    assert default["tiles"] > 1, "hybrid's k-TAB passes the budget: the frame is tiled"
    assert any("memory" in m for m in c.misses(default)) == (default["peak_memory_bytes"] > 60_000)
    with pytest.raises(ValueError, match="memory must be a positive number of bytes"):
        oit.compare(scene, orbit_cameras(scene, 1), SIZE, SIZE, ["hybrid"], memory=-1)


def test_the_command_writes_the_table_plot_and_sheet(tmp_path):
    out = tmp_path / "cmp"
    done = subprocess.run([sys.executable, "-m", "oit", "compare", str(box_and_panel_glb(tmp_path / "two.glb")), "--size",
                           str(SIZE), str(SIZE), "--views", "2", "--methods", *METHODS, "--tolerance", "0.05", "--out", str(out)],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "cheapest within max error <= 0.05" in done.stdout
    with open(out / "compare.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(plan(METHODS)) and all(math.isfinite(float(r["time_ms"])) for r in rows)
    assert "| method | params |" in (out / "compare.md").read_text()
    pytest.importorskip("matplotlib")
    assert (out / "tradeoff.png").stat().st_size > 0 and (out / "sheet.png").stat().st_size > 0
    bad = subprocess.run([sys.executable, "-m", "oit", "compare", str(tmp_path / "missing.glb")], cwd=tmp_path,
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "no such file" in bad.stderr
