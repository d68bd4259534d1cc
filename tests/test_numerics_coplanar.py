"""Coplanar and nearly coplanar fragments: equal depths, and depths apart by less than the
24-bit key's resolution (2^-24).

- The exact methods, hybrid, hybrid64, ktab and auto promise the same bits under any
  submission order (docs/methods.md): 10 shuffles of mesh, triangle and vertex order, compared bit for
  bit. The peeling methods are exact but break exact depth ties by submission (their
  documented rule): tested against that rule instead.
- The commutative float sums (wsum, wavg, wboit, additive, filter) promise the same image
  only up to the float32 rounding of a reordered sum.
- Blending in submission order (unsorted, sorted, screen_door, mlab's and adaptive's
  insertion order, stochastic's per-triangle noise) promises nothing under reordering.
- Every method repeats its frame bit for bit when nothing changes.
"""

from __future__ import annotations

import numpy as np
import pytest

from numerics import (
    BG,
    BIT_ORDER_INDEPENDENT,
    EXACT,
    NAMES,
    ORDER_TIES,
    SUBMISSION_TIES,
    SUM_ORDER_INDEPENDENT,
    exact_in_submission_order,
    expected,
    layer_arrays,
    params_for,
    tolerance,
)
from oit import geometry
from scenes import IDENTITY, MeshData, build_scene, layer, random_meshes

SIZE = (16, 16)
Z_NEAR = float(np.float32(0.2))  # in [1/8, 1/4): float32 steps of 2^-26 there
STEP = 2.0 ** -26  # a quarter of the 24-bit key's resolution
COLORS = [(1, 0, 0, 0.5), (0, 1, 0, 0.5), (0, 0, 1, 0.25), (1, 1, 0, 0.75), (0.2, 0.7, 0.9, 0.4), (0.5, 0.5, 0.5, 0.5)]


def full_screen(kind):
    """(z, rgba) layers: six coplanar ones between two others."""
    # "distinct": float32 depths within 6 x 2^-26 < 2^-23, so one or two 24-bit keys.
    zs = [0.5] * len(COLORS) if kind == "equal" else [Z_NEAR + i * STEP for i in range(len(COLORS))]
    return [(0.1, (0.3, 0.3, 0.3, 0.3)), *list(zip(zs, COLORS)), (0.9, (0.9, 0.1, 0.5, 0.6))]


def random_coplanar(kind, seed=5):
    """Overlapping random triangles (per-vertex colors) squashed onto z = 0.5, or onto
    z = 0.2 + (0..3) x 2^-26 per vertex (depths differ below the key resolution)."""
    rng = np.random.default_rng(seed)
    out = []
    for m in random_meshes(seed, transparent=6, opaque=0, triangles=4, spread=0.9):
        p = m.positions.copy()
        p[:, 2] = 0.5 if kind == "equal" else Z_NEAR + rng.integers(0, 4, len(p)) * STEP
        out.append(MeshData(p.astype(np.float32), m.indices, m.colors))
    return out


SCENES = {
    "layers-equal": lambda: [layer(z, c) for z, c in full_screen("equal")],
    "layers-near": lambda: [layer(z, c) for z, c in full_screen("near")],
    "triangles-equal": lambda: random_coplanar("equal"),
    "triangles-near": lambda: random_coplanar("near"),
}
RUNS = [(name, {}) for name in BIT_ORDER_INDEPENDENT if name not in ("hybrid", "hybrid64", "ktab")]
RUNS += [(name, {"k": k}) for name in ("hybrid", "hybrid64", "ktab") if name in NAMES for k in (2, 8)]


def runs(tied=True):
    """pytest params of RUNS. Where the scene has exactly tied depths (`tied`), the methods that
    take ties in submission order (ORDER_TIES) are left out; the exact ones among them
    (SUBMISSION_TIES) are tested on their own below."""
    return [pytest.param(name, params, id=f"{name}-{params}" if params else name)
            for name, params in RUNS if not (tied and name in ORDER_TIES)]


