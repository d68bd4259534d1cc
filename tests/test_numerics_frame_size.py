"""Frame sizes: 1 x 1, odd and thin sizes (every method against its model per pixel, the exact
ones against the reference), and sizes past the adapter's limits: a frame wider or taller
than the largest texture, or whose per-pixel buffers pass the storage-binding limit, must
raise MemoryError saying what fits (never a validation error, a crash or a black image).
`Renderer(..., max_binding_bytes=N)` lowers the binding limit so that small frames can test
it."""

from __future__ import annotations

import re

import numpy as np
import pytest

import oit
from numerics import (
    BG,
    EXACT,
    INFO,
    NAMES,
    assert_within_error_bound,
    expected_overflow,
    full_screen_layers,
    params_for,
    render_or_limit,
    stacks,
    tolerance,
)
from oit import constants
from scenes import IDENTITY, build_scene, random_meshes

SIZES = [(1, 1), (7, 3), (3, 7), (33, 17), (64, 1), (1, 64)]
LAYERS = 5
# Small bounded structures, so that hybrid/ktab/adaptive overflow on every pixel (mlab keeps
# 4 layers by default). Not `layers`: it caps the peeling methods, which are exact only
# when they peel every layer.
SMALL = dict(k=2, nodes=2)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("name", NAMES)
def test_odd_sizes_match_the_model_per_pixel(renderer, name, size):
    w, h = size
    s = stacks(w, h, LAYERS, seed=w * 100 + h)
    params = params_for(name, **SMALL)
    frame = render_or_limit(renderer(w, h), s.scene, name, background=tuple(BG), **params)
    assert frame.image.shape == (h, w, 4) and frame.depth_complexity.shape == (h, w)
    assert (frame.depth_complexity == LAYERS).all()
    assert_within_error_bound(frame, s.expect(EXACT[0]))
    want = s.expect(name, **params)
    err = np.abs(frame.image - want).max(-1)
    worst = np.unravel_index(np.argmax(err), err.shape)
    mass = max(a.sum() for a in s.alpha)
    assert err.max() <= tolerance(name, LAYERS, mass, **params), (worst, frame.image[worst], want[worst])
    overflow = [expected_overflow(name, z, a, **params) for z, a in zip(s.z, s.alpha)]
    if None not in overflow:
        assert frame.stats["overflow_fragments"] == sum(overflow)


