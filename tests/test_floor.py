"""`python -m oit bench --peers-floor`: its fixed input, its lit and unlit scenes, the command
(on a small frame: a check that it runs, not a measurement) and the baseline comparison."""

from __future__ import annotations

import csv
import hashlib
import json

import numpy as np
import pytest

import oit
from oit import cli, peers
from oit.bench import floor

needs_pygfx = pytest.mark.skipif(peers.pygfx_missing() is not None, reason=str(peers.pygfx_missing()))

# The floor's input is frozen: a changed file would silently change what every baseline ratio means.
FLOOR_SHA256 = "181f8f06b2d6410d8ef5cdc0ef6aeadf9570271eee45a163c2e1c76adf20b923"


def test_the_input_is_the_frozen_one():
    digest = hashlib.sha256(floor.FLOOR_SCENES.read_bytes()).hexdigest()
    assert digest == FLOOR_SHA256, "floor_scenes.npz changed: the baseline's ratios no longer describe this input"


@pytest.mark.parametrize("name", floor.SCENES)
def test_floor_scenes_unlit_and_lit(name):
    unlit, lit = floor.floor_scene(name, False), floor.floor_scene(name, True)
    assert [m.opaque for m in unlit.meshes] == [m.opaque for m in lit.meshes]
    assert not oit.scenes.is_lit(unlit) and oit.scenes.is_lit(lit)
    for u, m in zip(unlit.meshes, lit.meshes):
        np.testing.assert_array_equal(u.positions, m.positions)
        n = m.surface["normals"]
        assert n.shape == m.positions.shape and np.isfinite(n).all()
    np.testing.assert_array_equal(unlit.camera.view_proj, lit.camera.view_proj)


def test_vertex_normals_of_a_quad():
    p = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
    n = floor.vertex_normals(p, np.array([[0, 1, 2], [0, 2, 3]], np.uint32))
    np.testing.assert_allclose(n, [[0, 0, 1]] * 4)


@needs_pygfx
def test_cli_peers_floor_runs_and_writes_its_table(tmp_path):
    out = tmp_path / "floor"
    assert cli.main(["bench", "--peers-floor", "--quick", "--scenes", "glass", "--out", str(out)]) == 0
    with open(out / "floor.csv") as f:
        rows = list(csv.DictReader(f))
    assert [(r["shading"], r["method"]) for r in rows] == [(s, m) for s in floor.SHADINGS for m, _, _ in floor.ROWS]
    for r in rows:
        assert float(r["ours_ms"]) > 0 and float(r["peer_ms"]) > 0 and r["peer"].startswith("pygfx ")
        assert float(r["ratio"]) == pytest.approx(float(r["ours_ms"]) / float(r["peer_ms"]))
        assert int(r["fragments"]) > 0 and float(r["ns_per_fragment"]) > 0
    assert (out / "floor.md").read_text().startswith("Adapter: ")


@needs_pygfx
def test_a_ratio_past_the_baseline_is_flagged(tmp_path):
    """A baseline of the same frame size whose ratios are a tenth of any real one flags every
    row; the baseline written from a run holds that run's ratios."""
    size = f"{floor.QUICK_SIZE}x{floor.QUICK_SIZE}"
    keys = [floor.row_key("glass", s, m) for s in floor.SHADINGS for m, _, _ in floor.ROWS]
    baseline = {"pygfx": "0", "size": size, "ratios": dict.fromkeys(keys, 1e-3)}
    result = floor.peers_floor(("glass",), repeat=1, quick=True, show_progress=False, baseline=baseline)
    assert all(r["flag"] == "slower" and r["growth"] > floor.GROWTH for r in result.rows)
    assert all(r["pairs"] == 1 for r in result.rows), "a quick run takes the pairs it is asked for, no more"
    assert any("pygfx 0" in n for n in result.notes)
    path = tmp_path / "baseline.json"
    floor.write_baseline(result, path)
    kept = json.loads(path.read_text())
    assert kept["size"] == size and set(kept["ratios"]) == set(keys)
    again = floor.peers_floor(("glass",), repeat=1, quick=True, show_progress=False, baseline={**baseline, "size": "512x512"})
    assert not any(r["flag"] for r in again.rows), "a baseline of another frame size is not compared"
