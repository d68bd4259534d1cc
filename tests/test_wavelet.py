"""wavelet (wavelet transparency, Haar wavelets): one layer is exact, the error against the exact
composite falls as the rank grows, the GPU agrees with its float64 model
(oit.models.wavelet) within numerics.tolerance, its per-pixel error bound holds on random,
deep and extreme stacks and on every built-in scene, and bad parameters are refused naming
what to use."""

from __future__ import annotations

import numpy as np
import pytest

from numerics import (
    BG,
    EXACT,
    assert_within_error_bound,
    expected_image,
    full_screen_layers,
    layer_arrays,
    params_for,
    stacks,
    tolerance,
)
from oit import models, scenes
from oit.models_wavelet import RANKS, wavelet_absorbance, wavelet_cell, wavelet_coefficients
from scenes import IDENTITY


@pytest.mark.parametrize("rank", RANKS)
@pytest.mark.parametrize("alpha", [1e-4, 0.3, 0.9, 1 - 1e-6])
def test_one_layer_is_exact(renderer, rank, alpha):
    # One fragment: its color is the weighted average alone and 1 - exp(-d_0) = alpha, whatever
    # its reconstructed transmittance: alpha C + (1 - alpha) background to float32.
    ls = [(0.4, (0.9, 0.5, 0.25, alpha))]
    frame = renderer(4, 4).render(full_screen_layers(ls), IDENTITY, "wavelet", background=tuple(BG), rank=rank)
    want = expected_image(EXACT[0], 4, 4, *layer_arrays(ls), BG)
    assert np.abs(frame.image - want).max() <= tolerance("wavelet", 1, mass=alpha, rank=rank)


def test_absorbance_is_exact_at_cell_boundaries():
    # The projection keeps each finest cell's mass: A at a cell's boundary is the optical depth
    # strictly in front of it, and within a cell A is linear (the model; the GPU is held to it).
    rng = np.random.default_rng(1)
    z, alpha = rng.uniform(0, 1, 40), rng.uniform(0.05, 0.95, 40)
    tau = -np.log(1 - alpha)
    for rank in RANKS:
        d = wavelet_coefficients(z, alpha, rank)
        for u in rng.uniform(0, 1, 50):
            near, far = wavelet_cell(rank, u)
            for b in (near, far):
                assert wavelet_absorbance(d, b) == pytest.approx(tau[z < b].sum(), abs=1e-12)
            mid = wavelet_absorbance(d, near) + (u - near) / (far - near) * tau[(z >= near) & (z < far)].sum()
            assert wavelet_absorbance(d, u) == pytest.approx(mid, abs=1e-12)


def _mean_error(rank: int, layers: int, seed: int = 3, pixels: int = 200) -> float:
    rng = np.random.default_rng(seed)
    err = []
    for _ in range(pixels):
        z, c, a = rng.uniform(0, 1, layers), rng.uniform(0, 1, (layers, 3)), rng.uniform(0.05, 0.95, layers)
        err.append(np.abs(models.wavelet(z, c, a, BG, rank=rank) - models.exact(z, c, a, BG))[:3].max())
    return float(np.mean(err))


@pytest.mark.parametrize("layers", [4, 12, 40])
def test_error_falls_as_the_rank_grows(layers):
    # On random stacks (uniform depths; the model, the GPU is held to it below) the mean error
    # against the exact composite falls as the rank grows: the finest cells halve, and a
    # fragment alone in its cell sees the exact transmittance. Measured (ranks 4, 8, 12, 16):
    # 4 layers 0.035, 0.020, 0.014, 0.012; 12 layers 0.070, 0.051, 0.030, 0.029; 40 layers
    # 0.090, 0.082, 0.064, 0.064 (rank 16 refines only the far half beyond 12, hidden there).
    means = [_mean_error(rank, layers) for rank in RANKS]
    assert all(a >= b for a, b in zip(means, means[1:])), means
    assert means[-1] < 0.75 * means[0], means


@pytest.mark.parametrize("rank", RANKS)
def test_gpu_agrees_with_the_model(renderer, rank):
    s = stacks(8, 6, 10, seed=rank)
    params = params_for("wavelet", rank=rank)
    frame = renderer(8, 6).render(s.scene, IDENTITY, "wavelet", background=tuple(BG), **params)
    want = s.expect("wavelet", **params)
    mass = max(a.sum() for a in s.alpha)
    err = np.abs(frame.image - want).max()
    assert err <= tolerance("wavelet", 10, mass=mass, **params), err