@pytest.mark.parametrize("size", [(1, 1), (7, 3), (33, 17)], ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("name", EXACT)
def test_odd_sizes_match_the_reference(renderer, name, size):
    # Random triangles over the frame (per-vertex colors): the exact methods against the
    # float64 reference away from edges and depth ties, as tests/test_abuffer_reference.py
    # (its 1e-5 comes from float32 compositing of <= 30 layers and color interpolation).
    w, h = size
    scene = build_scene(random_meshes(w + h, transparent=8, opaque=2, triangles=5, spread=0.9))
    frame = renderer(w, h).render(scene, IDENTITY, name, background=tuple(BG))
    ref, ambiguous = oit.reference(scene, IDENTITY, w, h, background=tuple(BG), return_mask=True)
    assert np.abs(frame.image - ref)[~ambiguous].max(initial=0.0) <= 1e-5


# ---- past the adapter's limits


def largest_texture():
    with pytest.raises(MemoryError) as info:
        oit.Renderer(1 << 20, 1)
    m = re.search(r"render at most (\d+) pixels a side", str(info.value))
    assert m, str(info.value)
    return int(m.group(1))


def test_frames_past_the_largest_texture_raise_memory_error_naming_it(renderer):
    top = largest_texture()
    for w, h in [(top + 1, 1), (1, top + 1), (2 ** 32, 1), (1, 2 ** 40), (2 ** 70, 2 ** 70)]:
        with pytest.raises(MemoryError, match=rf"{w} x {h} passes .* at most {top} pixels a side"):
            oit.Renderer(w, h)
    # The size the message names works: a frame `top` pixels wide, one layer on every pixel.
    frame = oit.Renderer(top, 1).render(full_screen_layers([(0.5, (1.0, 0.0, 0.0, 0.5))]), IDENTITY, "abuffer",
                                        background=(0.0, 0.0, 0.0))
    assert frame.image.shape == (1, top, 4)
    assert np.array_equal(frame.image, np.broadcast_to(np.float32([0.5, 0.0, 0.0, 0.5]), (1, top, 4)))


def binding_limit(renderer):
    return int(renderer(1, 1).adapter_info["max_storage_binding_bytes"])


@pytest.fixture(scope="module")
def past_binding(renderer):
    """A renderer whose frame passes the binding limit at 36 bytes a pixel (1931 x 1931 on
    lavapipe), or None; module-scoped so that its ~160 MB of targets go with the module."""
    size = pixels_past(binding_limit(renderer), 36, largest_texture())
    yield None if size is None else oit.Renderer(*size)


def pixels_past(limit, bytes_per_pixel, top):
    """A square-ish frame whose per-pixel buffer of `bytes_per_pixel` passes `limit`, or None
    when that needs a side past the largest texture."""
    side = int(np.ceil(np.sqrt(limit / bytes_per_pixel + 1)))
    return (side, side) if side <= top else None


# Methods that keep per-pixel storage buffers (docs/methods.md, memory column): heads and
# sweep state (the list methods), the k-TAB and accumulators (hybrid, ktab), keys and
# accumulators (the peeling methods). The blends use textures, limited by their size only.
PER_PIXEL_STORAGE = sorted({"abuffer", "pall", "compact_abuffer", "sbuffer", "hybrid", "ktab", "hybrid64",
                            "depth_peeling", "dual_depth_peeling", "bucket_peeling"} & set(NAMES))
TINY_TRIANGLE = np.float32([[0.9, 0.9, 0.5], [0.99, 0.9, 0.5], [0.9, 0.99, 0.5]])


def at_most(message):
    """(pixels, side) from a message that says 'at most N pixels (e.g. S x S)'."""
    m = re.search(r"at most (\d+) pixels \(e\.g\. (\d+) x \2\)", message)
    assert m, message
    return int(m.group(1)), int(m.group(2))


@pytest.mark.parametrize("name", sorted({"abuffer", "hybrid", "depth_peeling"} & set(NAMES)))
def test_per_pixel_buffers_past_the_binding_limit_go_in_tiles(past_binding, name):
    # 36 bytes a pixel is the smallest of these methods' largest per-pixel buffers at their
    # defaults (the peeling accumulators; abuffer's sweep state is 48, hybrid's accumulators
    # 64): a frame past limit / 36 pixels overflows one buffer of each, so it goes in tiles
    # (docs/methods.md, "Tiles"), each within the binding. (They once raised a wgpu validation
    # error from create_bind_group, then a MemoryError naming the largest frame that fits.)
    if past_binding is None:
        pytest.skip("the adapter's binding limit cannot be passed within its largest texture")
    r = past_binding
    scene = oit.Scene()
    scene.add_mesh(TINY_TRIANGLE, [[0, 1, 2]], (1, 0, 0, 0.5))
    frame = r.render(scene, IDENTITY, name, background=(0.0, 0.0, 0.0), census=True)
    assert frame.stats["tiles"] > 1 and frame.stats["fragments"] > 0
    # One layer: every method gives the over-blended triangle (hybrid up to its 8-bit alpha).
    want = r.render(scene, IDENTITY, "unsorted", background=(0.0, 0.0, 0.0)).image
    assert np.abs(frame.image - want).max() <= (2.5 / 255 if name == "hybrid" else 1e-6)


def test_shared_buffers_past_the_binding_limit_raise_memory_error(renderer):
    # The census counts (4 B/pixel) of every frame: past limit / 4 pixels no method can run.
    # (Such a renderer once raised wgpu validation errors on every render.)
    limit = binding_limit(renderer)
    size = pixels_past(limit, 4, largest_texture())
    if size is None:
        pytest.skip("the adapter's binding limit cannot be passed within its largest texture")
    with pytest.raises(MemoryError) as info:
        oit.Renderer(*size).render(oit.Scene(), IDENTITY, NAMES[0])
    pixels, side = at_most(str(info.value))
    assert pixels == limit // 4 and side == int(np.sqrt(pixels)), str(info.value)


@pytest.mark.parametrize("name", sorted({"hybrid", "ktab"} & set(NAMES)))
def test_hybrid_past_the_binding_limit_goes_in_tiles_that_fit(renderer, name):
    # W x H x 4 (2k + accumulator and tail words) bytes in one frame would pass one binding with k = 32
    # (the k-TAB alone does): the frame goes in tiles whose buffers each fit.
    limit, top = binding_limit(renderer), largest_texture()
    k = 32
    per_pixel = 4 * (2 * k + sum(constants()[w] for w in ("HYBRID_ACCUM_WORDS", "HYBRID_TAIL_WORDS", "HYBRID_CORE_WORDS")))
    side = int(np.sqrt(limit // (4 * k)))
    if side + 1 > top:
        pytest.skip("the binding limit cannot be passed within the largest texture")
    frame = oit.Renderer(side, side + 1).render(oit.Scene(), IDENTITY, name, k=k, background=(0.5, 0.5, 0.5))
    assert frame.stats["tiles"] >= int(np.ceil(side * (side + 1) * per_pixel / limit))
    assert frame.stats["memory_bytes"] <= limit + 4
    assert (frame.image == np.float32([0.5, 0.5, 0.5, 0.0])).all()


@pytest.mark.parametrize("name", PER_PIXEL_STORAGE)
def test_per_pixel_buffers_honour_max_binding_bytes(renderer, name):
    # With 4096-byte bindings a 64 x 64 frame's 4 B/pixel buffers (16 KiB) do not fit: the
    # method renders in tiles whose buffers do, with the image of the whole frame (methods once
    # sized these buffers by the adapter's limit, ignoring max_binding_bytes).
    r = renderer(64, 64, max_binding_bytes=4096)
    scene = oit.Scene()
    scene.add_mesh(TINY_TRIANGLE, [[0, 1, 2]], (1, 0, 0, 0.5))
    tiled = r.render(scene, IDENTITY, name)
    assert tiled.stats["tiles"] > 1
    assert np.array_equal(tiled.image, renderer(64, 64).render(scene, IDENTITY, name).image)


# Methods that capture fragments into a node pool (unbounded memory and a capture pass).
NODE_POOL = [n for n in NAMES if not INFO[n]["bounded_memory"] and any("capture" in p for p in INFO[n]["passes"])]


@pytest.mark.parametrize("name", NODE_POOL)
def test_node_pools_honour_max_binding_bytes(renderer, name):
    # The pool is split over four bindings; 1024-byte bindings hold at most 340 nodes (12-byte
    # nodes; fewer of bigger ones), and 4 x 4 pixels x 24 layers = 384 fragments do not fit in
    # one: the frame goes in tiles with the image of the whole frame. A pixel of 400 layers fits
    # no pool: a MemoryError that names it.
    r = renderer(4, 4, max_binding_bytes=1024)
    scene = full_screen_layers([(z, (1.0, 0.0, 0.0, 0.5)) for z in np.linspace(0.1, 0.9, 24)])
    tiled = r.render(scene, IDENTITY, name, **params_for(name))
    assert tiled.stats["tiles"] > 1
    assert np.array_equal(tiled.image, renderer(4, 4).render(scene, IDENTITY, name, **params_for(name)).image)
    deep = full_screen_layers([(z, (1.0, 0.0, 0.0, 0.5)) for z in np.linspace(0.1, 0.9, 400)])
    with pytest.raises(MemoryError, match=r"pixel \(0, 0\) has 400 transparent fragments, more than one tile can hold"):
        r.render(deep, IDENTITY, name, **params_for(name))