def shuffles(meshes, count, seed=0):
    """`count` submissions of the same meshes: mesh order, triangle order in each mesh and
    vertex order all permuted (each triangle keeps its own vertex order)."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield [meshes[i].shuffled(rng) for i in rng.permutation(len(meshes))]


def render(renderer, meshes, name, **params):
    return renderer(*SIZE).render(build_scene(meshes), IDENTITY, name, background=tuple(BG),
                                  **params_for(name, **params), census=True)


# "layers-near" has distinct float32 depths everywhere: no exact tie for peeling to break.
@pytest.mark.parametrize("scene,name,params", [pytest.param(scene, *p.values, id=f"{p.id}-{scene}")
                                               for scene in SCENES for p in runs(tied=scene != "layers-near")])
def test_order_independent_methods_give_identical_bits(renderer, name, params, scene):
    meshes = SCENES[scene]()
    frames = [render(renderer, m, name, **params) for m in shuffles(meshes, 10)]
    first = frames[0]
    assert first.stats["max_depth_complexity"] >= 6
    for i, f in enumerate(frames[1:], 1):
        diff = np.argwhere((f.image != first.image).any(-1))
        assert len(diff) == 0, (f"shuffle {i}: {len(diff)} pixels differ, first {diff[0]}: "
                                f"{f.image[tuple(diff[0])]} vs {first.image[tuple(diff[0])]}")
        assert np.array_equal(f.depth_complexity, first.depth_complexity)


@pytest.mark.parametrize("kind,name,params", [pytest.param(kind, *p.values, id=f"{p.id}-{kind}")
                                              for kind in ("equal", "near") for p in runs(tied=kind == "equal")])
def test_coplanar_layers_match_the_model(renderer, name, params, kind):
    # The exact methods order equal depths by color (the reference's tie rule); hybrid's
    # keys tie below 2^-24 and ties share visibility (docs/methods.md, "Ties"); the models
    # mirror both.
    ls = full_screen(kind)
    frame = render(renderer, [layer(z, c) for z, c in ls], name, **params)
    z, rgb, a = layer_arrays(ls)
    want = expected(name, z, rgb, a, BG, **params_for(name, **params))
    assert np.abs(frame.image - want).max() <= tolerance(name, len(ls)), (frame.image[0, 0], want)


@pytest.mark.parametrize("name", SUBMISSION_TIES)
def test_peeling_composites_ties_in_submission_order(renderer, name):
    # What the peeling methods promise instead (docs/methods.md): exact, with equal depths in
    # submission order. Under the identity camera each full-screen quad gives every pixel one
    # fragment, so the order of the tied quads is the mesh order.
    ls = full_screen("equal")
    rng = np.random.default_rng(1)
    for _ in range(4):
        order = rng.permutation(len(ls))
        submitted = [ls[i] for i in order]
        frame = render(renderer, [layer(z, c) for z, c in submitted], name)
        want = exact_in_submission_order(*layer_arrays(submitted), BG)
        assert np.abs(frame.image - want).max() <= tolerance(name, len(ls)), order


@pytest.mark.parametrize("scene", list(SCENES))
@pytest.mark.parametrize("name", SUM_ORDER_INDEPENDENT)
def test_commutative_sums_agree_to_rounding(renderer, name, scene):
    # Not bit for bit: float additive blending rounds differently in another order. Each of
    # the n <= 8 terms is off by at most 2^-24 of the sum (numerics.tolerance, twice: both
    # images carry their own rounding).
    meshes = SCENES[scene]()
    frames = [render(renderer, m, name) for m in shuffles(meshes, 4)]
    n = int(frames[0].stats["max_depth_complexity"])
    bound = 2 * tolerance(name, n, mass=n)
    for f in frames[1:]:
        assert np.abs(f.image - frames[0].image).max() <= bound


@pytest.mark.parametrize("name", NAMES)
def test_same_submission_repeats_bit_for_bit(renderer, name):
    # Whatever the method, the same scene renders to the same bits frame after frame (the
    # blends keep submission order; stochastic is seeded).
    for scene in ("layers-equal", "triangles-near"):
        meshes = SCENES[scene]()
        frames = [render(renderer, meshes, name) for _ in range(3)]
        assert all(np.array_equal(frames[0].image, f.image) for f in frames[1:]), scene


@pytest.mark.parametrize("name", [n for n in EXACT[1:] if n not in SUBMISSION_TIES])
def test_exact_methods_agree_on_coplanar_triangles(renderer, name):
    # Every exact method resolves equal depths by the same tie rule, so they agree with the
    # first (abuffer) to float32 rounding on overlapping coplanar triangles (n <= 8 layers).
    meshes = SCENES["triangles-equal"]()
    a, b = render(renderer, meshes, EXACT[0]).image, render(renderer, meshes, name).image
    assert np.abs(a - b).max() <= 2 * tolerance(name, 8)


def _deep_tied_stacks():
    """Two stacks side by side in one frame, so that the sorted resolve's runs hold more than
    one block (its keys are then sorted by depth and link, and equal depths put in the tie rule's
    order afterwards): on the left seven layers (six tied), within one block of eight, on the
    right 22 (twelve tied, at two depths). The left half's pixels are the ones a frame with
    only them would sort by the whole order at once."""
    rng = np.random.default_rng(3)
    colors = [(*rng.uniform(0, 1, 3), a) for a in rng.uniform(0.1, 0.6, 16)]
    left = [(0.5, c) for c in colors[:6]] + [(0.3, colors[6])]
    right = [(0.5, c) for c in colors[6:12]] + [(0.7, c) for c in colors[10:16]]
    right += [(0.05 + 0.04 * i, colors[i]) for i in range(10)]
    return left, right


def _half(z, rgba, x):
    positions, indices = geometry.quad((x, 0.0, z), 1.0)
    return MeshData(positions, indices, np.tile(np.asarray(rgba, dtype=np.float32), (4, 1)))


@pytest.mark.parametrize("name", [n for n in EXACT if n not in SUBMISSION_TIES])
def test_ties_in_runs_longer_than_one_block(renderer, name):
    # The exact methods' runs past eight entries sort by depth and link and then order equal
    # depths by the tie rule; a frame whose runs are long sorts even a shallow pixel that way.
    left, right = _deep_tied_stacks()
    meshes = [_half(z, c, -0.5) for z, c in left] + [_half(z, c, 0.5) for z, c in right]
    frames = [render(renderer, m, name) for m in shuffles(meshes, 6)]
    first = frames[0]
    assert first.stats["max_depth_complexity"] == len(right)
    for i, f in enumerate(frames[1:], 1):
        assert np.array_equal(f.image, first.image), f"shuffle {i}"
    for stack, (row, col) in ((left, (8, 4)), (right, (8, 12))):
        z, rgb, a = layer_arrays(stack)
        want = expected(name, z, rgb, a, BG, **params_for(name))
        assert np.abs(first.image[row, col] - want).max() <= tolerance(name, len(stack)), (name, row, col)
