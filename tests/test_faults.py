"""Faults and resources: adapter selection (adapter= and OIT_ADAPTER), running out of GPU
memory, errors that must leave the renderer usable, the GIL released during GPU work
(threads sharing one renderer or using two), and 1,000 renders that must not grow the
process's memory.

Not testable on lavapipe: an adapter lacking a feature a method needs (lavapipe has all the
optional features the engine asks for, and wgpu cannot remove one from an adapter), and a
lost device. The features are reported in adapter_info; the methods check them up front.
"""

from __future__ import annotations

import itertools
import json
import os
import subprocess
import sys
import textwrap
import threading

import numpy as np
import pytest

import oit
from numerics import BG, BOUNDED, INFO, NAMES, full_screen_layers, params_for, stacks
from scenes import IDENTITY, PERSPECTIVE, build_scene, random_meshes

# ---- adapters


def test_unknown_adapter_lists_the_available_ones(renderer):
    name = renderer(1, 1).adapter_info["name"]
    with pytest.raises(RuntimeError) as info:
        oit.Renderer(2, 2, adapter="no-such-gpu")
    message = str(info.value)
    assert "no adapter name contains 'no-such-gpu'; available: " in message
    assert name in message


def test_adapter_is_chosen_by_a_case_insensitive_substring(renderer):
    name = renderer(1, 1).adapter_info["name"]
    word = name.split()[0]
    for pick in (word.upper(), word.lower()):
        assert oit.Renderer(2, 2, adapter=pick).adapter_info["name"] == name


def test_oit_adapter_variable(renderer, monkeypatch):
    name = renderer(1, 1).adapter_info["name"]
    monkeypatch.setenv("OIT_ADAPTER", "no-such-gpu")
    with pytest.raises(RuntimeError, match=r"no adapter name contains 'no-such-gpu'; available: .+"):
        oit.Renderer(2, 2)
    monkeypatch.setenv("OIT_ADAPTER", name.split()[0].upper())
    r = oit.Renderer(2, 2)
    assert r.adapter_info["name"] == name
    assert r.render(full_screen_layers([(0.5, (1.0, 0.0, 0.0, 1.0))]), IDENTITY).image[0, 0].tolist() == [1, 0, 0, 1]


def test_adapter_reports_the_features_methods_need(renderer):
    info = renderer(1, 1).adapter_info
    for feature in ("timestamps", "float32_blendable", "int64_atomic_min_max"):
        assert isinstance(info[feature], bool)
    assert info["max_storage_binding_bytes"] >= 256


# ---- out of memory, and errors that must leave the renderer usable

OOM_SCRIPT = textwrap.dedent("""
    import json, numpy as np, oit
    cam = oit.Camera(np.eye(4))
    scene = oit.Scene()
    scene.add_mesh(np.float32([[-1, -1, 0.5], [3, -1, 0.5], [-1, 3, 0.5]]), [[0, 1, 2]], (1.0, 0.0, 0.0, 0.5))
    small = oit.Renderer(8, 8)
    before = small.render(scene, cam, "wsum").image
    out = {}
    big = None
    try:
        # 2 GiB RGBA32F targets: lavapipe could not allocate them and reported out of memory
        # mid-frame, before the renderer checked its census buffer against the binding limit.
        big = oit.Renderer(16384, 8193)
        big.render(scene, cam, "wsum")
        out["first"] = ["ok", ""]
    except Exception as e:
        out["first"] = [type(e).__name__, str(e)]
    if big is not None:
        try:
            big.render(scene, cam, "wsum")
            out["again"] = ["ok", ""]
        except Exception as e:
            out["again"] = [type(e).__name__, str(e)]
    out["small_after"] = bool(np.array_equal(before, small.render(scene, cam, "wsum").image))
    out["new_after"] = bool(np.array_equal(before, oit.Renderer(8, 8).render(scene, cam, "wsum").image))
    print(json.dumps(out))
""")


