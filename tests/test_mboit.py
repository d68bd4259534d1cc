"""mboit (moment-based OIT), power and trigonometric moments: one layer is exact, the error against the exact composite falls as
the moment count grows, the GPU agrees with its float64 model (oit.models.mboit) within
numerics.tolerance, and bad parameters are refused naming what to use."""

from __future__ import annotations

import numpy as np
import pytest

import oit
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
from oit import models
from scenes import IDENTITY
from test_numerics_coplanar import SCENES as COPLANAR
from test_numerics_coplanar import render as render_coplanar
from test_numerics_coplanar import shuffles

COUNTS = {"power": (4, 6, 8), "trigonometric": (4, 6, 8)}  # real values: 2, 3, 4 complex trigonometric
CASES = [(basis, m) for basis, counts in COUNTS.items() for m in counts]


@pytest.mark.parametrize("basis,moments", CASES)
@pytest.mark.parametrize("alpha", [1e-4, 0.3, 0.9, 1 - 1e-6])
@pytest.mark.parametrize("precision", ["32", "16"])
def test_one_layer_is_exact(renderer, basis, moments, alpha, precision):
    # One fragment: its color is the weighted average alone and 1 - exp(-b0) = alpha, whatever
    # its reconstructed transmittance: alpha C + (1 - alpha) background to float32 (at 16 bits
    # too: b0 is kept as a float, only the normalized moments are quantized).
    ls = [(0.4, (0.9, 0.5, 0.25, alpha))]
    frame = renderer(4, 4).render(full_screen_layers(ls), IDENTITY, "mboit", background=tuple(BG), moments=moments, basis=basis,
                                  precision=precision)
    want = expected_image(EXACT[0], 4, 4, *layer_arrays(ls), BG)
    assert np.abs(frame.image - want).max() <= tolerance("mboit", 1, mass=alpha)


def _errors(basis: str, moments: int, seed: int = 3, layers: int = 12) -> np.ndarray:
    s = stacks(1, 200, layers, seed=seed)
    err = [np.abs(models.mboit(z, c, a, BG, moments=moments, basis=basis) - models.exact(z, c, a, BG))[:3].max()
           for z, c, a in zip(s.z, s.rgb, s.alpha)]
    return np.array(err)


@pytest.mark.parametrize("basis", list(COUNTS))
def test_error_falls_as_moments_grow(basis):
    # On random stacks of 12 layers (the model; the GPU is held to it below): the mean error
    # against the exact composite falls with each count of the basis (measured: power 0.067,
    # 0.045, 0.029; trigonometric 0.136, 0.108, 0.083).
    means = [_errors(basis, m).mean() for m in COUNTS[basis]]
    assert means[0] > means[1] > means[2], means
    assert means[2] < 0.7 * means[0], means


@pytest.mark.parametrize("basis,moments", CASES)
@pytest.mark.parametrize("precision,layers", [("32", 10), ("16", 10), ("16", 40)])
def test_gpu_agrees_with_the_model(renderer, basis, moments, precision, layers):
    # At 16 bits the model stores each fragment's renormalized moments in turn, in submission
    # order, as the critical sections do on these stacks (oit.models_mboit.mboit16).
    s = stacks(8, 6, layers, seed=moments)
    params = params_for("mboit", moments=moments, basis=basis, precision=precision)
    frame = renderer(8, 6).render(s.scene, IDENTITY, "mboit", background=tuple(BG), **params)
    want = s.expect("mboit", **params)
    mass = max(a.sum() for a in s.alpha)
    err = np.abs(frame.image - want).max()
    assert err <= tolerance("mboit", layers, mass=mass, **params), err
    assert frame.stats["overflow_fragments"] == 0 and (frame.error_bound is None) == (precision == "16")


@pytest.mark.parametrize("basis,moments", CASES)
def test_sixteen_bits_take_the_memory_they_declare_and_cost_little_error(renderer, basis, moments):
    # Memory: b0, the moments at 2 bytes and the lock word a pixel against 4 + 4 per moment.
    s = stacks(8, 6, 12, seed=7)
    r = renderer(8, 6)
    frames = {p: r.render(s.scene, IDENTITY, "mboit", background=tuple(BG), moments=moments, basis=basis, precision=p)
              for p in ("32", "16")}
    assert frames["16"].stats["memory_bytes"] == oit.memory_bytes("mboit", 8, 6, moments=moments, precision="16")
    assert frames["16"].stats["memory_bytes"] == 48 * (2 * moments + 40) + 8
    assert frames["32"].stats["memory_bytes"] == 48 * (4 * moments + 36)
    # Error against the exact composite: the quantization adds little on 12 random layers
    # (measured: the mean differs by under 1 % of itself).
    exact = s.expect(EXACT[0])
    err = {p: np.abs(f.image - exact)[..., :3].mean() for p, f in frames.items()}
    assert err["16"] <= 1.1 * err["32"], err


