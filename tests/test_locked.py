"""adaptive and mlab as the seeds design them (docs/methods.md, "Critical sections"): a fixed
number of entries a pixel, updated by each fragment inside its pixel's critical section. Their
memory is the formula's whatever the fragments; on lavapipe no fragment waits for or gives up on
a lock, and the update runs in submission order, so they give what the list versions
(adaptive_lists, mlab_lists) replay from captured lists: mlab bit for bit, adaptive within the
rounding of its blended sum."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from numerics import BG, stacks, tolerance
from oit import scenes as scene_lib

LOCKED = {"adaptive": "nodes", "mlab": "layers"}
SIZE = (48, 40)


def hair():
    return scene_lib.hair(strands=300)


@pytest.fixture(scope="module")
def scenes():
    return {"hair": hair(), "smoke": scene_lib.smoke(), "stacks": None}


def frames(renderer, built, name, n, **kw):
    r = renderer(*SIZE)
    param = LOCKED[name]
    locked = r.render(built.scene, built.camera, name, **{param: n}, **kw)
    lists = r.render(built.scene, built.camera, f"{name}_lists", **{param: n}, **kw)
    return locked, lists


@pytest.mark.parametrize("n", [1, 4, 32])
@pytest.mark.parametrize("name", list(LOCKED))
@pytest.mark.parametrize("scene", ["hair", "smoke"])
def test_locked_equals_the_list_version(renderer, scenes, scene, name, n):
    built = scenes[scene]
    locked, lists = frames(renderer, built, name, n)
    assert locked.stats["extra"]["lock_failures"] == locked.stats["extra"]["lock_waits"] == 0
    assert locked.stats["overflow_fragments"] == 0
    if name == "mlab":
        # The same float32 update in the same order, composited by the same loop.
        assert np.array_equal(locked.image, lists.image)
    else:
        # The same visibility function; the shading pass blends C alpha vis(z) in submission
        # order where the list version sums in list order: (d + 1) 2^-24 for d fragments a pixel.
        d = int(lists.stats["max_depth_complexity"])
        assert np.abs(locked.image - lists.image).max() <= 2 * (d + 1) * 2.0 ** -24


@pytest.mark.parametrize("name", list(LOCKED))
def test_memory_is_the_formula_whatever_the_fragments(renderer, scenes, name):
    param = LOCKED[name]
    r = renderer(*SIZE)
    mem = {s: r.render(scenes[s].scene, scenes[s].camera, name, **{param: 8}).stats["memory_bytes"] for s in ("hair", "smoke")}
    # Each list version on a renderer of its own: pools shrink lazily.
    lists = {s: oit.Renderer(*SIZE).render(scenes[s].scene, scenes[s].camera, f"{name}_lists", **{param: 8}).stats["memory_bytes"]
             for s in ("hair", "smoke")}
    assert mem["hair"] == mem["smoke"] == oit.memory_bytes(name, *SIZE, **{param: 8})
    assert lists["hair"] != lists["smoke"]  # the lists grow with the fragments
    per_entry = {"adaptive": 8, "mlab": 20}[name]
    targets = 16 if name == "adaptive" else 0
    assert mem["hair"] == SIZE[0] * SIZE[1] * (per_entry * 8 + 4 + targets) + 8


@pytest.mark.parametrize("name", list(LOCKED))
def test_every_pixel_matches_the_model(renderer, name):
    # 24 layers a pixel in shuffled depth order, so that every pixel merges entries.
    built = stacks(8, 6, 24, seed=5)
    param = LOCKED[name]
    for n in (2, 8):
        frame = renderer(8, 6).render(built.scene, oit.Camera(np.eye(4)), name, background=tuple(BG), **{param: n})
        want = built.expect(name, **{param: n})
        assert np.abs(frame.image - want).max() <= tolerance(name, 24), n


@pytest.mark.parametrize("name", list(LOCKED))
def test_tiles_under_a_budget_give_the_untiled_frame(renderer, scenes, name):
    built = scenes["hair"]
    param = LOCKED[name]
    whole = renderer(*SIZE).render(built.scene, built.camera, name, **{param: 8})
    budget = whole.stats["target_bytes"] + whole.stats["memory_bytes"] // 3
    tiled = oit.Renderer(*SIZE, memory_budget=budget).render(built.scene, built.camera, name, **{param: 8})
    assert tiled.stats["tiles"] > 1 and tiled.stats["peak_memory_bytes"] <= budget
    assert np.array_equal(tiled.image, whole.image)


def test_lock_counts_are_in_the_stats_schema():
    rules = dict(oit._oit.extra_merge_rules())
    assert rules["lock_failures"] == rules["lock_waits"] == "sum"