@pytest.fixture(scope="module")
def too_big():
    """Runs OOM_SCRIPT in a child process: should the up-front checks regress, the frame
    allocates ~0.6 GB and fails mid-frame, which must not take pytest with it."""
    p = subprocess.run([sys.executable, "-c", OOM_SCRIPT], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr[-3000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


def test_a_frame_too_big_for_the_device_is_a_memory_error(too_big):
    # A MemoryError that says what to do (at most N pixels, or smaller frames when the GPU
    # itself ran out), and other renderers keep working.
    kind, message = too_big["first"]
    assert kind == "MemoryError", message
    assert "at most" in message or "smaller" in message, message
    assert too_big["small_after"] and too_big["new_after"]


def test_a_renderer_too_big_for_the_device_says_so_again(too_big):
    # Once, the second render of that renderer raised a wgpu validation error about an invalid
    # texture view; it must repeat the MemoryError (or say to recreate the renderer).
    kind, message = too_big.get("again", too_big["first"])
    assert kind == "MemoryError" or "Renderer" in message, (kind, message)
    assert message == too_big["first"][1] or "Renderer" in message


# Methods that capture fragments into a node pool (unbounded memory and a capture pass).
NODE_POOL = [n for n in NAMES if n not in BOUNDED and any("capture" in p for p in INFO[n]["passes"])]


@pytest.mark.parametrize("name", NODE_POOL)
def test_renderer_is_usable_after_a_memory_error(renderer, name):
    # 1024-byte bindings: a pixel of 400 layers fits no node pool, whatever the tiles, 1 layer
    # does (test_numerics_frame_size.py checks the numbers).
    r = renderer(4, 4, max_binding_bytes=1024)
    deep = full_screen_layers([(z, (1.0, 0.0, 0.0, 0.5)) for z in np.linspace(0.1, 0.9, 400)])
    with pytest.raises(MemoryError):
        r.render(deep, IDENTITY, name, **params_for(name))
    shallow = full_screen_layers([(0.5, (0.0, 1.0, 0.0, 0.5))])
    got = r.render(shallow, IDENTITY, name, background=tuple(BG), **params_for(name)).image
    want = renderer(4, 4).render(shallow, IDENTITY, name, background=tuple(BG), **params_for(name)).image
    assert np.array_equal(got, want)


def test_renderer_is_usable_after_each_kind_of_error(renderer):
    # A bad parameter (ValueError), a pool past its bindings (MemoryError) and, on llvmpipe, a
    # pixel past adaptive_lists' loop budget (RuntimeError): after each, the renderer renders the
    # same bits as before. (A GPU-side failure once left a method's readback buffer mapped,
    # breaking every later render of that method.)
    ok = full_screen_layers([(0.5, (0.0, 1.0, 0.0, 0.5)), (0.25, (1.0, 0.0, 0.0, 0.5))])
    name = "adaptive_lists"
    limited = renderer(1, 1, max_binding_bytes=1024)  # at most 168 nodes, fewer than 200 fragments
    before = limited.render(ok, IDENTITY, name).image
    with pytest.raises(ValueError, match="no_such_parameter"):
        limited.render(ok, IDENTITY, name, no_such_parameter=1)
    assert np.array_equal(limited.render(ok, IDENTITY, name).image, before)
    with pytest.raises(MemoryError):
        limited.render(stacks(1, 1, 200, seed=1).scene, IDENTITY, name)
    assert np.array_equal(limited.render(ok, IDENTITY, name).image, before)
    r = renderer(1, 1)
    limit = r.adapter_info["loop_limit"]
    if limit is not None and name == "adaptive_lists":
        with pytest.raises(RuntimeError, match=str(limit)):
            r.render(stacks(1, 1, 4000, seed=3).scene, IDENTITY, name)
        assert np.array_equal(r.render(ok, IDENTITY, name).image, before)


# ---- threads


def thread_scenes():
    """(scene, camera, method, params, size) jobs of different kinds."""
    deep = stacks(8, 8, 12, seed=3)
    world = build_scene(random_meshes(1, transparent=8, opaque=2, triangles=5, space="world"))
    ndc = build_scene(random_meshes(2, transparent=6, opaque=1, triangles=4))
    hybrid = ("hybrid", {"k": 4}) if "hybrid" in NAMES else (NAMES[0], {})
    return [
        (world, PERSPECTIVE, NAMES[0], {}, (16, 16)),
        (deep.scene, IDENTITY, *hybrid, (8, 8)),
        (ndc, IDENTITY, "wboit" if "wboit" in NAMES else NAMES[0], {}, (16, 16)),
    ]


def run_threads(jobs, renderer_for, repeats=6):
    """Renders every job `repeats` times, one thread per job; returns {job index: [images]}."""
    results = {i: [] for i in range(len(jobs))}
    errors = []

    def work(i):
        scene, camera, method, params, size = jobs[i]
        try:
            for _ in range(repeats):
                frame = renderer_for(i, size).render(scene, camera, method, background=tuple(BG), **params)
                results[i].append(frame.image)
        except Exception as e:  # reported below: an exception in a thread would pass silently
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(jobs))]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert not any(t.is_alive() for t in threads), "a render thread hangs"
    assert not errors, errors
    return results


def test_threads_sharing_one_renderer_get_correct_images(renderer):
    jobs = [(s, c, m, p, (16, 16)) for s, c, m, p, _ in thread_scenes()]
    shared = renderer(16, 16)
    serial = [shared.render(s, c, m, background=tuple(BG), **p).image for s, c, m, p, _ in jobs]
    results = run_threads(jobs, lambda i, size: shared)
    for i, images in results.items():
        assert all(np.array_equal(im, serial[i]) for im in images), f"job {i}"


