"""abuffer does not depend on submission order: not of meshes, not of triangles, not of
coplanar surfaces; and the same frame renders to the same bits every time."""

from __future__ import annotations

import numpy as np
import pytest

from scenes import IDENTITY, PERSPECTIVE, MeshData, build_scene, layer, random_meshes


@pytest.mark.parametrize("space", ["ndc", "world"])
def test_shuffled_meshes_and_triangles_give_identical_bits(renderer, space):
    camera = IDENTITY if space == "ndc" else PERSPECTIVE
    meshes = random_meshes(3, transparent=10, opaque=2, triangles=6, space=space, spread=0.9)
    r = renderer(48, 40)
    first = r.render(build_scene(meshes), camera, background=(0.4, 0.4, 0.4))
    assert first.stats["max_depth_complexity"] >= 5
    rng = np.random.default_rng(0)
    for _ in range(3):
        shuffled = [meshes[i].shuffled(rng) for i in rng.permutation(len(meshes))]
        frame = r.render(build_scene(shuffled), camera, background=(0.4, 0.4, 0.4))
        assert np.array_equal(frame.image, first.image)
        assert np.array_equal(frame.depth_complexity, first.depth_complexity)


def test_all_triangles_in_one_mesh_or_one_mesh_each(renderer):
    # The same triangles as one mesh, and as one mesh a triangle in reverse order.
    meshes = random_meshes(4, transparent=6, opaque=0, triangles=6, space="ndc", spread=0.9)
    positions = np.concatenate([m.positions for m in meshes])
    colors = np.concatenate([m.colors for m in meshes])
    merged = build_scene([MeshData(positions, np.arange(len(positions)).reshape(-1, 3), colors)])
    singles = build_scene([
        MeshData(positions[3 * t:3 * t + 3], np.array([[0, 1, 2]]), colors[3 * t:3 * t + 3])
        for t in reversed(range(len(positions) // 3))
    ])
    r = renderer(32, 32)
    a = r.render(merged, IDENTITY, background=(1.0, 1.0, 1.0))
    b = r.render(singles, IDENTITY, background=(1.0, 1.0, 1.0))
    assert np.array_equal(a.image, b.image)


def over(colors, background):
    """float64 front-to-back compositing of straight RGBA colors in the given order."""
    accum, trans = np.zeros(3), 1.0
    for c in colors:
        accum += trans * c[3] * np.asarray(c[:3], dtype=np.float64)
        trans *= 1.0 - c[3]
    return np.append(accum + trans * np.asarray(background), 1.0 - trans)


def test_coplanar_quads_of_different_colors(renderer):
    # Four full-screen quads at one depth: only the tie rule (by color) orders them.
    colors = [(1, 0, 0, 0.5), (0, 1, 0, 0.5), (0, 0, 1, 0.25), (1, 1, 0, 0.75)]
    r = renderer(16, 16)
    images = []
    for perm in ([0, 1, 2, 3], [3, 2, 1, 0], [2, 0, 3, 1], [1, 3, 0, 2]):
        frame = r.render(build_scene([layer(0.5, colors[i]) for i in perm]), IDENTITY, background=(0.0, 0.0, 0.0))
        images.append(frame.image)
    for image in images[1:]:
        assert np.array_equal(image, images[0])
    # The order is the tie rule's (ascending R, G, B, A), and it matters: the reverse
    # order would give a visibly different color.
    tie_order = over(sorted(colors), (0.0, 0.0, 0.0))
    assert np.abs(images[0] - tie_order).max() <= 1e-7
    assert np.abs(over(sorted(colors)[::-1], (0.0, 0.0, 0.0)) - tie_order).max() > 0.1


def test_same_frame_five_times(renderer):
    meshes = random_meshes(7, transparent=12, opaque=2, triangles=6, space="world", spread=1.0)
    scene = build_scene(meshes)
    r = renderer(48, 48)
    images = [r.render(scene, PERSPECTIVE, background=(0.1, 0.2, 0.3)).image for _ in range(5)]
    assert all(np.array_equal(images[0], im) for im in images[1:])
