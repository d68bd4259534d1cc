"""Order and frame stability (docs/methods.md, "Guarantees: order and frame stability"): every
exact method, hybrid, hybrid64, ktab and auto (and bucket_peeling and screen_door, away from
exact depth ties) render the same bits whatever the order of meshes and triangles, and the
same bits frame after frame, also after other scenes have grown or shrunk the renderer's
buffers in between.

Two scenes: random overlapping triangles with per-vertex colors and opaque occluders under a
perspective camera, and the built-in smoke, thinned. Neither has two fragments at exactly
equal depth: the peeling methods break such ties by submission, their documented rule,
tested in test_numerics_coplanar.py."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from oit import scenes as scene_lib
from scenes import PERSPECTIVE, MeshData, build_scene, random_meshes

SIZE = (48, 48)
BACKGROUND = (0.3, 0.5, 0.7)
# The methods the registry declares bit-identical under reordering (`order_independent`):
# every exact method, the k-TAB family, auto, and bucket_peeling and screen_door, which keep
# each pixel's (or bucket's) nearest fragment and order exact ties by submission.
STABLE = [m["name"] for m in oit.methods() if m["order_independent"]]
METHODS = {m["name"] for m in oit.methods()}
# The k-TAB methods at their default k and at a k that sends most fragments to the tail; auto
# at its default tolerance (the exact fallback, after hybrids, on these scenes) and at one
# that a hybrid meets on the random scene.
VARIANTS = {"hybrid": [{"k": 8}, {"k": 3}], "hybrid64": [{"k": 8}, {"k": 3}], "ktab": [{"k": 8}, {"k": 3}],
            "auto": [{}, {"tolerance": 0.1}]}
RUNS = [(name, params) for name in STABLE if name in METHODS for params in VARIANTS.get(name, [{}])]


def random_scene(seed: int, transparent: int) -> tuple[list[MeshData], oit.Camera]:
    return random_meshes(seed, transparent=transparent, opaque=2, triangles=6, space="world", spread=1.0), PERSPECTIVE


def smoke(particles: int) -> tuple[list[MeshData], oit.Camera]:
    """The built-in smoke as triangle fans, thinned: soft billboards whose rims have alpha 0
    (test_primitives.py reorders particle sets)."""
    built = scene_lib.smoke(particles=particles, primitive="fans")
    return [MeshData(m.positions, m.indices, m.colors, m.opaque) for m in built.meshes], built.camera


# (scene, a deeper one, a shallower one): the two others run in between to resize the buffers.
SCENES = {
    "random": (lambda: random_scene(11, 20), lambda: random_scene(12, 40), lambda: random_scene(13, 2)),
    "smoke": (lambda: smoke(150), lambda: smoke(400), lambda: smoke(10)),
}


def orders(meshes: list[MeshData], seed: int = 0):
    """The same meshes submitted otherwise: (what changed, meshes)."""
    rng = np.random.default_rng(seed)
    yield "mesh order", [meshes[i] for i in rng.permutation(len(meshes))]
    yield "triangle and vertex order", [m.shuffled(rng) for m in meshes]
    yield "both", [meshes[i].shuffled(rng) for i in rng.permutation(len(meshes))]
    yield "reversed, triangles shuffled", [m.shuffled(rng) for m in meshes[::-1]]


def differences(a: oit.Frame, b: oit.Frame) -> str:
    """'' when the frames are bit-identical (image, depth complexity and error bound), else
    what differs, with the first differing pixel."""
    if not np.array_equal(a.depth_complexity, b.depth_complexity):
        return "depth complexity differs"
    if (a.error_bound is None) != (b.error_bound is None) or (
            a.error_bound is not None and not np.array_equal(a.error_bound, b.error_bound)):
        return "error bound differs"
    diff = np.argwhere((a.image != b.image).any(-1))
    if len(diff):
        p = tuple(diff[0])
        return f"{len(diff)} pixels differ, first {p}: {a.image[p]} vs {b.image[p]} (max {np.abs(a.image - b.image).max():.3g})"
    return ""


@pytest.mark.parametrize("scene", list(SCENES))
@pytest.mark.parametrize("name,params", [pytest.param(n, p, id=f"{n}-{p}" if p else n) for n, p in RUNS])
def test_bit_identical_under_reordering_and_across_frames(renderer, name, params, scene):
    r = renderer(*SIZE)
    build, deeper, shallower = SCENES[scene]
    meshes, camera = build()
    render = lambda ms: r.render(build_scene(ms), camera, name, background=BACKGROUND, **params, census=True)  # noqa: E731
    try:
        first = render(meshes)
    except RuntimeError as e:
        if "lacks SHADER_INT64" in str(e):
            pytest.skip(str(e))
        raise
    # Enough overlap for order to matter, and past k: hybrid's tail is in play.
    assert first.stats["max_depth_complexity"] >= 12
    for what, submitted in orders(meshes):
        assert differences(render(submitted), first) == "", f"{name} {params}, {what}"
    # Across frames: the same scene again, then after a deeper scene (more fragments, larger
    # pools) and a shallower one (pools may shrink), twice.
    same = build_scene(meshes)
    assert differences(r.render(same, camera, name, background=BACKGROUND, **params, census=True), first) == "", "repeated"
    for other in (deeper, shallower):
        ms, cam = other()
        r.render(build_scene(ms), cam, name, background=BACKGROUND, **params)
    for i in range(2):
        frame = r.render(same, camera, name, background=BACKGROUND, **params, census=True)
        assert differences(frame, first) == "", f"{name} {params}, frame {i + 1} after other scenes"
