"""Every registered method has a CPU model (numerics.expected), so that the numerics suites
compare each one's GPU image with it: a method added without one fails here, by name,
instead of being left out of the comparisons. And the one model that reproduces noise,
stochastic's, at other sample counts and seeds than the suites' defaults."""

from __future__ import annotations

import numpy as np
import pytest

from numerics import (
    BG,
    NAMES,
    expected,
    expected_image,
    full_screen_layers,
    full_screen_prims,
    layer_arrays,
    params_for,
    stacks,
    tolerance,
)
from oit import models
from scenes import IDENTITY


def test_every_registered_method_has_a_model():
    z, rgb, alpha = [0.7, 0.2, 0.5], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.2, 0.4, 0.8]], [0.5, 0.25, 0.75]
    missing, broken = [], []
    for name in NAMES:
        try:
            out = expected(name, z, rgb, alpha, BG, pixel=(1, 2), size=(4, 3), prims=full_screen_prims(3, (1, 2), (4, 3)),
                           **params_for(name))
        except LookupError:
            missing.append(name)
            continue
        if np.shape(out) != (4,) or not np.isfinite(out).all():
            broken.append(name)
    assert not missing, f"registered methods without a CPU model in oit.models: {missing}"
    assert not broken, f"models that return no finite RGBA: {broken}"


def test_a_method_without_a_model_raises_naming_it(monkeypatch):
    # What a newly registered method without a model meets: an error naming it, not a None.
    monkeypatch.delitem(models.MODELS, "stochastic")
    with pytest.raises(LookupError, match="no CPU model of 'stochastic'"):
        expected("stochastic", [0.5], [[1.0, 1.0, 1.0]], [0.5], BG, prims=[0])


@pytest.mark.parametrize("samples,seed", [(1, 0), (8, 12345), (33, 7), (64, 2 ** 32 - 1)])
def test_stochastic_model_draws_the_gpu_samples(renderer, samples, seed):
    # The same noise as the GPU, so agreement to the resolve's rounding: on per-pixel quads
    # (9 x 5, 12 layers) and on full-screen layers in a square frame, whose diagonal pixels the
    # top-left rule gives to one triangle of each quad (full_screen_prims).
    params = params_for("stochastic", samples=samples, seed=seed)
    s = stacks(9, 5, 12, seed=samples)
    frame = renderer(9, 5).render(s.scene, IDENTITY, "stochastic", background=tuple(BG), **params)
    assert np.abs(frame.image - s.expect("stochastic", **params)).max() <= tolerance("stochastic", 12)
    rng = np.random.default_rng(seed % 1000)
    ls = [(float(z), (*rng.uniform(0, 1, 3), float(rng.uniform(0.05, 0.95)))) for z in rng.permutation(np.linspace(0.1, 0.9, 6))]
    frame = renderer(6, 6).render(full_screen_layers(ls), IDENTITY, "stochastic", background=tuple(BG), **params)
    want = expected_image("stochastic", 6, 6, *layer_arrays(ls), BG, **params)
    assert np.abs(frame.image - want).max() <= tolerance("stochastic", 6)
