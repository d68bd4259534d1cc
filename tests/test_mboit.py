"""mboit (moment-based OIT): one layer is exact, the error against the exact composite falls as
the moment count grows, the GPU agrees with its float64 model (oit.models.mboit) within
numerics.tolerance, and bad parameters are refused naming what to use."""

from __future__ import annotations

import numpy as np
import pytest

from numerics import BG, EXACT, expected_image, full_screen_layers, layer_arrays, params_for, stacks, tolerance
from oit import models
from scenes import IDENTITY

COUNTS = (4, 6, 8)


@pytest.mark.parametrize("moments", COUNTS)
@pytest.mark.parametrize("alpha", [1e-4, 0.3, 0.9, 1 - 1e-6])
def test_one_layer_is_exact(renderer, moments, alpha):
    # One fragment: its color is the weighted average alone and 1 - exp(-b0) = alpha, whatever
    # its reconstructed transmittance: alpha C + (1 - alpha) background to float32.
    ls = [(0.4, (0.9, 0.5, 0.25, alpha))]
    frame = renderer(4, 4).render(full_screen_layers(ls), IDENTITY, "mboit", background=tuple(BG), moments=moments)
    want = expected_image(EXACT[0], 4, 4, *layer_arrays(ls), BG)
    assert np.abs(frame.image - want).max() <= tolerance("mboit", 1, mass=alpha, moments=moments)


def _errors(moments: int, seed: int = 3, layers: int = 12) -> np.ndarray:
    s = stacks(1, 200, layers, seed=seed)
    err = [np.abs(models.mboit(z, c, a, BG, moments=moments) - models.exact(z, c, a, BG))[:3].max()
           for z, c, a in zip(s.z, s.rgb, s.alpha)]
    return np.array(err)


def test_error_falls_as_moments_grow():
    # On random stacks of 12 layers (the model; the GPU is held to it below): the mean error
    # against the exact composite falls from 4 to 6 to 8 moments.
    means = [_errors(m).mean() for m in COUNTS]
    assert means[0] > means[1] > means[2], means
    assert means[2] < 0.05, means


@pytest.mark.parametrize("moments", COUNTS)
def test_gpu_agrees_with_the_model(renderer, moments):
    s = stacks(8, 6, 10, seed=moments)
    params = params_for("mboit", moments=moments)
    frame = renderer(8, 6).render(s.scene, IDENTITY, "mboit", background=tuple(BG), **params)
    want = s.expect("mboit", **params)
    mass = max(a.sum() for a in s.alpha)
    err = np.abs(frame.image - want).max()
    assert err <= tolerance("mboit", 10, mass=mass, **params), err


@pytest.mark.parametrize(
    "params,message",
    [
        ({"moments": 5}, "use 4, 6 or 8"),
        ({"moments": 10}, "moments = 10 is out of range"),
        ({"basis": "wavelet"}, "is not one of: power"),
        ({"bias": -1.0}, "bias = -1"),
        ({"overestimation": 2.0}, "overestimation = 2"),
    ],
)
def test_bad_parameters_say_what_to_use(renderer, params, message):
    scene = full_screen_layers([(0.5, (1.0, 0.0, 0.0, 0.5))])
    with pytest.raises(ValueError, match=message):
        renderer(2, 2).render(scene, IDENTITY, "mboit", **params)
