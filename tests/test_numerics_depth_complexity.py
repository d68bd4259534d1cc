"""Depth complexity from 1 to 4,000 fragments at one pixel, every method: the exact methods
stay within the float32 bound of the float64 composite (docs/methods.md: n 2^-24), the
others within their model's bound (numerics.tolerance); bounded methods keep their memory and
count what overflows, as the model says; list methods that cannot resolve a pixel on
llvmpipe (65,535 loop iterations an invocation) refuse it with an error instead of an image;
the sorted resolve of the storing methods splits its work across dispatches instead."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from numerics import (
    BG,
    BOUNDED,
    EXACT,
    INFO,
    NAMES,
    PER_LAYER,
    assert_within_error_bound,
    expected_overflow,
    params_for,
    render_or_limit,
    stacks,
    tolerance,
)
from oit import memory_bytes

DEPTHS = [1, 32, 33, 300, 4000]
REGIMES = {
    # Faint layers: T falls to ~e^-4 over 4,000 layers, so every layer matters to the end.
    "faint": lambda rng, n: rng.uniform(1e-4, 2e-3, n),
    # Dense layers: T underflows to 0 after ~150 layers; the tail and the sums saturate.
    "dense": lambda rng, n: rng.uniform(0.5, 1.0, n),
}
_STACKS = {}


def deep(n, regime):
    """A 1 x 1 frame with n fragments at distinct depths in shuffled order (cached)."""
    if (n, regime) not in _STACKS:
        _STACKS[(n, regime)] = stacks(1, 1, n, seed=n, alpha=REGIMES[regime])
    return _STACKS[(n, regime)]


def loop_limited(renderer):
    return renderer.adapter_info["loop_limit"] is not None


# Methods that peel one layer a geometry pass cost n passes of n fragments: 4,000 layers take
# ~10 s on lavapipe, so they run to 300 layers here (and bounded, at 4,000, below).
CASES = [pytest.param(name, n, id=f"{name}-{n}") for name in NAMES for n in DEPTHS
         if not (name in PER_LAYER and n > 300)]


@pytest.mark.parametrize("regime", list(REGIMES))
@pytest.mark.parametrize("name,n", CASES)
def test_deep_pixel_matches_model(renderer, name, n, regime):
    s = deep(n, regime)
    params = params_for(name)
    want = s.expect(name, **params)
    frame = render_or_limit(renderer(1, 1), s.scene, name, background=tuple(BG), **params)
    if isinstance(frame, RuntimeError):
        # Refused on llvmpipe: never at depths the docs promise (exact methods up to 10,890).
        assert not INFO[name]["exact"], frame
        return
    assert frame.stats["max_depth_complexity"] == n and frame.stats["fragments"] == n
    assert_within_error_bound(frame, s.expect(EXACT[0]))
    a = s.alpha[0]
    err = np.abs(frame.image[0, 0].astype(np.float64) - want[0, 0]).max()
    assert err <= tolerance(name, n, mass=a.sum(), **params), (err, frame.image[0, 0], want[0, 0])
    overflow = expected_overflow(name, s.z[0], a, **params)
    if overflow is not None:
        assert frame.stats["overflow_fragments"] == overflow


@pytest.mark.parametrize("name", BOUNDED)
def test_bounded_memory_does_not_grow_with_depth(renderer, name):
    # Per-layer methods peel at most 8 layers here (4,000 would take ~10 s): they must count
    # the rest as overflow.
    params = params_for(name, layers=8)
    frames = [render_or_limit(renderer(1, 1), deep(n, "faint").scene, name, **params) for n in (1, 4000)]
    mem = [f.stats["memory_bytes"] for f in frames]
    assert mem[0] == mem[1]
    if name in PER_LAYER:
        assert frames[1].stats["overflow_fragments"] >= 4000 - 2 * 8
    formula = memory_bytes(name, 1, 1, **params)
    if formula is not None:
        assert mem[0] == formula


@pytest.mark.parametrize("name", sorted(set(NAMES) - set(BOUNDED)))
def test_unbounded_memory_follows_the_fragments(renderer, name):
    # Methods that declare unbounded memory hold every fragment: at least a 4-byte word each
    # (abuffer's node is 24 bytes), whatever the frames before (pools shrink lazily).
    frame = render_or_limit(renderer(1, 1), deep(300, "faint").scene, name, **params_for(name))
    if isinstance(frame, RuntimeError):
        pytest.skip(f"{name} refuses 300 fragments on this adapter")
    assert frame.stats["memory_bytes"] >= 4 * 300


@pytest.mark.parametrize("k", [1, 8, 32])
@pytest.mark.parametrize("name", sorted({"hybrid", "ktab"} & set(NAMES)))
def test_overflow_counts_every_fragment_past_the_core(renderer, name, k):
    # 4,000 distinct keys at one pixel: exactly n - k go to the tail (hybrid) or are dropped
    # (ktab), whatever k; the memory stays the formula's.
    s = deep(4000, "dense")
    frame = renderer(1, 1).render(s.scene, oit.Camera(np.eye(4)), name, background=tuple(BG), k=k)
    assert frame.stats["overflow_fragments"] == 4000 - k == expected_overflow(name, s.z[0], s.alpha[0], k=k)
    assert frame.stats["memory_bytes"] == memory_bytes(name, 1, 1, k=k)
    want = s.expect(name, k=k)[0, 0]
    assert np.abs(frame.image[0, 0] - want).max() <= tolerance(name, 4000, s.alpha[0].sum())


@pytest.mark.parametrize("layers", [11000, 30000])
def test_exact_methods_resolve_pixels_past_the_loop_limit(renderer, layers):
    # docs/methods.md ("abuffer"): the sorted resolve pauses each invocation within
    # llvmpipe's 65,535 loop iterations and resumes in the next dispatch, so a pixel of any
    # depth is composited exactly (the old one-sweep-a-batch resolve refused past ~10,890).
    r = renderer(1, 1)
    s = stacks(1, 1, layers, seed=1, alpha=REGIMES["faint"])
    names = sorted(set(EXACT) - set(PER_LAYER))  # peeling has no per-pixel loop (and takes a minute)
    for name in names if layers < 20000 else ["abuffer"]:
        frame = r.render(s.scene, oit.Camera(np.eye(4)), name, background=tuple(BG))
        err = np.abs(frame.image[0, 0] - s.expect(name)[0, 0]).max()
        assert err <= tolerance(name, layers), (name, err)
        assert frame.stats["extra"]["resolve_sweeps"] > 2, frame.stats["extra"]


@pytest.mark.parametrize("nodes,depths", [(8, [300, 450, 500, 510, 520, 1000, 4000]), (32, [300, 330, 340])])
def test_adaptive_lists_is_right_or_refuses_near_its_loop_limit(renderer, nodes, depths):
    # On llvmpipe adaptive_lists builds a pixel's whole visibility function in one invocation; its
    # estimate of the loop count decides. On both sides of it, every frame must be either the
    # model's answer or a RuntimeError naming the limit: never a silently truncated loop.
    r = renderer(1, 1)
    outcomes = []
    for n in depths:
        s = deep(n, "faint") if n in DEPTHS else stacks(1, 1, n, seed=n, alpha=REGIMES["faint"])
        frame = render_or_limit(r, s.scene, "adaptive_lists", background=tuple(BG), nodes=nodes)
        if isinstance(frame, RuntimeError):
            assert f"{n} fragments" in str(frame) and "nodes" in str(frame)
            outcomes.append("refused")
            continue
        want = s.expect("adaptive_lists", nodes=nodes)[0, 0]
        assert np.abs(frame.image[0, 0] - want).max() <= tolerance("adaptive_lists", n, s.alpha[0].sum()), n
        outcomes.append("right")
    assert outcomes[0] == "right"  # 300 fragments always fit
    if loop_limited(r):
        assert outcomes[-1] == "refused"
        assert outcomes == sorted(outcomes, key=lambda o: o == "refused")  # refused only past a threshold


@pytest.mark.parametrize("name,param", [("adaptive", "nodes"), ("mlab", "layers")])
@pytest.mark.parametrize("count", [8, 32])
def test_locked_methods_have_no_loop_limit(renderer, name, param, count):
    # The bounded adaptive and mlab update N entries a fragment (docs/methods.md, "Critical
    # sections"): no loop grows with the pixel's depth, so 4,000 layers are the model's answer,
    # never a refusal, and no fragment waited for or gave up on its pixel's lock.
    r = renderer(1, 1)
    for regime in REGIMES:
        s = deep(4000, regime)
        frame = r.render(s.scene, oit.Camera(np.eye(4)), name, background=tuple(BG), **{param: count})
        want = s.expect(name, **{param: count})[0, 0]
        assert np.abs(frame.image[0, 0] - want).max() <= tolerance(name, 4000, s.alpha[0].sum()), regime
        assert frame.stats["extra"]["lock_failures"] == frame.stats["extra"]["lock_waits"] == 0


def test_deferred_shading_of_deep_pixels_keeps_within_the_loop_budget(renderer):
    # compact_abuffer shades each fragment at resolve (docs/shading.md): the light loop and
    # the shading-cost loop count in the sorted resolve's step budget on llvmpipe, so a deep
    # lit pixel still resolves completely, equal to the A-buffer, which shades at capture.
    rng = np.random.default_rng(2)
    scene = oit.Scene()
    for z in rng.permutation(np.linspace(0.01, 0.99, 3000)):
        positions = np.array([[-1, -1, z], [1, -1, z], [1, 1, z], [-1, 1, z]], dtype=np.float32)
        color = (*rng.uniform(0, 1, 3), rng.uniform(0.001, 0.01))
        scene.add_mesh(positions, [[0, 1, 2], [0, 2, 3]], color, normals=np.tile([0.0, 0.3, -1.0], (4, 1)), specular=0.3)
    r = renderer(2, 2)
    for cost in (0, 64):
        exact = r.render(scene, oit.Camera(np.eye(4)), "abuffer", shading_cost=cost, background=tuple(BG))
        frame = r.render(scene, oit.Camera(np.eye(4)), "compact_abuffer", shading_cost=cost, background=tuple(BG))
        assert np.abs(frame.image - exact.image).max() <= 2e-6
        assert frame.stats["extra"]["resolve_sweeps"] > 2
