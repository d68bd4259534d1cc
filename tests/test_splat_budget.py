"""Splats under a memory budget (issue 44): every bounded method renders a splat set within a
budget that tiles its storage and makes `sorted` draw its splats in batches, with the image it
renders without a budget; a budget that cannot hold one splat's draw is refused by name. The
same path at one million splats and 512² is the bench's (`python -m oit bench --splats`,
docs/results.md, "Gaussian splats")."""

from __future__ import annotations

import csv

import numpy as np
import pytest

import oit

SIZE = 40
SPLATS = 1500
BOUNDED = [m["name"] for m in oit.methods() if m["bounded_memory"]]


@pytest.fixture(scope="module")
def splat_scene():
    return oit.scenes.splats(SPLATS)


def test_sorted_holds_a_draw_a_splat_and_batches_them_within_a_budget(splat_scene):
    built = splat_scene
    whole = oit.Renderer(SIZE, SIZE).render(built.scene, built.camera, "sorted")
    # 16 bytes of indirect draw arguments a splat, counted in the frame's memory.
    assert whole.stats["memory_bytes"] == 16 * SPLATS
    # Room for a fifth of the draws beside the frame's targets: five batches, the same blend.
    budget = whole.stats["target_bytes"] + 16 * SPLATS // 5
    batched = oit.Renderer(SIZE, SIZE, memory_budget=budget).render(built.scene, built.camera, "sorted")
    assert batched.stats["memory_bytes"] == 16 * SPLATS // 5
    assert batched.stats["peak_memory_bytes"] <= budget
    assert np.array_equal(batched.image, whole.image)
    # Room for no draw: refused, saying what to raise.
    with pytest.raises(MemoryError, match="raise memory_budget"):
        oit.Renderer(SIZE, SIZE, memory_budget=whole.stats["target_bytes"] + 8).render(built.scene, built.camera, "sorted")


@pytest.mark.parametrize("name", BOUNDED)
def test_every_bounded_method_renders_splats_within_a_budget_as_without_one(splat_scene, name):
    built = splat_scene
    if name not in oit.Renderer(1, 1).adapter_info["methods"]:
        pytest.skip(f"the adapter lacks what {name} needs")
    whole = oit.Renderer(SIZE, SIZE).render(built.scene, built.camera, name)
    # The frame-sized targets and half the method's storage (sorted: of its draws). The screen
    # door's 4 bytes a pixel are render targets, which tile only with the frame's targets, one
    # run of pixels at a time at this budget (tests/test_tiles.py tiles them): all of it.
    memory = whole.stats["memory_bytes"]
    budget = whole.stats["target_bytes"] + (memory if name == "screen_door" else max(memory // 2, 4096))
    framed = oit.Renderer(SIZE, SIZE, memory_budget=budget).render(built.scene, built.camera, name)
    assert framed.stats["peak_memory_bytes"] <= budget
    if name != "screen_door" and memory > 2 * 4096:
        assert framed.stats["tiles"] > 1 or name == "sorted"
    # The same fragments, drawn in the same order within each pixel: bit for bit.
    assert np.array_equal(framed.image, whole.image)


def test_a_rebuilt_splat_scene_keeps_its_depth_choice(renderer):
    # Through MeshArrays (oit.scenes, scene rebuilds such as unlit): "ray" stays "ray".
    from oit._meshes import unlit

    built = {d: oit.scenes.splats(400, "cloud", splat_depth=d) for d in ("center", "ray")}
    assert built["ray"].meta["splat_depth"] == "ray"
    m = built["ray"].meshes[0]
    direct = oit.Scene()
    direct.add_gaussians(m.positions, m.primitive["scales"], m.primitive["rotations"], m.colors[:, 3], m.colors[:, :3],
                         splat_depth="ray")
    image = {d: renderer(32, 32).render(b.scene, b.camera, "abuffer").image for d, b in built.items()}
    cam = built["ray"].camera
    assert np.array_equal(image["ray"], renderer(32, 32).render(direct, cam, "abuffer").image)
    assert np.array_equal(image["ray"], renderer(32, 32).render(unlit(built["ray"]).scene, cam, "abuffer").image)
    assert not np.array_equal(image["ray"], image["center"])
    with pytest.raises(ValueError, match="splat_depth must be 'center' or 'ray'"):
        oit.scenes.splats(10, splat_depth="peak")


def test_the_splat_bench_writes_the_trade_and_the_scale(tmp_path):
    from oit import cli

    out = tmp_path / "bench"
    code = cli.main(["bench", "--splats", "--splat-scale", "--quick", "--methods", "sorted", "abuffer", "wboit",
                     "--frames", "2", "--out", str(out), "--no-plots"])
    assert code == 0
    with open(out / "splats.csv") as f:
        rows = list(csv.DictReader(f))
    # sorted's order is the means' whatever the depth choice: one row; the others both.
    assert [(r["method"], r["splat_depth"]) for r in rows[:5]] == [
        ("sorted", "center"), ("abuffer", "center"), ("abuffer", "ray"), ("wboit", "center"), ("wboit", "ray")]
    by = {(r["scene"], r["method"], r["splat_depth"]): r for r in rows}
    for scene in ("splats", "splat_cloud"):
        # The exact frame is abuffer with "ray": no error and no flicker against itself.
        exact = by[(scene, "abuffer", "ray")]
        assert float(exact["mean_err"]) == 0.0 and float(exact["flicker"]) == 0.0
        assert float(by[(scene, "sorted", "center")]["mean_err"]) > 0.0
    with open(out / "splat-scale.csv") as f:
        scale = list(csv.DictReader(f))
    # Bounded methods only (abuffer is not), each within the budget.
    assert [r["method"] for r in scale] == ["sorted", "wboit"]
    assert all(r["status"] == "ok" and float(r["peak_mib"]) <= float(r["budget_mib"]) for r in scale)
