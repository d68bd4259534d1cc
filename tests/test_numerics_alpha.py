"""Alpha at its extremes, for every method: exactly 0 (the background, exactly: no 0/0),
exactly 1 (the front fragment wins, exactly, for the exact methods and hybrid/ktab), 1e-4
(below hybrid's 8-bit key resolution, 1/510) and just below 1 (1 - 1e-6, which the key
rounds to 255). Each GPU image is checked against the method's CPU model (numerics.expected)
within numerics.tolerance, and the exactness promises bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from numerics import (
    BG,
    BIT_ORDER_INDEPENDENT,
    EXACT,
    NAMES,
    RANDOMIZED,
    assert_within_error_bound,
    color_quantum,
    expected,
    expected_image,
    full_screen_layers,
    layer_arrays,
    params_for,
    tolerance,
)
from scenes import IDENTITY

DEPTHS = (0.7, 0.4, 0.1, 0.55)  # submission order, neither front to back nor back to front
COLORS = ((0.0, 1.0, 0.0), (0.3, 0.2, 0.1), (0.0, 0.0, 1.0), (0.9, 0.5, 0.25))
ALPHAS = {
    "zero": (0.0, 0.0, 0.0, 0.0),
    "one": (1.0, 1.0, 1.0, 1.0),
    "tiny": (1e-4, 1e-4, 1e-4, 1e-4),
    "near_one": (1 - 1e-6,) * 4,
    "mixed": (1 - 1e-6, 1e-4, 0.0, 1.0),
}
SIZE = (4, 4)
F32_BG = BG.astype(np.float32)


def layers(alphas, colors=COLORS, depths=DEPTHS):
    return [(z, (*c, a)) for z, c, a in zip(depths, colors, alphas)]


def render(renderer, name, scene, bg=BG, **params):
    return renderer(*SIZE).render(scene, IDENTITY, name, background=tuple(bg), **params_for(name, **params))


@pytest.mark.parametrize("case", list(ALPHAS))
@pytest.mark.parametrize("name", NAMES)
def test_gpu_matches_model_at_alpha_extremes(renderer, name, case):
    ls = layers(ALPHAS[case])
    params = params_for(name, k=2, nodes=2)  # k < 4 layers: hybrid's tail and ktab's drop are exercised
    want = expected_image(name, *SIZE, *layer_arrays(ls), BG, mesh_per_fragment=True, **params)
    frame = render(renderer, name, full_screen_layers(ls), **params)
    assert_within_error_bound(frame, expected_image(EXACT[0], *SIZE, *layer_arrays(ls), BG))
    _, _, a = layer_arrays(ls)
    err = np.abs(frame.image.astype(np.float64) - want).max()
    assert err <= tolerance(name, len(ls), mass=a.sum(), **params), (name, case, frame.image[0, 0], want)


@pytest.mark.parametrize("name", NAMES)
def test_alpha_zero_everywhere_is_the_background_exactly(renderer, name):
    # No 0/0 in the weighted methods, no NaN: the background bit for bit, coverage 0.
    frame = render(renderer, name, full_screen_layers(layers(ALPHAS["zero"])))
    assert np.array_equal(frame.image[..., :3], np.broadcast_to(F32_BG, (*SIZE[::-1], 3))), frame.image[0, 0]
    assert (frame.image[..., 3] == 0).all()
    # In front of an opaque surface: that surface, exactly, with coverage 1.
    scene = full_screen_layers([*layers(ALPHAS["zero"]), (0.9, (0.25, 0.5, 0.75, 1.0))], opaque=[4])
    frame = render(renderer, name, scene)
    assert np.array_equal(frame.image, np.broadcast_to(np.float32([0.25, 0.5, 0.75, 1.0]), (*SIZE[::-1], 4)))


@pytest.mark.parametrize("name", sorted(set(NAMES) - set(RANDOMIZED)))
def test_alpha_zero_fragments_change_nothing(renderer, name):
    # Invisible fragments are skipped or add exactly 0 (T 0 c = 0, T (1 - 0) = T): the image
    # with them interleaved is the image without them, bit for bit. (Randomized methods draw
    # their noise by triangle index, so extra triangles change it: not tested here.)
    visible = layers((0.5, 0.25, 0.75, 0.6))
    hidden = [(z, (1.0, 1.0, 1.0, 0.0)) for z in (0.05, 0.45, 0.6, 0.95)]
    mixed = [x for pair in zip(hidden, visible) for x in pair]
    a = render(renderer, name, full_screen_layers(visible))
    b = render(renderer, name, full_screen_layers(mixed))
    assert np.array_equal(a.image, b.image), (a.image[0, 0], b.image[0, 0])


@pytest.mark.parametrize("k", [1, 8])
@pytest.mark.parametrize("name", BIT_ORDER_INDEPENDENT)
def test_alpha_one_front_fragment_wins_exactly(renderer, name, k):
    # The exact methods composite T = 0 behind an alpha-1 fragment; hybrid/ktab pack alpha 1
    # to 255 exactly (docs/methods.md), so T_core = 0 and the tail is weighted by 0. So the
    # image is, bit for bit, the image of the front fragment alone, and that is its color up
    # to the method's attribute interpolation (one rounding: compact_abuffer rebuilds colors
    # from barycentrics), hybrid's 2^-31 fixed point and hybrid64's 11/11/10-bit colors.
    ls = layers((0.6, 1.0, 0.5, 0.3), depths=(0.7, 0.1, 0.4, 0.2))  # front: (0.3, 0.2, 0.1) at 0.1
    frame = render(renderer, name, full_screen_layers(ls), k=k)
    alone = render(renderer, name, full_screen_layers([ls[1]]), k=k)
    assert np.array_equal(frame.image, alone.image), (frame.image[0, 0], alone.image[0, 0])
    assert np.abs(frame.image - np.float32([0.3, 0.2, 0.1, 1.0])).max() <= tolerance(name, 1) + color_quantum(name)
    assert (frame.image[..., 3] == 1).all()


@pytest.mark.parametrize("name", sorted({"hybrid", "ktab"} & set(NAMES)))
def test_alpha_below_key_resolution(renderer, name):
    # alpha = 1e-4 < 1/510 packs to 0 in the key: the fragments still add C alpha T, but
    # nothing behind them is attenuated and coverage comes from the keys: exactly 0. Against
    # the exact composite the error is at most the attenuation missed, sum(alpha).
    ls = layers(ALPHAS["tiny"])
    frame = render(renderer, name, full_screen_layers(ls), k=8)
    assert (frame.image[..., 3] == 0).all()
    z, rgb, a = layer_arrays(ls)
    exact = expected(EXACT[0], z, rgb, a, BG)
    assert np.abs(frame.image[..., :3] - exact[:3]).max() <= a.sum()
    assert (frame.image[0, 0, :3] > F32_BG).all()  # the fragments' own color was added


@pytest.mark.parametrize("name", sorted({"hybrid", "ktab"} & set(NAMES)))
def test_alpha_just_below_one_is_quantized_to_one(renderer, name):
    # 1 - 1e-6 packs to 255: everything behind the front fragment gets T = 0. docs/methods.md:
    # |T'_i - T_i| <= sum_{j<i} |q_j - a_j|, so the pixel error is at most
    # (sum_i a_i (i - 1) + n) max|q - a| with max|q - a| = 1e-6 here (the bound with 1/510).
    ls = layers(ALPHAS["near_one"])
    frame = render(renderer, name, full_screen_layers(ls), k=8)
    z, rgb, a = layer_arrays(ls)
    exact = expected(EXACT[0], z, rgb, a, BG)
    q_err = 1.0 - a[0]
    bound = (np.sum(np.sort(a) * np.arange(len(a))) + len(a)) * q_err
    assert np.abs(frame.image - exact).max() <= bound + tolerance(name, len(a))
    front = np.argmin(z)
    assert np.array_equal(frame.image[0, 0, :3], (np.float32(a[front]) * rgb[front]).astype(np.float32))


@pytest.mark.parametrize("name", NAMES)
def test_no_transparent_fragments_at_all(renderer, name):
    # The limit of alpha 0 everywhere: nothing transparent to composite (compact_abuffer
    # once failed here, its per-triangle buffer sized for no triangle).
    r = renderer(3, 2)
    empty_mesh = oit.Scene()
    empty_mesh.add_mesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.uint32), (1.0, 0.0, 0.0, 0.5))
    opaque_only = full_screen_layers([(0.5, (0.25, 0.5, 0.75, 1.0))], opaque=[0])
    cases = ((oit.Scene(), (*F32_BG, 0.0)), (empty_mesh, (*F32_BG, 0.0)), (opaque_only, (0.25, 0.5, 0.75, 1.0)))
    for scene, want in cases:
        frame = r.render(scene, IDENTITY, name, background=tuple(BG), **params_for(name), census=True)
        assert np.array_equal(frame.image, np.broadcast_to(np.float32(want), (2, 3, 4)))
        assert frame.stats["fragments"] == 0 and frame.stats["overflow_fragments"] == 0