@pytest.mark.parametrize("basis,moments", CASES)
@pytest.mark.parametrize("alphas", [(1.0, 1.0, 1.0, 1.0), (1 - 1e-6, 1e-4, 0.0, 1.0), (1e-4,) * 4, (0.5, 0.25, 0.75, 0.6)])
def test_gpu_agrees_with_the_model_at_alpha_extremes(renderer, basis, moments, alphas):
    ls = [(z, (*c, a)) for z, c, a in zip((0.7, 0.4, 0.1, 0.55), ((0, 1, 0), (0.3, 0.2, 0.1), (0, 0, 1), (0.9, 0.5, 0.25)), alphas)]
    params = params_for("mboit", moments=moments, basis=basis)
    frame = renderer(4, 4).render(full_screen_layers(ls), IDENTITY, "mboit", background=tuple(BG), **params)
    want = expected_image("mboit", 4, 4, *layer_arrays(ls), BG, **params)
    assert np.abs(frame.image - want).max() <= tolerance("mboit", 4, mass=sum(alphas), **params)


@pytest.mark.parametrize("basis,moments", CASES)
@pytest.mark.parametrize("layers,alpha", [(10, None), (300, lambda r, n: r.uniform(1e-4, 2e-3, n)),
                                          (300, lambda r, n: r.uniform(0.5, 1.0, n)),
                                          (40, lambda r, n: np.where(r.uniform(0, 1, n) < 0.5, 1e-4, 1 - 1e-6))])
def test_error_bound_holds(renderer, basis, moments, layers, alpha):
    # frame.error_bound (the moment problem's bounds on each fragment's transmittance, the
    # bias's share and the average's scale: docs/methods.md, "mboit") holds against the exact
    # composite on random stacks, faint and dense deep ones, and alphas at both extremes.
    s = stacks(4, 3, layers, seed=layers + moments, alpha=alpha)
    frame = renderer(4, 3).render(s.scene, IDENTITY, "mboit", background=tuple(BG), moments=moments, basis=basis)
    assert frame.error_bound is not None
    assert_within_error_bound(frame, s.expect(EXACT[0]))


@pytest.mark.parametrize(
    "params,message",
    [
        ({"moments": 5}, "moments = 5 is not a valid count; use one of 4, 6, 8"),
        ({"moments": 7, "basis": "trigonometric"}, "moments = 7 is not a valid count; use one of 4, 6, 8"),
        ({"moments": 10}, "moments = 10 is out of range"),
        ({"basis": "wavelet"}, "is not one of: power, trigonometric"),
        ({"precision": "8"}, "is not one of: 32, 16"),
        ({"bias": -1.0}, "bias = -1"),
        ({"overestimation": 2.0}, "overestimation = 2"),
    ],
)
def test_bad_parameters_say_what_to_use(renderer, params, message):
    scene = full_screen_layers([(0.5, (1.0, 0.0, 0.0, 0.5))])
    with pytest.raises(ValueError, match=message):
        renderer(2, 2).render(scene, IDENTITY, "mboit", **params)


@pytest.mark.parametrize("precision", ["32", "16"])
def test_a_budget_tiles_mboit_and_the_image_stays_bit_for_bit(precision):
    # Tiles keep each pixel's fragments in submission order, into its blends or its critical
    # sections alike: the same bits, and everything the frame allocates within the budget.
    s = stacks(32, 24, 12, seed=5)
    untiled = oit.Renderer(32, 24).render(s.scene, IDENTITY, "mboit", background=tuple(BG), precision=precision)
    budget = untiled.stats["peak_memory_bytes"] // 3
    tiled = oit.Renderer(32, 24, memory_budget=budget).render(s.scene, IDENTITY, "mboit", background=tuple(BG),
                                                              precision=precision)
    assert tiled.stats["tiles"] > 1 and tiled.stats["peak_memory_bytes"] <= budget
    assert np.array_equal(tiled.image, untiled.image)
    if precision == "32":
        assert np.array_equal(tiled.error_bound, untiled.error_bound)


@pytest.mark.parametrize("scene", list(COPLANAR))
@pytest.mark.parametrize("moments", COUNTS["power"])
def test_reordered_coplanar_layers_agree_to_rounding_at_every_count(renderer, moments, scene):
    # The numerics suite's order test at every count, not only the default: equal and nearly
    # equal depths make the Hankel matrix nearly singular, where float32's rounding of the sums
    # in another order could move a kernel root across the fragment's depth; the default
    # biases keep it away (crates/oit-core/src/consts.rs MBOIT_BIAS).
    frames = [render_coplanar(renderer, m, "mboit", moments=moments) for m in shuffles(COPLANAR[scene](), 6)]
    n = int(frames[0].stats["max_depth_complexity"])
    for f in frames[1:]:
        assert np.abs(f.image - frames[0].image).max() <= 2 * tolerance("mboit", n, mass=n)
