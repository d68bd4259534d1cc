"""The survey's approximate methods (issue 4): additive, filter, screen_door, mlab and
bucket_peeling
against their CPU models (oit.models) on per-pixel stacks; stochastic transparency is
deterministic for a seed and its error falls as samples rise."""

from __future__ import annotations

import numpy as np
import pytest

from oit import models
from oit.scenes import stacks

BG = np.array([0.2, 0.4, 0.6])
SIZE = (8, 8)


def model_image(built, method, **params):
    m = built.meta
    w = built.size[0]
    out = []
    for p in range(len(m["z"])):
        extra = {"pixel": divmod(p, w)} if method == "screen_door" else {}
        out.append(models.MODELS[method](m["z"][p], m["rgb"][p], m["alpha"][p], BG, **params, **extra))
    return np.array(out)


# Tolerances: float32 blending or compositing of 24 layers against float64 (<= 24 * 2^-24
# relative, on values up to 24 for additive); screen_door copies one color, rounded to float32.
@pytest.mark.parametrize("method,params,tol", [
    ("additive", {}, 1e-5), ("filter", {}, 2e-6), ("screen_door", {}, 6e-8),
    ("mlab", {"layers": 1}, 2e-6), ("mlab", {"layers": 4}, 2e-6), ("mlab", {"layers": 32}, 2e-6),
    ("bucket_peeling", {"buckets": 8}, 2e-6), ("bucket_peeling", {"buckets": 32}, 2e-6),
])
@pytest.mark.parametrize("alphas", ["random", "worst"])
def test_gpu_matches_model(renderer, method, params, tol, alphas):
    built = stacks(layers=24, alphas=alphas, size=SIZE, seed=9)
    frame = renderer(*SIZE).render(built.scene, built.camera, method, background=tuple(BG), **params)
    assert np.abs(frame.image.reshape(-1, 4) - model_image(built, method, **params)).max() <= tol


def test_mlab_with_enough_layers_is_exact():
    built = stacks(layers=12, alphas="random", size=(3, 3), seed=4)
    m = built.meta
    for p in range(9):
        exact = models.exact(m["z"][p], m["rgb"][p], m["alpha"][p], BG)
        assert np.abs(models.mlab(m["z"][p], m["rgb"][p], m["alpha"][p], BG, layers=12) - exact).max() < 1e-12


def mean_error(renderer, built, **params):
    r = renderer(*built.size)
    exact = r.render(built.scene, built.camera, "abuffer").image
    image = r.render(built.scene, built.camera, "stochastic", **params).image
    return float(np.sqrt(((image[..., :3] - exact[..., :3]) ** 2).sum(-1)).mean()), image


def test_stochastic_is_deterministic_for_a_seed(renderer):
    built = stacks(layers=10, alphas="random", size=(12, 12), seed=1)
    _, a = mean_error(renderer, built, samples=8, seed=5)
    _, b = mean_error(renderer, built, samples=8, seed=5)
    _, c = mean_error(renderer, built, samples=8, seed=6)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_stochastic_error_falls_as_samples_rise(renderer):
    built = stacks(layers=10, alphas="random", size=(24, 24), seed=2)
    errors = [np.mean([mean_error(renderer, built, samples=s, seed=seed)[0] for seed in range(3)])
              for s in (2, 8, 32)]
    # The estimate's noise falls about as 1/sqrt(samples): each 4x step should at least
    # take off a quarter of the error (measured: about half).
    assert errors[1] < 0.75 * errors[0] and errors[2] < 0.75 * errors[1], errors


def test_bucket_peeling_counts_what_it_drops(renderer):
    built = stacks(layers=40, alphas="random", size=SIZE, seed=3)
    frame = renderer(*SIZE).render(built.scene, built.camera, "bucket_peeling", buckets=8)
    # At most 8 of 40 fragments survive per pixel.
    assert frame.stats["overflow_fragments"] >= 32 * SIZE[0] * SIZE[1]
