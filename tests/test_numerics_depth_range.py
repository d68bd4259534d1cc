"""Depth range extremes: perspective cameras with near/far ratios up to 1e6 (window depth
crowds towards 1 as near/d), and geometry exactly at, just inside and just outside the near
and far planes. The GPU clips to 0 <= z <= w and keeps fragments strictly in front of the
opaque depth, which is cleared to 1, so window depths in [0, 1) are drawn; the reference
composites hits with 0 <= z < 1 along the segment between the planes, flagging hits within
4e-6 of either plane as ambiguous (docs/methods.md, "The reference")."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from numerics import BG, EXACT, NAMES, RANDOMIZED, full_screen_layers, params_for, tolerance
from oit import _oit, models
from oit.models import ALPHA_8BIT_ERROR
from scenes import IDENTITY, MeshData, build_scene

SIZE = 48
FOV = 45.0


def facing_quad(d, half, center=(0.0, 0.0), rgba=(1.0, 0.0, 0.0, 0.5)):
    """A quad facing a camera at the origin looking down -z, at distance d."""
    cx, cy = center
    p = np.array([[cx - half, cy - half, -d], [cx + half, cy - half, -d], [cx + half, cy + half, -d],
                  [cx - half, cy + half, -d]], np.float32)
    return MeshData(p, np.array([[0, 1, 2], [0, 2, 3]]), np.tile(np.float32(rgba), (4, 1)))


def spread_quads(dists, seed=0):
    """Overlapping quads at the given view distances, each a constant color (so that only
    depth, not attribute interpolation, is under test), covering 50-90 % of the view."""
    rng = np.random.default_rng(seed)
    t = np.tan(np.radians(FOV) / 2)
    return [facing_quad(d, d * t * rng.uniform(0.5, 0.9), rng.uniform(-0.4, 0.4, 2) * d * t,
                        (*rng.uniform(0, 1, 3), rng.uniform(0.2, 0.8))) for d in dists]


def look(near, far):
    return oit.Camera.look_at((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), FOV, near, far)


# (near, far, view distances): window depths 1 - z from 0.3 down to 5.7e-6, each pair of
# layers at least 4e-6 apart (the reference's tie distance) and ~95 24-bit key steps.
RANGES = {
    "1e3": (0.1, 100.0, [0.3, 1.0, 3.0, 10.0, 30.0]),
    "1e6-near": (1e-3, 1e3, [0.01, 0.05, 0.3, 2.0, 20.0, 150.0]),
    "1e6-far": (1e-2, 1e4, [0.05, 0.5, 5.0, 50.0, 500.0, 1500.0]),
}


@pytest.mark.parametrize("name", EXACT)
@pytest.mark.parametrize("case", list(RANGES))
def test_wide_depth_range_matches_reference(renderer, case, name):
    near, far, dists = RANGES[case]
    scene, camera = build_scene(spread_quads(dists)), look(near, far)
    frame = renderer(SIZE, SIZE).render(scene, camera, name, background=tuple(BG), census=True)
    ref, ambiguous = oit.reference(scene, camera, SIZE, SIZE, background=tuple(BG), return_mask=True)
    n = int(frame.stats["max_depth_complexity"])
    assert n >= len(dists) - 1 and ambiguous.mean() < 0.1
    err = np.abs(frame.image - ref)[~ambiguous].max()
    # Compositing (numerics.tolerance) plus one rounding a fragment for the interpolated
    # constant color: twice the compositing bound.
    assert err <= 2 * tolerance(name, n), err


@pytest.mark.parametrize("case", list(RANGES))
def test_hybrid_keys_separate_layers_at_wide_depth_ranges(renderer, case):
    # 24-bit depth keys still order layers 5.7e-6 apart in window depth: with k >= the depth
    # complexity hybrid is within the 8-bit alpha bound of abuffer (docs/methods.md).
    near, far, dists = RANGES[case]
    scene, camera = build_scene(spread_quads(dists)), look(near, far)
    r = renderer(SIZE, SIZE)
    exact = r.render(scene, camera, EXACT[0], background=tuple(BG), census=True)
    dc = exact.depth_complexity
    for name in sorted({"hybrid", "ktab"} & set(NAMES)):
        f = r.render(scene, camera, name, background=tuple(BG), k=int(dc.max()))
        assert f.stats["overflow_fragments"] == 0
        bound = (dc * (dc + 1) / 2 + dc) * ALPHA_8BIT_ERROR + tolerance(name, int(dc.max()))
        assert (np.abs(f.image - exact.image).max(-1) <= bound).all(), name


# ---- geometry exactly at the planes (identity camera: window depth = z)

MID = (0.5, (0.0, 1.0, 0.0, 0.5))


def planes_scene(z, opaque=False):
    return full_screen_layers([(z, (1.0, 0.0, 0.0, 1.0 if opaque else 0.5)), MID], opaque=[0] if opaque else [])


@pytest.mark.parametrize("name", NAMES)
def test_geometry_at_the_near_plane_is_drawn(renderer, name):
    # z = 0 is inside both the GPU's clip volume and the reference's segment.
    r = renderer(8, 8)
    frame = r.render(planes_scene(0.0), IDENTITY, name, background=tuple(BG), **params_for(name), census=True)
    assert (frame.depth_complexity == 2).all()
    if name in EXACT:
        ref, ambiguous = oit.reference(planes_scene(0.0), IDENTITY, 8, 8, background=tuple(BG), return_mask=True)
        assert ambiguous.all()  # documented: a hit within 4e-6 of a plane
        assert np.abs(frame.image - ref).max() <= tolerance(name, 2)


PAST_FAR = float(np.nextafter(np.float32(1), np.float32(2)))


@pytest.mark.parametrize("z", [-1e-7, PAST_FAR], ids=["before-near", "past-far"])
@pytest.mark.parametrize("name", NAMES)
def test_geometry_just_outside_the_planes_is_clipped(renderer, name, z):
    scene = planes_scene(z)
    frame = renderer(8, 8).render(scene, IDENTITY, name, background=tuple(BG), **params_for(name), census=True)
    assert (frame.depth_complexity == 1).all()
    if name in EXACT:
        # Clipped by the reference too; no plane tie to excuse (only the quads' diagonal is
        # flagged, and the top-left rule draws it once on both sides): every pixel compares.
        ref = oit.reference(scene, IDENTITY, 8, 8, background=tuple(BG))
        assert np.abs(frame.image - ref).max() <= tolerance(name, 1)


@pytest.mark.parametrize("opaque", [False, True], ids=["transparent", "opaque"])
@pytest.mark.parametrize("name", NAMES)
def test_geometry_at_the_far_plane_is_clipped_as_in_the_reference(renderer, name, opaque):
    # Window depth exactly 1: the GPU's depth test rejects it against the cleared 1.0, and the
    # reference takes depths in [0, 1) to match (it once composited z = 1).
    scene = planes_scene(1.0, opaque)
    frame = renderer(8, 8).render(scene, IDENTITY, name, background=tuple(BG), **params_for(name), census=True)
    assert (frame.depth_complexity == 1).all()
    if name not in RANDOMIZED:  # (whose noise follows triangle indices)
        alone = renderer(8, 8).render(full_screen_layers([MID]), IDENTITY, name, background=tuple(BG),
                                      **params_for(name))
        assert np.array_equal(frame.image, alone.image)  # as if the layer at z = 1 were not there
    if name in EXACT:
        ref = oit.reference(scene, IDENTITY, 8, 8, background=tuple(BG))
        assert np.abs(frame.image - ref).max() <= tolerance(name, 1), (frame.image[0, 0], ref[0, 0])


@pytest.mark.parametrize("plane", ["near", "far"])
@pytest.mark.parametrize("ratio", [1e3, 1e6])
def test_perspective_geometry_on_a_plane_is_in_or_out_never_garbage(renderer, ratio, plane):
    # A quad at exactly the near (or far) distance lands on window depth 0 (or 1) up to
    # float32 rounding: each pixel may keep or clip it (the reference flags a hit within 4e-6
    # of a plane), but the result must be one of the two composites, and the reference's
    # wherever it does not flag the pixel.
    near = 1e-3
    far = near * ratio
    d = near if plane == "near" else far
    t = np.tan(np.radians(FOV) / 2)
    mid = (near * far) ** 0.5
    scene = build_scene([facing_quad(d, 1.5 * d * t, rgba=(1.0, 0.0, 0.0, 0.5)),
                         facing_quad(mid, 1.5 * mid * t, rgba=MID[1])])
    camera = look(near, far)
    ref, ambiguous = oit.reference(scene, camera, 16, 16, background=tuple(BG), return_mask=True)
    z = [0.0, 0.5] if plane == "near" else [0.5, 1.0]  # the plane's layer in front or behind
    with_it = models.exact(z, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [0.5, 0.5], BG)
    without = models.exact([0.5], [[0.0, 1.0, 0.0]], [0.5], BG)
    for name in EXACT:
        f = renderer(16, 16).render(scene, camera, name, background=tuple(BG), census=True)
        assert set(np.unique(f.depth_complexity)) <= {1, 2}
        want = np.where((f.depth_complexity == 2)[..., None], with_it, without)
        assert np.abs(f.image - want).max() <= tolerance(name, 2), name
        assert np.abs(f.image - ref)[~ambiguous].max(initial=0.0) <= tolerance(name, 2), name


def test_reference_counts_a_shared_edge_once():
    # A quad at view distance 500 under near = 1e-3, far = 1e3 has its shared diagonal through
    # pixel centers; the reference once counted 2 hits on some and 0 on others (its edge
    # distances were not antisymmetric in float64). The GPU counts 1 everywhere.
    t = np.tan(np.radians(FOV) / 2)
    scene = build_scene([facing_quad(500.0, 1.5 * 500.0 * t)])
    _, _, dc = _oit.reference(scene._native, look(1e-3, 1e3).view_proj, 16, 16, tuple(BG))
    assert (dc == 1).all(), np.unique(dc, return_counts=True)
