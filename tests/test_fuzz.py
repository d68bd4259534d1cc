"""Fuzzing with hypothesis (derandomized, bounded: CI sees the same examples every run).

Random small valid scenes never crash, every method returns a finite image of the right shape,
and abuffer matches the float64 reference away from edges and depth ties. Random bad input
(dtypes, shapes, NaN/Inf, out-of-range indices and colors, bad sizes, parameters and
cameras) raises TypeError, ValueError or MemoryError with a message that names the argument.
Sizes that could exhaust memory run in a subprocess, so that a crash cannot take pytest down.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import oit
from numerics import BG, EXACT, INFO, NAMES, tolerance
from scenes import IDENTITY

FUZZ = settings(max_examples=40, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
# Sizes the numerics tests use too: renderers (and their compiled pipelines) are reused.
SIZES = [(1, 1), (4, 4), (7, 3), (8, 8)]

# ---- valid scenes

coord = st.floats(-1.25, 1.25, width=32)  # partly off screen: clipped triangles
depth = st.floats(-0.125, 1.125, width=32)  # partly past the near and far planes
unit = st.floats(0.0, 1.0, width=32)
alpha = st.one_of(st.sampled_from([0.0, 1.0, 1e-4, 1 - 1e-6]), unit)


@st.composite
def meshes(draw):
    """0-4 meshes of 0-4 triangles; each triangle its own three vertices and one color (so
    that only coverage and compositing are under test, not color interpolation)."""
    out = []
    for _ in range(draw(st.integers(0, 4))):
        n = draw(st.integers(0, 4))
        pos = np.array([[draw(coord), draw(coord), draw(depth)] for _ in range(3 * n)], np.float32).reshape(-1, 3)
        opaque = draw(st.booleans()) and draw(st.booleans())  # one mesh in four
        cols = [(draw(unit), draw(unit), draw(unit), 1.0 if opaque else draw(alpha)) for _ in range(n)]
        colors = np.repeat(np.array(cols, np.float32).reshape(-1, 4), 3, axis=0)
        out.append((pos, np.arange(3 * n).reshape(-1, 3), colors, opaque))
    return out


@st.composite
def method_params(draw):
    """A method and valid parameters. Integer parameters are compile-time constants of the
    shaders (each new value builds pipelines, ~30 ms on lavapipe): three values each."""
    name = draw(st.sampled_from(NAMES))
    params = {}
    for p in INFO[name]["params"]:
        if p["type"] == "int":
            params[p["name"]] = draw(st.sampled_from(sorted({p["min"], p["default"], min(p["max"], p["min"] + p["step"])})))
        elif p["type"] == "float":
            params[p["name"]] = draw(st.floats(p["min"], p["max"]))
        else:
            params[p["name"]] = draw(st.sampled_from(p["choices"]))
    return name, params


@FUZZ
@given(ms=meshes(), size=st.sampled_from(SIZES), mp=method_params())
def test_random_valid_scenes(renderer, ms, size, mp):
    scene = oit.Scene()
    for pos, idx, col, opaque in ms:
        scene.add_mesh(pos, idx, col, opaque=opaque)
    r = renderer(*size)
    name, params = mp
    frame = r.render(scene, IDENTITY, name, background=tuple(BG), **params, census=True)
    w, h = size
    assert frame.image.shape == (h, w, 4) and np.isfinite(frame.image).all()
    assert frame.depth_complexity.shape == (h, w)
    assert frame.stats["fragments"] == int(frame.depth_complexity.sum())
    exact = r.render(scene, IDENTITY, EXACT[0], background=tuple(BG))
    ref, ambiguous = oit.reference(scene, IDENTITY, w, h, background=tuple(BG), return_mask=True)
    n = int(exact.stats["max_depth_complexity"])
    # Compositing bound (numerics.tolerance) plus one rounding a fragment where the clipper
    # re-interpolates a constant color: twice the bound.
    err = np.abs(exact.image - ref)[~ambiguous]
    assert err.max(initial=0.0) <= 2 * tolerance(EXACT[0], n), (err.max(), n)
    assert (exact.image[..., 3] >= 0).all() and (exact.image[..., 3] <= 1).all()


def test_reference_flags_centers_a_snapped_vertex_can_cover(renderer):
    # Found by the fuzzer (not derandomized): pixel (row 4, col 3) of 16 x 9 has its center at
    # (-0.5625, 0), on the line of the edge y = 0 and 0.00036 px beyond the vertex at
    # x = -0.5624099. The rasterizer snaps that vertex to 1/256 px, onto the center, and covers
    # it; the reference did not, and did not flag it either: its BVH pruned the triangle (boxes
    # padded by 1e-5 of their extent), so the 0.01 px edge test never ran.
    scene = oit.Scene()
    scene.add_mesh(np.float32([[0, 0, 0.5], [-0.5624099, 0, 0.5], [0, -1, 0.5]]), [[0, 1, 2]], (0.0, 0.0, 0.0, 1.0))
    frame = renderer(16, 9).render(scene, IDENTITY, EXACT[0], background=tuple(BG))
    ref, ambiguous = oit.reference(scene, IDENTITY, 16, 9, background=tuple(BG), return_mask=True)
    assert frame.depth_complexity[4, 3] == 1  # what the rasterizer does
    assert ambiguous[4, 3] or ref[4, 3, 3] == 1.0


# ---- bad input: each case is (call, exception types, words the message must contain)

P = np.float32([[0.0, 0.0, 0.5], [1.0, 0.0, 0.5], [0.0, 1.0, 0.5]])
I3 = np.array([[0, 1, 2]])
C4 = (1.0, 0.0, 0.0, 0.5)
index = st.integers(0, 2)


@st.composite
def bad_add_mesh(draw):
    """add_mesh arguments with one of them broken; returns (args, error, argument name)."""
    pos, idx, col = P.copy(), I3.copy(), np.tile(np.float32(C4), (3, 1))
    which = draw(st.sampled_from(["positions", "indices", "colors"]))
    how = draw(st.sampled_from(["dtype", "shape", "value"]))
    if which == "positions":
        if how == "dtype":
            bad = draw(st.sampled_from([P.astype(str), P.astype(bool), P.astype(complex), P.astype(object)]))
            return (bad, idx, col), TypeError, which
        if how == "shape":
            bad = draw(st.sampled_from([P[:, :2], np.zeros((3, 4)), P.ravel(), P[:, :, None]]))
            return (bad, idx, col), ValueError, which
        bad = pos.astype(np.float64)
        bad[draw(index), draw(index)] = draw(st.sampled_from([np.nan, np.inf, -np.inf, 1e39, -1e300]))
        return (bad, idx, col), ValueError, which
    if which == "indices":
        if how == "dtype":
            bad = draw(st.sampled_from([I3.astype(np.float32), I3.astype(bool), I3.astype(str)]))
            return (pos, bad, col), TypeError, which
        if how == "shape":
            bad = draw(st.sampled_from([I3[:, :2], I3.ravel()[:, None], I3[None], np.arange(4)[None]]))
            return (pos, bad, col), ValueError, which
        bad = I3.astype(np.int64)
        bad[0, draw(index)] = draw(st.one_of(st.integers(-2 ** 63, -1), st.integers(3, 2 ** 63 - 1)))
        return (pos, bad, col), ValueError, which
    if how == "dtype":
        return (pos, idx, draw(st.sampled_from(["red", np.array(["1", "0", "0", "1"]), None]))), TypeError, which
    if how == "shape":
        # (Not (1, 4): one row is one RGBA for the whole mesh, like (4,).)
        return (pos, idx, draw(st.sampled_from([(1.0, 0.0, 0.0), np.full((2, 4), 0.5), np.full((3, 3), 0.5),
                                                  np.full((3, 4, 1), 0.5)]))), ValueError, which
    bad = col.astype(np.float64)
    bad[draw(index), draw(st.integers(0, 3))] = draw(st.one_of(
        st.floats(1.0, 1e30, exclude_min=True), st.floats(-1e30, 0.0, exclude_max=True),
        st.sampled_from([np.nan, np.inf, -np.inf])))
    return (pos, idx, bad), ValueError, which


@FUZZ
@given(case=bad_add_mesh())
def test_bad_meshes_raise_naming_the_argument(case):
    args, error, name = case
    scene = oit.Scene()
    with pytest.raises(error) as info:
        scene.add_mesh(*args)
    assert name in str(info.value)
    assert scene.mesh_count == 0


big = st.integers(2 ** 31, 2 ** 80)


@FUZZ
@given(which=st.sampled_from(["width", "height"]),
       value=st.one_of(st.integers(-2 ** 80, 0), big, st.floats(allow_nan=True),
                       st.sampled_from(["8", None, True, 8.0])))
def test_bad_renderer_sizes(which, value):
    args = {"width": 4, "height": 4, which: value}
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value > 0:
        # Past every adapter's largest texture: MemoryError naming the largest side.
        with pytest.raises(MemoryError, match=r"largest texture .* at most \d+ pixels a side"):
            oit.Renderer(**args)
        return
    with pytest.raises((TypeError, ValueError)) as info:
        oit.Renderer(**args)
    assert which in str(info.value)


@FUZZ
@given(which=st.sampled_from(["width", "height"]),
       value=st.one_of(st.integers(-2 ** 80, 0), st.integers(65537, 2 ** 80), st.floats(allow_nan=True),
                       st.sampled_from(["8", None, True])))
def test_bad_reference_sizes(which, value):
    args = {"width": 4, "height": 4, which: value}
    with pytest.raises((TypeError, ValueError)) as info:
        oit.reference(oit.Scene(), IDENTITY, **args)
    assert which in str(info.value) or "width and height" in str(info.value)


def test_reference_too_large_for_memory_raises_in_a_subprocess():
    # A frame the machine cannot hold (37 bytes a pixel) raised a Rust allocation abort
    # before python/oit checked it; run it in a child so that a regression cannot kill pytest.
    code = textwrap.dedent("""
        import numpy as np, oit
        for w, h in [(65536, 65536), (65536, 65535), (40000, 40000)]:
            try:
                oit.reference(oit.Scene(), oit.Camera(np.eye(4)), w, h)
                print("returned", w, h)
            except MemoryError as e:
                assert f"{w} x {h}" in str(e), str(e)
                print("MemoryError")
    """)
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr[-2000:]
    assert p.stdout.split() == ["MemoryError"] * 3, p.stdout


@st.composite
def bad_params(draw):
    """(method, params, words the message must contain)."""
    kind = draw(st.sampled_from(["method", "unknown", "range", "type"]))
    if kind == "method":
        name = draw(st.text(min_size=0, max_size=12).filter(lambda s: s not in NAMES))
        return name, {}, ["unknown method"]
    with_params = [(n, p) for n in NAMES for p in INFO[n]["params"]]
    name, p = draw(st.sampled_from(with_params))
    if kind == "unknown":
        extra = draw(st.text("abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=8).filter(
            lambda s: s not in {q["name"] for q in INFO[name]["params"]}))
        return name, {extra: 1}, [extra]
    if kind == "range" and p["type"] == "int":
        value = draw(st.one_of(st.integers(-2 ** 62, p["min"] - 1), st.integers(p["max"] + 1, 2 ** 62), st.just(10 ** 6)
                               if p["max"] < 10 ** 6 else st.just(p["min"] - 1)))
        return name, {p["name"]: value}, [p["name"]]
    if kind == "range" and p["type"] == "choice":
        value = draw(st.text(max_size=6).filter(lambda s: s not in p["choices"]))
        return name, {p["name"]: value}, [p["name"]]
    value = draw(st.sampled_from([None, [1], (2,), {"a": 1}, b"4", True, 2 ** 70, float("nan"), 1.5, complex(1, 1)]))
    return name, {p["name"]: value}, [p["name"]]


@FUZZ
@given(case=bad_params())
def test_bad_methods_and_parameters(renderer, case):
    name, params, words = case
    scene = oit.Scene()
    scene.add_mesh(P, I3, C4)
    with pytest.raises((TypeError, ValueError)) as info:
        renderer(4, 4).render(scene, IDENTITY, name, **params)
    assert all(w in str(info.value) for w in words), str(info.value)


INT_PARAMS = [(n, p) for n in NAMES for p in INFO[n]["params"] if p["type"] == "int"]


@pytest.mark.parametrize("name,param", INT_PARAMS, ids=[f"{n}-{p['name']}" for n, p in INT_PARAMS])
def test_integer_parameters_out_of_range(renderer, name, param):
    # The cases the issue names (k = 0, k = 10^6) for every integer parameter, whatever the
    # fuzzer draws: a ValueError naming the parameter and its range.
    scene = oit.Scene()
    scene.add_mesh(P, I3, C4)
    lo, hi = param["min"], param["max"]
    for value in sorted(v for v in {0, 10 ** 6, -1, lo - 1, hi + 1} if not lo <= v <= hi):
        with pytest.raises(ValueError, match=rf"{param['name']} = {value} is out of range; use {param['min']} <= "):
            renderer(4, 4).render(scene, IDENTITY, name, **{param["name"]: value})


finite = st.floats(-10, 10, allow_nan=False)


@st.composite
def bad_matrix(draw):
    kind = draw(st.sampled_from(["shape", "nonfinite", "singular", "huge", "kind"]))
    if kind == "shape":
        shape = draw(st.sampled_from([(3, 3), (4,), (16,), (4, 3), (2, 4, 4), (0, 4), ()]))
        return np.ones(shape), ValueError
    m = np.eye(4) + np.array([[draw(finite) for _ in range(4)] for _ in range(4)]) * 0.1
    if kind == "nonfinite":
        m[draw(st.integers(0, 3)), draw(st.integers(0, 3))] = draw(st.sampled_from([np.nan, np.inf, -np.inf]))
    elif kind == "singular":  # a zero column, or a row a power-of-two multiple of another: det exactly 0
        r, o = draw(st.lists(st.integers(0, 3), min_size=2, max_size=2, unique=True))
        if draw(st.booleans()):
            m[r] = m[o] * draw(st.sampled_from([0.0, 0.5, 1.0, -2.0, 4.0]))
        else:
            m[:, r] = 0.0
    elif kind == "huge":
        m[draw(st.integers(0, 3)), draw(st.integers(0, 3))] = draw(st.floats(1e39, 1e300))
    else:
        return draw(st.sampled_from(["eye", {"a": 1}, [[1, "x"]] * 2, m.astype(complex)])), TypeError
    return m, ValueError


@FUZZ
@given(case=bad_matrix())
def test_bad_camera_matrices(case):
    m, error = case
    with pytest.raises(error) as info:
        oit.Camera(m)
    assert "view_proj" in str(info.value)


@FUZZ
@given(bg=st.one_of(st.lists(st.floats(allow_nan=True), min_size=0, max_size=5),
                    st.tuples(st.floats(1.0, 1e30, exclude_min=True), unit, unit),
                    st.sampled_from(["white", None, 1.0, {"r": 1}])))
def test_bad_backgrounds(renderer, bg):
    values = np.asarray(bg, dtype=object).ravel() if isinstance(bg, (list, tuple)) else None
    if values is not None and len(values) == 3 and all(isinstance(v, float) and 0 <= v <= 1 for v in values):
        return  # drew a valid background
    with pytest.raises(ValueError, match="background"):
        renderer(4, 4).render(oit.Scene(), IDENTITY, NAMES[0], background=bg)


@FUZZ
@given(mesh=st.one_of(st.integers(-2 ** 80, 2 ** 80), st.sampled_from([None, "0", 0.0, True])),
       alpha_=st.one_of(st.floats(allow_nan=True), st.sampled_from([None, "0.5", True])))
def test_bad_set_mesh_alpha(mesh, alpha_):
    scene = oit.Scene()
    scene.add_mesh(P, I3, C4)
    ok_mesh = isinstance(mesh, int) and not isinstance(mesh, bool) and mesh == 0
    ok_alpha = isinstance(alpha_, float) and 0.0 <= alpha_ <= 1.0
    if ok_mesh and ok_alpha:
        scene.set_mesh_alpha(mesh, alpha_)
        return
    with pytest.raises((TypeError, ValueError)) as info:
        scene.set_mesh_alpha(mesh, alpha_)
    named = [w for w, ok in (("mesh", ok_mesh), ("alpha", ok_alpha)) if not ok]
    assert any(w in str(info.value) for w in named), (named, str(info.value))
