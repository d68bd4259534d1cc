"""The bench on a tiny configuration (a smoke test of its outputs and their consistency, not
a timing test), its parameter sweeps and error measures, and the pygfx peer's input match."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

import oit
from oit import cli, geometry, peers, plots, scenes
from oit.bench import auto, harness, results, scale, temporal
from oit.imageio import linear_to_srgb

TINY = dict(scenes=["glass"], methods=["abuffer", "unsorted", "sorted", "hybrid", "wboit"], sizes=[32], repeat=1,
            quick=True, with_peers=False, show_progress=False)


@pytest.fixture(scope="module")
def tiny():
    return results.run(**TINY)


def number(text):
    """A bench table's parameter value as the type the method declares (int, else float, else the string)."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def by_method(rows):
    return {r["method"]: r for r in rows}


def test_rows_are_consistent(tiny):
    rows = by_method(tiny.rows)
    assert set(rows) == set(TINY["methods"])
    assert all(r["status"] == "ok" and r["size"] == "32x32" for r in rows.values())
    # Every method saw the same geometry.
    assert len({(r["fragments"], r["max_depth"]) for r in rows.values()}) == 1
    assert rows["abuffer"]["mean_err"] == 0 and rows["abuffer"]["abuffer_speedup"] == 1
    # Glass defeats sorting; hybrid with k = 8 > 6 layers is exact up to its 8-bit alphas.
    assert rows["sorted"]["mean_err"] > 0.05
    assert rows["hybrid"]["mean_err"] < 0.01 < rows["wboit"]["mean_err"]
    for r in rows.values():
        assert r["mean_err_all"] <= r["mean_err"] <= r["max_err"]
        assert r["x_floor"] > 0 and r["wall_x_floor"] > 0
        formula = oit.memory_bytes(r["method"], 32, 32, **{k: number(v) for k, v in (p.split("=") for p in r["params"].split())})
        if formula is not None:
            assert r["memory_mib"] == r["formula_mib"] == formula / 2 ** 20
    assert set(tiny.sheets[("glass", "32x32")]) == set(TINY["methods"])


def test_a_failing_method_gives_a_failed_row(monkeypatch):
    real = oit.Renderer.render

    def render(self, scene, camera, method="abuffer", **kw):
        if method == "hybrid":
            raise RuntimeError("adapter limit: too many layers for this adapter\nsecond line")
        return real(self, scene, camera, method, **kw)

    monkeypatch.setattr(oit.Renderer, "render", render)
    rows = by_method(results.run(**TINY).rows)
    assert rows["hybrid"]["status"] == "failed"
    assert rows["hybrid"]["message"] == "adapter limit: too many layers for this adapter"
    assert math.isnan(rows["hybrid"]["mean_err"])
    assert rows["wboit"]["status"] == "ok"
    assert "| hybrid | k=8 tail=exact |" in harness.markdown(list(rows.values()), results.COLUMNS)
    assert "failed: adapter limit" in harness.markdown(list(rows.values()), results.COLUMNS)


