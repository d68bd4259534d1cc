"""The method registry is the one place a method's facts live (docs/methods.md, "Adding a
method"): what `oit.methods()` reports must be what the renderer does. Memory formulas equal
the bytes each method allocates, declared error bounds are the ones frames carry, declared
antialias modes are the ones accepted, and declared features decide what an adapter runs."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from scenes import IDENTITY, build_scene, random_meshes

INFO = {m["name"]: m for m in oit.methods()}
SIZE = (24, 16)
# Non-default parameters too, so that a formula's parameter is really used.
VARIANTS = {"hybrid": [{"k": 3}], "ktab": [{"k": 5}], "hybrid64": [{"k": 2}], "stochastic": [{"samples": 3}],
            "bucket_peeling": [{"buckets": 5}]}


def scene():
    return build_scene(random_meshes(3, transparent=6, opaque=1, triangles=4, space="ndc"))


def runs():
    for name in INFO:
        for params in [{}, *VARIANTS.get(name, [])]:
            yield pytest.param(name, params, id=f"{name}-{params}" if params else name)


@pytest.mark.parametrize("name,params", list(runs()))
def test_memory_formula_is_what_the_method_allocates(renderer, name, params):
    if name not in renderer(1, 1).adapter_info["methods"]:
        pytest.skip(f"the adapter lacks {INFO[name]['features']}, which {name} needs")
    frame = renderer(*SIZE).render(scene(), IDENTITY, name, **params)
    formula = oit.memory_bytes(name, *SIZE, **params)
    kind = INFO[name]["memory"]["kind"]
    if kind == "frame":
        assert formula == frame.stats["memory_bytes"], INFO[name]["memory"]["formula"]
        assert INFO[name]["bounded_memory"]
    elif kind == "scene":
        assert formula is None and not INFO[name]["bounded_memory"]
    else:  # auto: the slots it chose decide, when it rendered hybrid
        assert kind == "slots" and formula is None
        extra = frame.stats["extra"]
        # mboit's targets count where it was tried (1: missed, 2: kept), with the estimate's words.
        moments = oit.memory_bytes("mboit", *SIZE, moments=4) if extra["auto_moments"] else 0
        if extra["auto_moments"] == 2:
            assert frame.stats["memory_bytes"] == moments + SIZE[0] * SIZE[1] * 20
        elif extra["auto_exact"] == 0:
            slots = int(extra["auto_slots"])
            assert oit.memory_bytes(name, *SIZE, slots=slots, **params) + moments == frame.stats["memory_bytes"]


@pytest.mark.parametrize("name", list(INFO))
def test_declared_error_bound_is_what_frames_carry(renderer, name):
    if name not in renderer(1, 1).adapter_info["methods"]:
        pytest.skip(f"the adapter lacks {INFO[name]['features']}, which {name} needs")
    info = INFO[name]
    assert info["error_bound"] in ("exact", "per_pixel", "none")
    assert (info["error_bound"] == "exact") == info["exact"]
    frame = renderer(*SIZE).render(scene(), IDENTITY, name)
    assert (frame.error_bound is not None) == (info["error_bound"] == "per_pixel")
    if frame.error_bound is None:
        assert frame.error_bound_reason.startswith("exact method" if info["exact"] else "no per-pixel bound")


@pytest.mark.parametrize("name", list(INFO))
def test_declared_antialias_modes_are_the_accepted_ones(renderer, name):
    if name not in renderer(1, 1).adapter_info["methods"]:
        pytest.skip(f"the adapter lacks {INFO[name]['features']}, which {name} needs")
    modes = INFO[name]["antialias_modes"]
    assert "frames" in modes and set(modes) <= {"frames", "coverage"}
    samples = oit.constants()["COVERAGE_SAMPLES"]
    r = renderer(8, 8)
    if "coverage" in modes:
        assert r.render(scene(), IDENTITY, name, antialias=samples, antialias_mode="coverage").stats["antialias_mode"] == "coverage"
    else:
        with pytest.raises(ValueError, match="antialias_mode 'coverage' is implemented by"):
            r.render(scene(), IDENTITY, name, antialias=samples, antialias_mode="coverage")


def test_the_adapter_runs_exactly_the_methods_whose_features_it_has(renderer):
    info = renderer(1, 1).adapter_info
    assert info["methods"] == [m["name"] for m in oit.methods() if set(m["features"]) <= set(info["features"])]
    for m in oit.methods():
        assert m["order"] in ("bitwise", "bitwise_except_ties", "rounding", "submission")
        assert m["order_independent"] == (m["order"] in ("bitwise", "bitwise_except_ties"))


def test_memory_bytes_refuses_what_it_cannot_answer():
    with pytest.raises(ValueError, match=r"unknown method 'hybird'.*did you mean 'hybrid'"):
        oit.memory_bytes("hybird", 4, 4)
    with pytest.raises(ValueError, match="k = 99 is out of range"):
        oit.memory_bytes("hybrid", 4, 4, k=99)
    with pytest.raises(ValueError, match="no per-pixel slots"):
        oit.memory_bytes("hybrid", 4, 4, slots=3)
    with pytest.raises(TypeError, match="width must be an int"):
        oit.memory_bytes("hybrid", 4.0, 4)
    words = sum(oit.constants()[w] for w in ("HYBRID_ACCUM_WORDS", "HYBRID_TAIL_WORDS", "HYBRID_CORE_WORDS"))
    assert oit.memory_bytes("hybrid", 10, 10, k=4) == 100 * (2 * 4 + words) * 4 + 8
    assert oit.memory_bytes("abuffer", 10, 10) is None


def test_shared_constants_are_the_models():
    # python/oit/models.py takes these from the core, not from copies.
    from oit import models

    c = oit.constants()
    assert c["DEPTH_MAX"] == models.DEPTH_MAX and c["ALPHA_8BIT_ERROR"] == models.ALPHA_8BIT_ERROR
    assert np.float32(c["ALPHA_8BIT_BIAS"]) == models.ALPHA_8BIT_BIAS
    assert c["ALPHA_8BIT_ERROR"] == (0.5 + 2.0 ** -10) / 255.0


@pytest.mark.parametrize("name", ["abuffer", "hybrid", "wboit"])
def test_stats_have_the_documented_keys(renderer, name):
    # oit.Stats documents every key; method-specific figures are under "extra" only.
    frame = renderer(*SIZE).render(scene(), IDENTITY, name)
    documented = set(oit.Stats.__annotations__)
    keys = set(frame.stats)
    assert keys <= documented and documented - keys <= {"error_bound_max"}, keys ^ documented
    assert all(isinstance(v, float) for v in frame.stats["extra"].values())


def test_the_main_parameter_is_an_int_parameter_of_its_method():
    """`main` (what `oit compare` sweeps) names an int parameter; every method with an int
    parameter besides its seed has one."""
    for m in oit.methods():
        ints = [p["name"] for p in m["params"] if p["type"] == "int" and p["name"] != "seed"]
        assert m["main"] == (ints[0] if ints else None), m["name"]
