"""Accuracy on demand (issue 8): the per-pixel error bound of hybrid, hybrid64 and ktab is
never exceeded by the measured error against the A-buffer, and `auto` meets its tolerance
at the least cost it finds."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from oit.scenes import stacks
from scenes import IDENTITY, PERSPECTIVE, build_scene, layer, random_meshes


def measured(frame, exact):
    return np.abs(frame.image[..., :3].astype(np.float64) - exact.image[..., :3])


@pytest.mark.parametrize("method", ["hybrid", "hybrid64", "ktab"])
@pytest.mark.parametrize("k", [1, 2, 4, 8])
@pytest.mark.parametrize("alphas", ["random", "worst", "constant"])
def test_bound_holds_on_stacks(renderer, method, k, alphas):
    built = stacks(layers=24, alphas=alphas, size=(12, 12), seed=k)
    r = renderer(12, 12)
    exact = r.render(built.scene, built.camera, "abuffer")
    frame = r.render(built.scene, built.camera, method, k=k)
    assert frame.error_bound is not None and frame.error_bound.shape == (12, 12, 3)
    assert (measured(frame, exact) <= frame.error_bound).all()


@pytest.mark.parametrize("method", ["hybrid", "hybrid64", "ktab"])
@pytest.mark.parametrize("seed", [0, 1])
def test_bound_holds_on_random_scenes(renderer, method, seed):
    scene = build_scene(random_meshes(seed, transparent=12, triangles=6, space="world"))
    r = renderer(40, 40)
    exact = r.render(scene, PERSPECTIVE, "abuffer")
    frame = r.render(scene, PERSPECTIVE, method, k=2)
    assert (measured(frame, exact) <= frame.error_bound).all()


def test_methods_without_a_bound_say_why(renderer):
    scene = build_scene(random_meshes(3))
    r = renderer(16, 16)
    for method in ("wavg", "abuffer"):
        frame = r.render(scene, IDENTITY, method)
        assert frame.error_bound is None and frame.error_bound_reason


@pytest.mark.parametrize("tolerance", [1 / 255, 4 / 255, 16 / 255])
def test_auto_meets_its_tolerance(renderer, tolerance):
    built = stacks(layers=60, alphas="random", size=(12, 12), seed=7)
    r = renderer(12, 12)
    exact = r.render(built.scene, built.camera, "abuffer")
    frame = r.render(built.scene, built.camera, "auto", tolerance=tolerance)
    assert frame.stats["error_bound_max"] <= tolerance
    assert measured(frame, exact).max() <= tolerance
    assert (measured(frame, exact) <= frame.error_bound).all()


def test_auto_uses_no_more_slots_than_the_depth_complexity(renderer):
    built = stacks(layers=5, alphas="constant", size=(8, 8), seed=1)
    frame = renderer(8, 8).render(built.scene, built.camera, "auto", tolerance=0.05)
    assert frame.stats["extra"]["auto_k"] == 5 and frame.stats["overflow_fragments"] == 0
    assert frame.stats["extra"]["auto_attempts"] == 1 and frame.stats["extra"]["auto_slots"] == 5 * 64
    assert frame.stats["memory_bytes"] == oit.memory_bytes("auto", 8, 8, slots=5 * 64)


def test_auto_gives_each_pixel_its_own_slots(renderer):
    # Three layers over the whole frame, seventeen more over its left half (alpha 0.3 each):
    # the right half gets 3 slots (no tail), the left as many as its 20 layers need.
    full = [layer(0.1 + 0.05 * i, (0.9, 0.2, 0.1, 0.3)) for i in range(3)]
    half = []
    for i in range(17):
        q = layer(0.3 + 0.03 * i, (0.1, 0.3 + 0.02 * i, 0.8, 0.3))
        q.positions[:, 0] = np.minimum(q.positions[:, 0], 0.0)  # x in [-1, 0]: the left half
        half.append(q)
    scene = build_scene(full + half)
    r = renderer(8, 8)
    frame = r.render(scene, IDENTITY, "auto", tolerance=0.02)
    exact = r.render(scene, IDENTITY, "abuffer")
    k_left = frame.stats["extra"]["auto_k"]
    assert frame.stats["extra"]["auto_exact"] == 0 and 3 < k_left < 20
    assert frame.stats["extra"]["auto_slots"] == 32 * k_left + 32 * 3
    assert measured(frame, exact).max() <= 0.02
    assert frame.stats["memory_bytes"] == oit.memory_bytes("auto", 8, 8, slots=int(frame.stats["extra"]["auto_slots"]))


def test_auto_predicts_k_on_hair_like_stacks(renderer):
    # Random alphas, 40 layers: the prediction picks one k, fewer than the layers, and it holds.
    built = stacks(layers=40, alphas="random", size=(16, 16), seed=3)
    r = renderer(16, 16)
    frame = r.render(built.scene, built.camera, "auto", tolerance=16 / 255)
    exact = r.render(built.scene, built.camera, "abuffer")
    assert measured(frame, exact).max() <= 16 / 255
    assert frame.stats["extra"]["auto_exact"] == 0 and frame.stats["extra"]["auto_attempts"] == 1
    assert frame.stats["extra"]["auto_k"] == frame.stats["extra"]["auto_predicted_k"] < 40


def test_auto_falls_back_to_exact_for_a_tiny_tolerance(renderer):
    built = stacks(layers=60, alphas="random", size=(8, 8), seed=2)
    r = renderer(8, 8)
    frame = r.render(built.scene, built.camera, "auto", tolerance=1e-4)
    assert frame.stats["extra"]["auto_exact"] == 1
    # Predicted before rendering: no hybrid is tried, and the exact image is the A-buffer's.
    assert frame.stats["extra"]["auto_attempts"] == 1 and frame.stats["extra"]["auto_predicted_k"] == 0
    assert np.array_equal(frame.image, r.render(built.scene, built.camera, "abuffer").image)
    # The exact composite's own bound: float32 rounding of 62 terms.
    assert frame.stats["error_bound_max"] == pytest.approx(62 * 2.4e-7, rel=1e-6)


@pytest.mark.parametrize("method", ["hybrid", "ktab"])
def test_the_tail_term_scales_with_the_range_of_the_colors_behind_the_core(renderer, method):
    # Twenty layers of one gray over a background of the same gray: whatever the tail holds,
    # the image behind the core is that gray, so only the 8-bit alpha terms remain in the bound.
    gray = (0.5, 0.5, 0.5)
    meshes = [layer(0.05 + 0.04 * i, (*gray, 0.1 + 0.02 * i)) for i in range(20)]
    r = renderer(8, 8)
    frame = r.render(build_scene(meshes), IDENTITY, method, k=2, background=gray)
    exact = r.render(build_scene(meshes), IDENTITY, "abuffer", background=gray)
    assert frame.stats["overflow_fragments"] == 18 * 64
    assert frame.error_bound.max() < 0.02 and (measured(frame, exact) <= frame.error_bound).all()
    # A white background widens the range to 0.5: T_core * 0.5 comes back.
    bright = r.render(build_scene(meshes), IDENTITY, method, k=2, background=(1.0, 1.0, 1.0))
    assert bright.error_bound.max() > 0.3


def test_auto_renders_mboit_where_a_weighted_average_is_within_the_tolerance(renderer):
    # Ten faint layers (coverage 1 - 0.98^10, about 0.18) over black: any average of their colors
    # that keeps the exact coverage errs by at most their range with the base's (0 to 0.77) times
    # 0.18, and mboit's own bound meets 0.2, so auto renders it, at less memory than any hybrid.
    scene = build_scene([layer(0.1 + 0.08 * i, (0.5 + 0.03 * i, 0.4, 0.6 - 0.02 * i, 0.02)) for i in range(10)])
    r = renderer(8, 8)
    frame = r.render(scene, IDENTITY, "auto", tolerance=0.2)
    exact = r.render(scene, IDENTITY, "abuffer")
    extra = frame.stats["extra"]
    assert extra["auto_moments"] == 2 and extra["auto_exact"] == 0 and extra["auto_k"] == 0
    assert np.array_equal(frame.image, r.render(scene, IDENTITY, "mboit", moments=4).image)
    assert measured(frame, exact).max() <= frame.error_bound.max() + 1e-6 <= 0.2 + 1e-6
    assert frame.stats["memory_bytes"] == oit.memory_bytes("mboit", 8, 8, moments=4) + 8 * 8 * 20
    # A tolerance below that: mboit is not tried, and hybrid meets it.
    tight = r.render(scene, IDENTITY, "auto", tolerance=0.01)
    assert tight.stats["extra"]["auto_moments"] == 0 and tight.stats["extra"]["auto_k"] > 0