def test_cli_writes_tables_and_plots(tmp_path, capsys):
    out = tmp_path / "bench"
    code = cli.main(["bench", "--quick", "--scenes", "glass", "--sizes", "32", "--methods", "abuffer", "unsorted",
                     "hybrid", "--no-peers", "--out", str(out)])
    assert code == 0
    with open(out / "results.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["method"] for r in rows] == ["abuffer", "unsorted", "hybrid"]
    table = (out / "results.md").read_text()
    assert table.startswith("Adapter: ") and sum(line.startswith("| glass |") for line in table.splitlines()) == 3
    if plots.matplotlib_missing() is None:
        assert (out / "tradeoff-glass-32x32.png").stat().st_size > 0
        assert (out / "sheet-glass-32x32.png").stat().st_size > 0
    else:
        assert "no plots: matplotlib is not installed" in capsys.readouterr().out


def test_unknown_method_is_named():
    with pytest.raises(ValueError, match=r"unknown method.*hybird"):
        results.run(["glass"], ["hybird"], [8], quick=True, with_peers=False, show_progress=False)


def test_defaults_runs_each_method_once_at_the_full_size():
    r = results.run(["glass"], ["hybrid", "abuffer"], [72], repeat=1, with_peers=False, show_progress=False, defaults=True)
    rows = [row for row in r.rows if row["method"] in ("hybrid", "abuffer")]
    assert sorted(row["method"] for row in rows) == ["abuffer", "hybrid"]  # hybrid's default k only, not its sweep
    assert {row["size"] for row in rows} == {"72x72"}  # past --quick's cap of 64
    assert rows[[row["method"] for row in rows].index("hybrid")]["params"] == "k=8 tail=exact"


def test_sweep_follows_the_declared_ranges():
    method = {"name": "m", "params": [
        {"name": "k", "type": "int", "min": 2, "max": 12, "default": 3},
        {"name": "w", "type": "choice", "choices": ["a", "b"], "default": "a"},
        {"name": "t", "type": "float", "min": 0.0, "max": 1.0, "default": 0.5},
        {"name": "seed", "type": "int", "min": 0, "max": 2 ** 32 - 1, "default": 0},
    ]}
    runs = harness.sweep(method)
    base = {"k": 3, "w": "a", "t": 0.5, "seed": 0}
    assert base in runs and len(runs) == len({tuple(r.items()) for r in runs})
    assert sorted(r["k"] for r in runs if r["w"] == "a" and r["t"] == 0.5) == [2, 3, 4, 8]
    assert {r["w"] for r in runs} == {"a", "b"} and {r["t"] for r in runs} == {0.0, 0.5, 1.0}
    assert {r["seed"] for r in runs} == {0}
    assert harness.sweep(method, quick=True) == [base]
    assert harness.sweep({"name": "plain", "params": []}) == [{}]
    # A stepped count (mboit's moments: 4, 6, 8) keeps to its step.
    stepped = {"name": "s", "params": [{"name": "n", "type": "int", "min": 4, "max": 8, "default": 6, "step": 2}]}
    assert [r["n"] for r in harness.sweep(stepped)] == [4, 6, 8]


def test_image_errors():
    exact = np.zeros((4, 4, 4), np.float32)
    image = exact.copy()
    image[:2, :, :3] = 0.1  # the top half is off by 0.1 per channel
    covered = np.zeros((4, 4), bool)
    covered[:2] = True
    e = harness.image_errors(image, exact, covered)
    assert e["mean_err"] == pytest.approx(0.1 * math.sqrt(3)) == e["max_err"]
    assert e["mean_err_all"] == pytest.approx(0.05 * math.sqrt(3))
    assert e["rmse"] == pytest.approx(0.1) and e["psnr"] == pytest.approx(20.0)
    assert harness.image_errors(exact, exact, covered)["psnr"] == math.inf
    if harness.flip_missing() is None:
        assert e["flip"] > 0 and harness.image_errors(exact, exact, covered)["flip"] == 0
    else:
        assert math.isnan(e["flip"])


def test_pareto_front():
    points = [(1.0, 5.0), (2.0, 3.0), (3.0, 4.0), (4.0, 1.0), (2.0, 6.0)]
    assert plots.pareto_front(points) == [0, 1, 3]


# ---- pygfx, the peer: the same input gives the same picture

needs_pygfx = pytest.mark.skipif(peers.pygfx_missing() is not None, reason=str(peers.pygfx_missing()))
PEER_SIZE = 48


def srgb8(image):
    return np.rint(linear_to_srgb(image[..., :3]) * 255.0)


@needs_pygfx
def test_pygfx_draws_an_opaque_scene_as_we_do(renderer):
    """Opaque meshes with random linear vertex colors under a perspective camera, on a colored
    background: if colors, camera or background were converted differently, whole regions
    would differ; pygfx stores 8-bit sRGB, so one step of that is the tolerance."""
    rng = np.random.default_rng(5)
    meshes = []
    for _ in range(5):
        p, i = geometry.uv_sphere(rng.uniform(-0.5, 0.5, 3), rng.uniform(0.2, 0.4), 8, 16)
        meshes.append(scenes.MeshArrays(p, i, rng.uniform(0, 1, (len(p), 4)).astype(np.float32), opaque=True))
    camera = oit.Camera.look_at(eye=(0.7, 0.5, 2.5), target=(0.0, 0.0, 0.0), fov_y=45.0, near=1.0, far=5.0)
    built = scenes.from_meshes(meshes, camera)
    background = (0.2, 0.5, 0.9)
    ours = renderer(PEER_SIZE, PEER_SIZE).render(built.scene, built.camera, "abuffer", background=background).image
    theirs, _ = peers.pygfx_renderer(PEER_SIZE, PEER_SIZE).render(built, "solid", background)
    assert np.abs(srgb8(ours) - srgb8(theirs)).max() <= 1


@needs_pygfx
def test_pygfx_blend_sorts_objects_back_to_front_as_sorted_does(renderer):
    """Three transparent quads, separate in depth, submitted nearest first: pygfx's blend mode
    sorts objects by their view depth, so it must agree with our `sorted` (not `unsorted`); a
    camera passed with the wrong depth direction would reverse its order."""
    camera = oit.Camera.look_at(eye=(0.3, 0.2, 3.0), target=(0.0, 0.0, 0.0), fov_y=45.0, near=1.0, far=6.0)
    meshes = [scenes.MeshArrays(*geometry.quad((0.1 * k, 0.0, 0.5 - 0.5 * k), 1.2), np.tile(rgba, (4, 1)).astype(np.float32))
              for k, rgba in enumerate([(0.9, 0.1, 0.1, 0.5), (0.1, 0.9, 0.1, 0.5), (0.1, 0.1, 0.9, 0.5)])]
    built = scenes.from_meshes(meshes, camera)
    r = renderer(PEER_SIZE, PEER_SIZE)
    ours = {m: r.render(built.scene, built.camera, m).image for m in ("sorted", "unsorted")}
    theirs, _ = peers.pygfx_renderer(PEER_SIZE, PEER_SIZE).render(built, "blend")
    assert np.abs(srgb8(ours["sorted"]) - srgb8(theirs)).max() <= 2
    assert np.abs(srgb8(ours["unsorted"]) - srgb8(theirs)).max() > 30


@needs_pygfx
def test_bench_puts_pygfx_rows_in_the_table():
    rows = by_method(results.run(**{**TINY, "methods": ["abuffer", "unsorted"], "with_peers": True}).rows)
    for mode in peers.PYGFX_MODES:
        row = rows[f"pygfx-{mode}"]
        assert row["status"] == "ok" and row["wall_ms"] > 0 and row["mean_err"] >= 0, row
        assert row["adapter"].startswith("pygfx on ") and math.isnan(row["gpu_ms"])


# ---- temporal stability

def test_orbit_turns_about_the_scene_center():
    built = scenes.glass(detail=8)
    cameras = temporal.orbit(built, frames=4, step_deg=2.0)
    assert len(cameras) == 4 and np.array_equal(cameras[0].view_proj, built.camera.view_proj)

    def ndc(camera, p):
        clip = camera.view_proj @ np.append(p, 1.0)
        return clip[:3] / clip[3]

    # Glass is centered on the origin: points on the vertical axis through it stay put, a point
    # off the axis moves, further each frame.
    for p in ((0.0, 0.0, 0.0), (0.0, 0.4, 0.0)):
        assert all(np.allclose(ndc(c, p), ndc(cameras[0], p), atol=1e-12) for c in cameras)
    moved = [np.linalg.norm(ndc(c, (0.5, 0.0, 0.5)) - ndc(cameras[0], (0.5, 0.0, 0.5))) for c in cameras]
    assert 0 < moved[1] < moved[2] < moved[3] < 0.2


def test_frame_changes():
    rng = np.random.default_rng(3)
    exact = [rng.uniform(0, 1, (6, 6, 4)) for _ in range(4)]
    covered = [np.ones((6, 6), bool) for _ in range(4)]
    for c in covered:
        c[0] = False  # the top row is never covered: what happens there does not count
    offset = [e + 0.1 for e in exact]  # a constant error follows the motion exactly
    eps = 0.01
    noisy = [e + (eps if t % 2 else -eps) for t, e in enumerate(exact)]  # an error that flips every frame
    for images in (offset, noisy):
        for im in images:
            im[0] = rng.uniform(0, 1, (6, 4))
    ref = temporal.frame_changes(exact, exact, covered)
    steps = [np.sqrt(((exact[t + 1][1:, :, :3] - exact[t][1:, :, :3]) ** 2).sum(-1)) for t in range(3)]
    assert ref["change"] == pytest.approx(np.mean(steps)) and ref["flicker"] == 0 == ref["max_flicker"]
    still = temporal.frame_changes(offset, exact, covered)
    assert still["change"] == pytest.approx(ref["change"]) and still["flicker"] == pytest.approx(0, abs=1e-12)
    flips = temporal.frame_changes(noisy, exact, covered)
    assert flips["flicker"] == pytest.approx(2 * eps * math.sqrt(3)) == flips["max_flicker"]


TEMPORAL_TINY = dict(scenes=["glass"], methods=["hybrid", "unsorted", "stochastic"], sizes=[24], frames=3, quick=True,
                     show_progress=False)


def test_temporal_rows():
    result = temporal.temporal(**TEMPORAL_TINY, step_deg=1.0)
    rows = by_method(result.rows)
    assert list(rows) == ["abuffer", "unsorted", "hybrid", "stochastic"]  # abuffer, then as in oit.methods()
    for r in rows.values():
        assert set(r) >= {c for c, _ in temporal.TEMPORAL_COLUMNS}
        assert r["status"] == "ok" and r["size"] == "24x24" and r["frames"] == 3 and r["step_deg"] == 1.0
        assert r["change"] > 0 and r["flicker"] <= r["max_flicker"]
    assert rows["abuffer"]["change_ratio"] == 1 and rows["abuffer"]["flicker"] == 0 == rows["abuffer"]["flicker_ratio"]
    assert rows["hybrid"]["mean_err"] < 0.01 < rows["unsorted"]["mean_err"]  # glass defeats submission order
    for r in rows.values():
        assert r["change_ratio"] == r["change"] / rows["abuffer"]["change"]


def test_temporal_with_a_still_camera_sees_no_change():
    # Every method repeats its frame bit for bit (stochastic is seeded), so nothing changes.
    for r in temporal.temporal(**TEMPORAL_TINY, step_deg=0.0).rows:
        assert r["change"] == 0 and r["flicker"] == 0 and math.isnan(r["change_ratio"]), r["method"]


def test_cli_temporal_writes_table_and_figure(tmp_path):
    out = tmp_path / "bench"
    code = cli.main(["bench", "--temporal", "--quick", "--scenes", "glass", "--sizes", "24", "--methods", "hybrid",
                     "--frames", "3", "--out", str(out)])
    assert code == 0
    with open(out / "temporal.csv") as f:
        assert [r["method"] for r in csv.DictReader(f)] == ["abuffer", "hybrid"]
    assert (out / "temporal.md").read_text().startswith("Adapter: ")
    assert not (out / "results.csv").exists()  # instead of the sweep, not beside it
    if plots.matplotlib_missing() is None:
        assert (out / "temporal.png").stat().st_size > 0


# ---- auto against fixed k

def test_smallest_k_scans_upward_and_stops_at_the_first():
    errors = {1: 0.5, 2: 0.1, 3: 0.3, 4: 0.05}  # not monotone in k, as hybrid's need not be
    asked = []
    error = lambda k: asked.append(k) or errors[k]  # noqa: E731
    assert auto.smallest_k(error, 0.2, max_k=4) == 2 and asked == [1, 2]
    assert auto.smallest_k(error, 0.06, max_k=4) == 4
    assert auto.smallest_k(error, 0.3, max_k=4) == 2
    assert auto.smallest_k(error, 0.01, max_k=4) is None
    assert auto.smallest_k(error, 0.06, max_k=3) is None


AUTO_TINY = dict(scenes=["glass"], sizes=[24], tolerances=(1 / 255, 16 / 255), repeat=1, max_k=8, quick=True,
                 show_progress=False)


def test_auto_against_fixed_k(renderer):
    result = auto.auto_vs_fixed(**AUTO_TINY)
    assert [r["tolerance"] for r in result.rows] == list(AUTO_TINY["tolerances"])
    built = scenes.glass()
    r24 = renderer(24, 24)
    exact = r24.render(built.scene, built.camera, "abuffer").image
    measured = {k: auto.max_abs_error(r24.render(built.scene, built.camera, "hybrid", k=k).image, exact)
                for k in range(1, AUTO_TINY["max_k"] + 1)}
    for row in result.rows:
        t = row["tolerance"]
        assert set(row) >= {c for c, _ in auto.AUTO_COLUMNS} and row["status"] == "ok"
        # auto's promise: every channel of every pixel within t of the exact image.
        assert row["within_t"] is True and row["auto_max_abs"] <= t
        assert row["auto_max_err"] <= row["auto_max_err_all"] and row["auto_mib"] > 0
        assert row["auto_exact"] in (0, 1) and row["auto_attempts"] >= 1
        # The fixed k is the first that meets t, by the same measure.
        k = row["fixed_k"]
        below = range(1, (AUTO_TINY["max_k"] + 1) if k == "none" else k)
        assert all(measured[j] > t for j in below)
        if k != "none":
            assert row["fixed_max_abs"] == measured[k] <= t
            assert row["mib_ratio"] == row["auto_mib"] / row["fixed_mib"]
            assert row["gpu_ms_ratio"] == row["auto_gpu_ms"] / row["fixed_gpu_ms"]
            assert row["fixed_mib"] * 2 ** 20 == oit.memory_bytes("hybrid", 24, 24, k=k)
        else:
            assert math.isnan(row["mib_ratio"])
    assert any(r["fixed_k"] != "none" for r in result.rows)


def test_auto_over_its_tolerance_is_flagged(monkeypatch, tmp_path, capsys):
    real = oit.Renderer.render

    def render(self, scene, camera, method="abuffer", **kw):
        frame = real(self, scene, camera, method, **kw)
        if method == "auto":
            frame.image[0, 0, :3] += 0.5  # a pixel far off: what a broken auto would return
        return frame

    monkeypatch.setattr(oit.Renderer, "render", render)
    code = cli.main(["bench", "--auto", "--quick", "--scenes", "glass", "--sizes", "24", "--tolerances", "0.0627",
                     "--max-k", "4", "--out", str(tmp_path)])
    assert code == 1
    assert "auto exceeded its tolerance on glass 24x24" in capsys.readouterr().err
    with open(tmp_path / "auto.csv") as f:
        (row,) = list(csv.DictReader(f))
    assert row["within_t"] == "False" and float(row["auto_max_abs"]) > 0.0627


# ---- cost as the work grows (--scale)

SCALE_TINY = dict(methods=["unsorted", "abuffer", "hybrid"], sizes=[(16, 16), (24, 16)], strands=[40, 80], layers=[2, 4],
                  repeat=1, quick=True, show_progress=False)


@pytest.fixture(scope="module")
def scaled():
    return scale.scale(**SCALE_TINY)


def test_scale_rows_are_consistent(scaled, tmp_path):
    rows = scaled.rows
    per_strand = scale.HAIR_TRIANGLES_PER_STRAND
    for sweep, xs in (("resolution", [256, 384]), ("triangles", [40 * per_strand, 80 * per_strand]), ("depth", [2, 4])):
        mine = [r for r in rows if r["sweep"] == sweep]
        assert sorted({r["x"] for r in mine}) == xs
        for x in xs:  # every method at every point, abuffer (the reference) first
            assert [r["method"] for r in mine if r["x"] == x] == ["abuffer", "unsorted", "hybrid"]
    for r in rows:
        assert r["status"] == "ok" and r["message"] == "", r
        assert r["tiles"] >= 1 and r["chunks"] >= 1 and r["fragments"] > 0 and r["peak_mib"] >= r["memory_mib"] >= 0
        assert r["wall_ms"] > 0 and (r["mean_err"] == 0 if r["method"] == "abuffer" else r["mean_err"] >= 0)
        if r["sweep"] == "depth":
            assert r["max_depth"] == r["x"] and r["size"] == "8x8"  # a stack of x layers in every pixel
        elif r["sweep"] == "triangles":
            assert r["triangles"] == r["x"]
    assert {r["size"] for r in rows if r["sweep"] == "resolution"} == {"16x16", "24x16"}
    fits = scale.slopes(rows)
    assert [(f["sweep"], f["method"]) for f in fits] == [(s, m) for s in scale.SWEEPS for m in ("abuffer", "unsorted", "hybrid")]
    for f in fits:
        assert f["points"] == 2 and math.isfinite(f["slope"]) and math.isfinite(f["wall_slope"]), f
    if plots.matplotlib_missing() is None:
        paths = plots.write_scale(rows, fits, str(tmp_path))
        assert [p.rsplit("/", 1)[1] for p in paths] == [f"scale-{s}.png" for s in scale.SWEEPS]
        assert all((tmp_path / f"scale-{s}.png").stat().st_size > 0 for s in scale.SWEEPS)


def test_scale_failed_and_skipped_methods(monkeypatch):
    real_render, real_info = oit.Renderer.render, oit.Renderer.adapter_info

    def render(self, scene, camera, method="abuffer", **kw):
        if method == "hybrid" and len(scene_sizes) == 1:
            raise MemoryError("hybrid needs 9 GiB\nsecond line")
        return real_render(self, scene, camera, method, **kw)

    scene_sizes = []  # the points seen so far: hybrid fails at the first only
    real_stacks = scenes.stacks
    monkeypatch.setattr(scenes, "stacks", lambda **kw: scene_sizes.append(kw) or real_stacks(**kw))
    monkeypatch.setattr(oit.Renderer, "render", render)
    info = {**real_info.fget(oit.Renderer(1, 1))}
    info["methods"] = [m for m in info["methods"] if m != "hybrid64"]
    monkeypatch.setattr(oit.Renderer, "adapter_info", property(lambda self: info))
    result = scale.scale(["depth"], ["abuffer", "hybrid", "hybrid64"], layers=[2, 4, 8], repeat=1, quick=True,
                         show_progress=False)
    assert {r["method"] for r in result.rows} == {"abuffer", "hybrid"}
    assert any("hybrid64 skipped" in n for n in result.notes)
    failed = [r for r in result.rows if r["status"] != "ok"]
    assert [(r["method"], r["x"], r["message"]) for r in failed] == [("hybrid", 2, "hybrid needs 9 GiB")]
    assert math.isnan(failed[0]["gpu_ms"])
    fits = {f["method"]: f for f in scale.slopes(result.rows)}
    assert fits["hybrid"]["points"] == 2 and math.isfinite(fits["hybrid"]["slope"])
    assert "failed: hybrid needs 9 GiB" in harness.markdown(result.rows, scale.SCALE_COLUMNS)


def test_fit_slope_and_sizes():
    xs = [10.0, 100.0, 1000.0]
    assert scale.fit_slope(xs, [3 * x ** 2 for x in xs]) == pytest.approx(2.0)
    assert scale.fit_slope(xs, [5.0, math.nan, 50.0]) == pytest.approx(0.5)  # failed points drop out
    assert math.isnan(scale.fit_slope(xs, [5.0, math.nan, 0.0])) and math.isnan(scale.fit_slope([], []))
    assert scale.parse_size("512") == (512, 512) and scale.parse_size("1920x1080") == (1920, 1080)
    with pytest.raises(ValueError, match="WxH"):
        scale.parse_size("big")
    with pytest.raises(ValueError, match=r"unknown method.*hybird"):
        scale.scale(methods=["hybird"], quick=True, show_progress=False)


def test_cli_scale_writes_tables_and_no_plots(tmp_path):
    out = tmp_path / "bench"
    code = cli.main(["bench", "--scale", "--quick", "--no-plots", "--methods", "abuffer", "unsorted", "--scale-sweeps",
                     "depth", "resolution", "--scale-sizes", "16", "24x16", "--scale-layers", "2", "4", "--out", str(out)])
    assert code == 0
    with open(out / "scale.csv") as f:
        rows = list(csv.DictReader(f))
    assert [(r["sweep"], r["size"], r["method"]) for r in rows] == [
        (s, size, m) for s, size in (("resolution", "16x16"), ("resolution", "24x16"), ("depth", "8x8"), ("depth", "8x8"))
        for m in ("abuffer", "unsorted")]
    with open(out / "scale-slopes.csv") as f:
        fits = list(csv.DictReader(f))
    assert len(fits) == 4 and all(math.isfinite(float(f["slope"])) for f in fits)
    table = (out / "scale.md").read_text()
    assert table.startswith("Adapter: ") and "## Slopes" in table and "slope: the least-squares slope" in table
    assert not list(out.glob("*.png"))


# ---- shading cost

def test_shading_cost_sweep_keeps_the_image_and_measures_each_method():
    from oit.bench import shading

    result = shading.shading_cost(["glass"], ["abuffer", "compact_abuffer", "hybrid"], sizes=[24], costs=(8,), repeat=1,
                                  quick=True, show_progress=False)
    rows = result.rows
    assert [(r["method"], r["shading_cost"]) for r in rows] == [(m, c) for m in ("abuffer", "compact_abuffer", "hybrid")
                                                              for c in (0, 8)]
    for r in rows:
        assert r["status"] == "ok" and r["same_image"] is True, r
        assert math.isfinite(r["ms_per_100"]) and r["wall_ms"] > 0
    assert {r["method"]: r["shadings"] for r in rows} == {"abuffer": "1", "compact_abuffer": "stored only (deferred)",
                                                          "hybrid": "1 + alpha"}


def test_cli_strands_writes_the_strand_table(tmp_path):
    code = cli.main(["bench", "--strands", "--quick", "--methods", "unsorted", "--out", str(tmp_path)])
    assert code == 0
    with open(tmp_path / "strands.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["method"] for r in rows] == ["unsorted"]
    # Points and a word a segment against two shaded vertices a point and six indices a segment.
    assert float(rows[0]["bytes_x"]) > 3.0
    # The moving camera builds the corners in its frames; the still one kept them.
    assert float(rows[0]["moving_wall_ms"]) > 0 and "expand_ms" in rows[0]
    assert (tmp_path / "strands.md").read_text().count("| 300 | unsorted |") == 1