def test_threads_with_their_own_renderers_get_correct_images(renderer):
    jobs = thread_scenes()
    own = {i: oit.Renderer(*size) for i, (*_, size) in enumerate(jobs)}
    serial = [renderer(*size).render(s, c, m, background=tuple(BG), **p).image for s, c, m, p, size in jobs]
    results = run_threads(jobs, lambda i, size: own[i])
    for i, images in results.items():
        assert all(np.array_equal(im, serial[i]) for im in images), f"job {i}"


def test_the_gil_is_released_during_gpu_work(renderer):
    """Another Python thread makes progress while a render runs: the worker reads the main
    thread's counter just before the native render and just after it. With a switch interval
    of a second the interpreter does not take the GIL from the worker between the two reads,
    so, were the render to hold it, the counter could not move at all; released, it moves by
    however much the main thread counts during a render (4,000 fragments at each of 16 pixels).
    No clock is read."""
    interval = sys.getswitchinterval()
    deep = stacks(4, 4, 4000, seed=4, alpha=lambda rng, n: rng.uniform(1e-4, 2e-3, n))
    r = renderer(4, 4)
    r.render(deep.scene, IDENTITY, NAMES[0])  # warm: upload and pipelines
    count, seen, failure = [0], [], []
    started, done = threading.Event(), threading.Event()

    def work():
        try:
            started.set()
            before = count[0]
            options = {"background": (1.0, 1.0, 1.0), "antialias": 1, "antialias_mode": "frames", "shading_cost": 0,
                       "census": False}
            r._native.render(deep.scene._native, IDENTITY.view_proj, NAMES[0], {}, options)
            seen.append(count[0] - before)
        except Exception as e:  # reported below
            failure.append(e)
        finally:
            done.set()

    sys.setswitchinterval(1.0)
    try:
        t = threading.Thread(target=work)
        t.start()
        started.wait()
        while not done.is_set():
            count[0] += 1
        t.join()
    finally:
        sys.setswitchinterval(interval)
    assert not failure, failure
    assert seen[0] > 0, "the main thread could not count while the render ran: it holds the GIL"


# ---- memory over 1,000 renders


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_changing_k_does_not_rebuild_pipelines(renderer):
    """Once every k has been rendered, cycling through them builds no pipeline: the device's
    pipeline cache counts what it built."""
    name = "hybrid" if "hybrid" in NAMES else pytest.skip("no hybrid")
    scene = build_scene(random_meshes(1, transparent=4, opaque=1, triangles=3))
    r = renderer(8, 8)
    for k in range(1, 6):
        r.render(scene, IDENTITY, name, k=k)
    built = r.pipelines_built
    assert built > 0
    for i in range(50):
        r.render(scene, IDENTITY, name, k=1 + i % 5)
    assert r.pipelines_built == built, "a frame of a configuration rendered before built a pipeline"
    # A k not rendered before does build its own.
    r.render(scene, IDENTITY, name, k=7)
    assert r.pipelines_built > built


@pytest.mark.skipif(not os.path.exists("/proc/self/statm"), reason="needs /proc/self/statm (Linux)")
def test_a_thousand_renders_do_not_grow_memory(renderer):
    sizes = [(1, 1), (7, 3), (16, 16)]
    scenes = [build_scene(random_meshes(s, transparent=4, opaque=1, triangles=3)) for s in range(3)]
    # Not `auto`: it changes hybrid's k from scene to scene, which rebuilds pipelines (see
    # test_changing_k_does_not_rebuild_pipelines).
    names = [n for n in NAMES if n != "auto"]
    combos = list(itertools.product(sizes, names, range(len(scenes))))
    stats = {}

    def render(i):
        size, name, s = combos[i % len(combos)]
        # Every 7th frame a new Scene (a new upload); the rest reuse three scenes.
        scene = scenes[s] if i % 7 else build_scene(random_meshes(s, transparent=4, opaque=1, triangles=3))
        f = renderer(*size).render(scene, IDENTITY, name, background=tuple(BG), **params_for(name))
        stats.setdefault((size, name, s), []).append(f.stats["memory_bytes"])

    # Warm up: every (size, method, scene) once, then a thousand renders more, so that
    # pipelines, pools and the driver's caches are built: a combination first met with a scene
    # it has seen before is counted in its own capture (no census), and llvmpipe compiles that
    # capture's pipelines then (7-14 MiB of code once, measured). What grows after is a leak.
    for i in range(len(combos) + 1000):
        render(i)
    before = rss_bytes()
    for i in range(len(combos) + 1000, len(combos) + 2000):
        render(i)
    grown = rss_bytes() - before
    # Measured: < 0.5 MiB on lavapipe (whose GPU memory is this process's memory). 4 MiB is
    # what a leak of one small frame's image (4 KiB) per render would cost.
    assert grown <= 4 * 2 ** 20, f"RSS grew by {grown / 2 ** 20:.1f} MiB over 1,000 renders"
    for (size, name, _), mem in stats.items():
        if name in BOUNDED:
            assert len(set(mem)) == 1, (size, name, mem)  # bounded: the same bytes every frame
