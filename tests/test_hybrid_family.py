"""Hybrid transparency and the methods it is judged against (hybrid, ktab, wavg, wsum,
wboit, adaptive): each GPU image against its CPU model (oit.models, float64) fed the same
fragment stacks, the models against the exact composite, and hybrid's packing cases (ties,
tiny alpha, alpha = 1)."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from oit import memory_bytes, models
from oit.models import ALPHA_8BIT_ERROR
from oit.scenes import stacks
from scenes import IDENTITY, build_scene, layer, random_meshes

BG = np.array([0.2, 0.4, 0.6])

# (method, params, tolerance against its model). Bounds, from docs/methods.md:
# - hybrid/ktab: the model mirrors the 24/8-bit keys and the tie rule, so only float32
#   products (<= n * 2^-24 relative) and fixed-point sums (core 2^-32, tail n * 2^-25 per
#   add) separate them: 2e-6 covers n = 100.
# - wavg/wboit/adaptive: float32 sums and products over n <= 100 layers: 2e-6.
# - wsum is unbounded (sums reach n): float32 relative error 100 * 2^-24 of values up to 50.
CASES = [
    ("hybrid", {"k": 1}, 2e-6), ("hybrid", {"k": 4}, 2e-6), ("hybrid", {"k": 16}, 2e-6),
    ("hybrid64", {"k": 1}, 2e-6), ("hybrid64", {"k": 4}, 2e-6), ("hybrid64", {"k": 16}, 2e-6),
    ("ktab", {"k": 4}, 2e-6), ("wavg", {}, 2e-6), ("wboit", {}, 2e-6),
    ("adaptive", {"nodes": 4}, 2e-6), ("adaptive", {"nodes": 8}, 2e-6), ("wsum", {}, 5e-5),
]


def model_image(built, method, params, bg=BG):
    m = built.meta
    return np.array([models.MODELS[method](m["z"][p], m["rgb"][p], m["alpha"][p], bg, **params)
                     for p in range(len(m["z"]))])


@pytest.mark.parametrize("alphas", ["random", "worst"])
@pytest.mark.parametrize("layers", [20, 100])
@pytest.mark.parametrize("method,params,tol", CASES, ids=[f"{m}-{p}" for m, p, _ in CASES])
def test_gpu_matches_model(renderer, method, params, tol, layers, alphas):
    built = stacks(layers=layers, alphas=alphas, size=(6, 6), seed=layers)
    frame = renderer(6, 6).render(built.scene, built.camera, method, background=tuple(BG), **params)
    got = frame.image.reshape(-1, 4)
    want = model_image(built, method, params)
    assert np.abs(got - want).max() <= tol


@pytest.mark.parametrize("alphas", ["random", "increasing", "worst", "constant"])
def test_models_are_exact_when_capacity_suffices(alphas):
    """With k (nodes) >= the depth complexity, hybrid and ktab equal the exact composite up
    to 8-bit alpha quantization, and adaptive equals it exactly."""
    built = stacks(layers=12, alphas=alphas, size=(4, 4), seed=7)
    m = built.meta
    for p in range(16):
        z, rgb, a = m["z"][p], m["rgb"][p], m["alpha"][p]
        exact = models.exact(z, rgb, a, BG)
        # |T' - T| <= sum |q_j - a_j| <= (i - 1) * ALPHA_8BIT_ERROR before fragment i (docs/methods.md).
        n = len(z)
        bound = (np.sum(a * np.arange(n)) + n) * ALPHA_8BIT_ERROR
        for method in ("hybrid", "ktab"):
            assert np.abs(models.MODELS[method](z, rgb, a, BG, k=n) - exact).max() <= bound
        assert np.abs(models.adaptive(z, rgb, a, BG, nodes=n) - exact).max() <= 1e-12


def random_scene(seed):
    return build_scene(random_meshes(seed)), IDENTITY


def test_hybrid_with_k_at_depth_complexity_equals_abuffer(renderer):
    scene, camera = random_scene(11)
    r = renderer(32, 32)
    exact = r.render(scene, camera, "abuffer", background=tuple(BG))
    k = int(exact.stats["max_depth_complexity"])
    assert 2 <= k <= 32
    hyb = r.render(scene, camera, "hybrid", background=tuple(BG), k=k)
    assert hyb.stats["overflow_fragments"] == 0
    dc = exact.depth_complexity
    # Per pixel, 8-bit alpha changes each transmittance by at most (number in front) * ALPHA_8BIT_ERROR.
    bound = (dc * (dc + 1) / 2 + dc) * ALPHA_8BIT_ERROR + 1e-6
    assert (np.abs(hyb.image - exact.image).max(-1) <= bound).all()
    assert np.abs(hyb.image - exact.image).mean() < 2e-3


def quads(layers, size=4):
    """A scene of full-screen quads: (z, (r, g, b, a)) in submission order."""
    s = oit.Scene()
    for z, rgba in layers:
        p = np.array([[-1, -1, z], [1, -1, z], [1, 1, z], [-1, 1, z]], np.float32)
        s.add_mesh(p, [[0, 1, 2], [0, 2, 3]], rgba)
    return s


def composite_model(layers, method, **params):
    z = np.array([layer[0] for layer in layers])
    rgba = np.array([layer[1] for layer in layers], np.float64)
    return models.MODELS[method](z, rgba[:, :3], rgba[:, 3], BG, **params)


def test_quantized_depth_ties_across_the_core_boundary(renderer, identity_camera):
    """Three fragments share one packed key and only one slot is left for them: none may be
    counted twice or dropped, and the result must not depend on submission order."""
    layers = [(0.2, (0.9, 0.1, 0.1, 0.5)), (0.6, (0.1, 0.9, 0.1, 0.3)), (0.6, (0.1, 0.1, 0.9, 0.3)),
              (0.6 + 1e-9, (0.9, 0.9, 0.1, 0.3)), (0.8, (0.5, 0.5, 0.5, 0.4))]
    r = renderer(4, 4)
    images = []
    for perm in ([0, 1, 2, 3, 4], [4, 3, 2, 1, 0], [2, 0, 4, 1, 3]):
        f = r.render(quads([layers[i] for i in perm]), identity_camera, "hybrid", background=tuple(BG), k=2)
        images.append(f.image)
        # The nearer fragment is core; the three tied ones and the far one go to the tail.
        assert f.stats["overflow_fragments"] == 4 * 16
    assert all(np.array_equal(images[0], im) for im in images[1:])
    want = composite_model(layers, "hybrid", k=2)
    assert np.abs(images[0][0, 0] - want).max() < 2e-6
    # With room for all of them the tied group is core: its members share the group's
    # visibility T (1 - (1 - a)^3) equally (their order is undefined), so coverage is exact up
    # to 8-bit alpha and the color is the model's.
    f = r.render(quads(layers), identity_camera, "hybrid", background=tuple(BG), k=8)
    assert f.stats["overflow_fragments"] == 0
    assert np.abs(f.image[0, 0] - composite_model(layers, "hybrid", k=8)).max() < 2e-6
    assert abs(f.image[0, 0, 3] - composite_model(layers, "abuffer")[3]) < 5 * ALPHA_8BIT_ERROR


def test_alpha_below_8bit_resolution_is_not_dropped(renderer, identity_camera):
    """alpha = 1e-3 packs to 0 in the key; the fragment still adds C * alpha * T."""
    layers = [(0.3, (1.0, 1.0, 1.0, 1e-3)), (0.5, (1.0, 0.0, 0.0, 1e-4))]
    r = renderer(4, 4)
    for method in ("hybrid", "ktab"):
        f = r.render(quads(layers), identity_camera, method, background=(0.0, 0.0, 0.0), k=4)
        exact = r.render(quads(layers), identity_camera, "abuffer", background=(0.0, 0.0, 0.0))
        # Colors use the exact alpha; only the transmittance in front of the second fragment
        # loses 1e-3 (its key's alpha is 0), a color error of 1e-3 * 1e-4.
        assert np.abs(f.image[..., :3] - exact.image[..., :3]).max() <= 1e-3 * 1e-4 + 1e-7
        assert f.image[0, 0, 0] > 1e-3
        # Coverage comes from the keys: both alphas pack to 0, an error below their sum.
        assert np.abs(f.image[..., 3] - exact.image[..., 3]).max() <= 1e-3 + 1e-4


def test_alpha_one_hides_everything_behind(renderer, identity_camera):
    layers = [(0.7, (0.0, 1.0, 0.0, 0.6)), (0.4, (0.3, 0.2, 0.1, 1.0)), (0.1, (0.0, 0.0, 1.0, 0.5))]
    r = renderer(4, 4)
    want = np.array([0.5 * 0.3, 0.5 * 0.2, 0.5 + 0.5 * 0.1, 1.0])
    for method, params in (("abuffer", {}), ("hybrid", {"k": 2}), ("hybrid", {"k": 8}), ("ktab", {"k": 2})):
        f = r.render(quads(layers), identity_camera, method, background=tuple(BG), **params)
        # 8-bit alpha: 0.5 packs exactly (128/255 differs by 1/510), so allow that bound.
        assert np.abs(f.image - want).max() <= 1 / 510 + 1e-6, method


def test_weighted_methods_with_all_alpha_zero_give_the_background(renderer, identity_camera):
    layers = [(0.3, (1.0, 0.0, 0.0, 0.0)), (0.6, (0.0, 1.0, 0.0, 0.0))]
    r = renderer(4, 4)
    for method in ("wavg", "wsum", "wboit", "hybrid", "ktab", "adaptive", "abuffer", "unsorted"):
        f = r.render(quads(layers), identity_camera, method, background=tuple(BG))
        assert np.array_equal(f.image[..., :3], np.broadcast_to(BG.astype(np.float32), (4, 4, 3))), method
        assert (f.image[..., 3] == 0).all(), method


@pytest.mark.parametrize("method,params", [
    ("hybrid", {"k": 1}), ("hybrid", {"k": 8}), ("ktab", {"k": 32}), ("wavg", {}), ("wsum", {}), ("wboit", {}),
    ("hybrid64", {"k": 8}),
    ("unsorted", {}), ("additive", {}), ("filter", {}), ("depth_peeling", {}), ("dual_depth_peeling", {"layers": 2}),
    ("bucket_peeling", {"buckets": 4}), ("stochastic", {"samples": 16}), ("screen_door", {}),
])
def test_bounded_memory_follows_the_formula(renderer, method, params):
    scene, camera = random_scene(2)
    f = renderer(24, 16).render(scene, camera, method, **params)
    assert f.stats["memory_bytes"] == memory_bytes(method, 24, 16, **params)


def test_wboit_weight_choice(renderer):
    scene, camera = random_scene(5)
    r = renderer(16, 16)
    a = r.render(scene, camera, "wboit", weight="eq10").image
    b = r.render(scene, camera, "wboit", weight="eq7").image
    assert not np.array_equal(a, b)
    with pytest.raises(ValueError, match="eq10"):
        r.render(scene, camera, "wboit", weight="eq11")


def test_every_bounded_method_has_a_memory_formula():
    missing = [m["name"] for m in oit.methods() if m["bounded_memory"] and memory_bytes(m["name"], 4, 4) is None]
    assert not missing


def test_hybrid64_with_k_at_depth_complexity_is_within_its_quantization(renderer):
    scene, camera = random_scene(13)
    r = renderer(32, 32)
    exact = r.render(scene, camera, "abuffer", background=tuple(BG))
    k = int(exact.stats["max_depth_complexity"])
    h = r.render(scene, camera, "hybrid64", background=tuple(BG), k=k)
    assert h.stats["overflow_fragments"] == 0
    dc = exact.depth_complexity
    # 8-bit alpha as in hybrid, plus colors quantized to 11/11/10 bits (<= 1/2046 a channel).
    bound = (dc * (dc + 1) / 2 + dc) * ALPHA_8BIT_ERROR + 1 / 2046 + 1e-6
    assert (np.abs(h.image - exact.image).max(-1) <= bound).all()


def test_hybrid64_is_order_independent(renderer, identity_camera):
    layers = [(0.1 * (i + 1), (0.1 * i, 0.5, 1 - 0.1 * i, 0.3)) for i in range(9)]
    r = renderer(4, 4)
    a = r.render(quads(layers), identity_camera, "hybrid64", k=3).image
    b = r.render(quads(layers[::-1]), identity_camera, "hybrid64", k=3).image
    assert np.array_equal(a, b)


@pytest.mark.parametrize("alpha", [0.1, 0.3, 0.5, 0.7, 0.9])
def test_decimal_alphas_get_one_key_whatever_their_last_bits(alpha):
    # alpha * 255 is an exact half step here; the interpolated alpha lands a few float32
    # ulps either side of it, and every one must give the same 8-bit key (docs/methods.md).
    a = np.float32(alpha)
    near = [a]
    for _ in range(8):
        near += [np.nextafter(near[-2] if len(near) > 1 else a, np.float32(0)), np.nextafter(near[-1], np.float32(1))]
    keys = models.alpha_8bit(np.array(near, np.float32))
    assert len(set(keys.tolist())) == 1 and abs(int(keys[0]) / 255 - alpha) <= models.ALPHA_8BIT_ERROR


@pytest.mark.parametrize("method", ["hybrid", "hybrid64", "ktab"])
def test_a_flat_alpha_of_0_7_shades_flat(renderer, method):
    # Two flat layers seen in perspective: alpha 0.7 in front (178.5 / 255) interpolates with
    # rounding noise across the frame; the image must still be one color.
    meshes = [layer(0.3, (0.9, 0.2, 0.1, 0.7)), layer(0.6, (0.1, 0.4, 0.9, 0.5))]
    for m in meshes:
        m.positions[:, 2] = m.positions[:, 2] + 0.2 * m.positions[:, 0]  # tilted: z varies across
    frame = renderer(32, 32).render(build_scene(meshes), IDENTITY, method, k=2, background=(1.0, 1.0, 1.0))
    rgb = frame.image[2:-2, 2:-2, :3].reshape(-1, 3)
    assert np.abs(rgb - rgb[0]).max() <= 2e-6


# The float tails (docs/methods.md, "hybrid"): tail="blend" sums by float32 blending, in whatever
# order fragments arrive; tail="compact" (Eq. 12's 2k + 2 words a pixel) blends its sums into
# RGBA16F and takes the count from the census. Each of the three tail sums (C alpha, alpha,
# count) is within n u of its value relative to the sum (u: the format's unit roundoff, 2^-24
# or 2^-11), and eqs. 7-10 move the tail by at most three such relative errors: 3 n u on top of
# the fixed-point tail's tolerance.
ROUNDOFF = {"blend": 2.0**-24, "compact": 2.0**-11}
HALF = ROUNDOFF["compact"]


@pytest.mark.parametrize("alphas", ["random", "worst"])
@pytest.mark.parametrize("k", [1, 4])
@pytest.mark.parametrize("tail", list(ROUNDOFF))
def test_float_tails_match_the_model_within_their_sums(renderer, tail, k, alphas):
    layers = 100
    built = stacks(layers=layers, alphas=alphas, size=(6, 6), seed=layers)
    frame = renderer(6, 6).render(built.scene, built.camera, "hybrid", background=tuple(BG), k=k, tail=tail)
    want = model_image(built, "hybrid", {"k": k})
    assert np.abs(frame.image.reshape(-1, 4) - want).max() <= 2e-6 + 3 * layers * ROUNDOFF[tail]
    assert frame.stats["params"]["tail"] == tail
    # compact's count is the census's less the core's: the same tail as the others'.
    assert frame.stats["census"] == (tail == "compact")
    exact = renderer(6, 6).render(built.scene, built.camera, "hybrid", background=tuple(BG), k=k)
    assert frame.stats["overflow_fragments"] == exact.stats["overflow_fragments"]


def test_blended_tail_depends_on_order_only_within_its_rounding(renderer):
    meshes = random_meshes(7, transparent=12, opaque=1, triangles=8, space="ndc", spread=0.9)
    r = renderer(40, 40)
    first = r.render(build_scene(meshes), IDENTITY, "hybrid", background=(0.3, 0.3, 0.3), k=2, tail="blend", census=True)
    n = first.stats["max_depth_complexity"]
    assert first.stats["overflow_fragments"] > 0  # a tail to sum
    exact = r.render(build_scene(meshes), IDENTITY, "hybrid", background=(0.3, 0.3, 0.3), k=2)
    rng = np.random.default_rng(1)
    for _ in range(3):
        shuffled = [meshes[i].shuffled(rng) for i in rng.permutation(len(meshes))]
        frame = r.render(build_scene(shuffled), IDENTITY, "hybrid", background=(0.3, 0.3, 0.3), k=2, tail="blend")
        assert np.abs(frame.image - first.image).max() <= 2 * 3 * n * 2.0**-24
        # The fixed-point tail is bit-identical under the same shuffles.
        assert np.array_equal(r.render(build_scene(shuffled), IDENTITY, "hybrid", background=(0.3, 0.3, 0.3), k=2).image, exact.image)
    # Both tails keep the per-pixel error bound against the exact composite.
    ref = r.render(build_scene(meshes), IDENTITY, "abuffer", background=(0.3, 0.3, 0.3)).image
    for frame in (first, exact):
        assert (np.abs(frame.image - ref)[..., :3] <= frame.error_bound + 1e-6).all()


@pytest.mark.parametrize("k", [1, 8, 32])
def test_compact_tail_keeps_eq_12s_words(renderer, k):
    built = stacks(layers=40, alphas="random", size=(8, 6), seed=2)
    frame = renderer(8, 6).render(built.scene, built.camera, "hybrid", k=k, tail="compact")
    # Per pixel Eq. 12's 2k + 2 words; per frame the slot-offset placeholder (4 bytes, which also
    # fills the unused sums' binding) and the overflow counter (4).
    assert frame.stats["memory_bytes"] == memory_bytes("hybrid", 8, 6, k=k, tail="compact") == 8 * 6 * (2 * k + 2) * 4 + 8
    # The exact tail: k-TAB and visibility, 9 accumulator words and 6 tail words a pixel.
    assert memory_bytes("hybrid", 8, 6, k=k) == 8 * 6 * (2 * k + 15) * 4 + 8
    exact = renderer(8, 6).render(built.scene, built.camera, "hybrid", k=k, tail="exact")
    assert exact.stats["memory_bytes"] == memory_bytes("hybrid", 8, 6, k=k)


def test_compact_tail_depends_on_order_only_within_its_rounding(renderer):
    meshes = random_meshes(7, transparent=12, opaque=1, triangles=8, space="ndc", spread=0.9)
    r = renderer(40, 40)
    bg = (0.3, 0.3, 0.3)
    first = r.render(build_scene(meshes), IDENTITY, "hybrid", background=bg, k=2, tail="compact")
    n = first.stats["max_depth_complexity"]
    assert first.stats["overflow_fragments"] > 0  # a tail to sum
    ref = r.render(build_scene(meshes), IDENTITY, "abuffer", background=bg).image
    rng = np.random.default_rng(1)
    for _ in range(3):
        shuffled = [meshes[i].shuffled(rng) for i in rng.permutation(len(meshes))]
        frame = r.render(build_scene(shuffled), IDENTITY, "hybrid", background=bg, k=2, tail="compact")
        # The tail's half-float sums, and the core's float32 sums (k terms) in the output.
        assert np.abs(frame.image - first.image).max() <= 2 * 3 * n * HALF + 2 * 2 * 2.0**-24
        assert (np.abs(frame.image - ref)[..., :3] <= frame.error_bound + 1e-6).all()


def test_compact_tail_in_tiles_is_the_untiled_frame(renderer):
    built = oit.scenes.hair(strands=300)
    whole = renderer(64, 48).render(built.scene, built.camera, "hybrid", k=4, tail="compact")
    budget = whole.stats["target_bytes"] + whole.stats["memory_bytes"] // 3
    tiled = oit.Renderer(64, 48, memory_budget=budget).render(built.scene, built.camera, "hybrid", k=4, tail="compact")
    assert tiled.stats["tiles"] > 1 and tiled.stats["peak_memory_bytes"] <= budget
    assert np.abs(tiled.image - whole.image).max() <= 1e-6


def test_tail_must_be_exact_or_blend(renderer):
    built = stacks(layers=4, alphas="random", size=(2, 2), seed=1)
    with pytest.raises(ValueError, match="exact, blend, compact"):
        renderer(2, 2).render(built.scene, built.camera, "hybrid", tail="fast")
    with pytest.raises(ValueError, match="no parameter 'tail'"):
        renderer(2, 2).render(built.scene, built.camera, "ktab", tail="blend")