@pytest.mark.parametrize("rank", RANKS)
@pytest.mark.parametrize("alphas", [(1.0, 1.0, 1.0, 1.0), (1 - 1e-6, 1e-4, 0.0, 1.0), (1e-4,) * 4, (0.5, 0.25, 0.75, 0.6)])
def test_gpu_agrees_with_the_model_at_alpha_extremes(renderer, rank, alphas):
    ls = [(z, (*c, a)) for z, c, a in zip((0.7, 0.4, 0.1, 0.55), ((0, 1, 0), (0.3, 0.2, 0.1), (0, 0, 1), (0.9, 0.5, 0.25)), alphas)]
    params = params_for("wavelet", rank=rank)
    frame = renderer(4, 4).render(full_screen_layers(ls), IDENTITY, "wavelet", background=tuple(BG), **params)
    want = expected_image("wavelet", 4, 4, *layer_arrays(ls), BG, **params)
    assert np.abs(frame.image - want).max() <= tolerance("wavelet", 4, mass=sum(alphas), **params)


@pytest.mark.parametrize("rank", RANKS)
@pytest.mark.parametrize("layers,alpha", [(10, None), (300, lambda r, n: r.uniform(1e-4, 2e-3, n)),
                                          (300, lambda r, n: r.uniform(0.5, 1.0, n)),
                                          (40, lambda r, n: np.where(r.uniform(0, 1, n) < 0.5, 1e-4, 1 - 1e-6)),
                                          (3000, lambda r, n: np.where(r.uniform(0, 1, n) < 0.5, 1e-4, 1 - 1e-6)),
                                          (3000, lambda r, n: r.uniform(1e-5, 1e-3, n))])
def test_error_bound_holds(renderer, rank, layers, alpha):
    # frame.error_bound (each fragment's transmittance between exp(-A) at its cell's two
    # boundaries, where A is exact, and the average's scale: docs/methods.md, "wavelet") holds
    # against the exact composite on random stacks, faint and dense deep ones, thousands of
    # layers and alphas at both extremes.
    s = stacks(2, 2, layers, seed=layers + rank, alpha=alpha)
    frame = renderer(2, 2).render(s.scene, IDENTITY, "wavelet", background=tuple(BG), rank=rank)
    assert frame.error_bound is not None
    assert_within_error_bound(frame, s.expect(EXACT[0]))


SMALL = {"hair": dict(strands=300), "smoke": dict(particles=80), "foliage": dict(leaves=300), "glass": dict(detail=12),
         "dragons": dict(max_triangles=1500), "stacks": dict(layers=12, size=(8, 8))}


@pytest.mark.parametrize("name", list(scenes.SCENES))
def test_every_scene_renders_within_its_bound(renderer, name):
    # Every built-in scene (small versions, perspective cameras and the log warp): finite
    # pixels, and the error against the A-buffer within frame.error_bound at every pixel.
    b = scenes.SCENES[name](**SMALL.get(name, {}))
    r = renderer(32, 32)
    exact = r.render(b.scene, b.camera, EXACT[0]).image.astype(np.float64)
    for rank in (4, 16):
        frame = r.render(b.scene, b.camera, "wavelet", rank=rank)
        assert np.isfinite(frame.image).all() and np.isfinite(frame.error_bound).all(), (name, rank)
        assert_within_error_bound(frame, exact)


@pytest.mark.parametrize(
    "params,message",
    [
        ({"rank": 6}, "rank = 6 is not a valid count; use one of 4, 8, 12, 16"),
        ({"rank": 32}, "rank = 32 is out of range"),
        ({"rank": 0}, "rank = 0 is out of range"),
        ({"levels": 3}, "levels"),
    ],
)
def test_bad_parameters_say_what_to_use(renderer, params, message):
    scene = full_screen_layers([(0.5, (1.0, 0.0, 0.0, 0.5))])
    with pytest.raises(ValueError, match=message):
        renderer(2, 2).render(scene, IDENTITY, "wavelet", **params)
