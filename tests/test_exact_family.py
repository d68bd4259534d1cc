"""The exact family (issue 4): every method that declares itself exact equals `abuffer` to
float32 rounding and agrees with the float64 reference, on random scenes with opaque
occluders and on pixels with hundreds of layers."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from scenes import IDENTITY, PERSPECTIVE, build_scene, layer, random_meshes

EXACT = [m["name"] for m in oit.methods() if m["exact"] and m["name"] != "abuffer"]


@pytest.mark.parametrize("method", EXACT)
@pytest.mark.parametrize("space", ["ndc", "world"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_exact_methods_equal_abuffer_and_the_reference(renderer, method, space, seed):
    camera = IDENTITY if space == "ndc" else PERSPECTIVE
    scene = build_scene(random_meshes(seed, transparent=10, triangles=6, space=space))
    r = renderer(48, 40)
    exact = r.render(scene, camera, "abuffer", background=(0.2, 0.4, 0.6))
    frame = r.render(scene, camera, method, background=(0.2, 0.4, 0.6))
    # Same fragments, same order, same float32 compositing: at most the rounding of a
    # re-interpolated color (compact_abuffer shades at resolve: measured <= 8e-7).
    assert np.abs(frame.image - exact.image).max() <= 2e-6
    ref, ambiguous = oit.reference(scene, camera, 48, 40, background=(0.2, 0.4, 0.6), return_mask=True)
    # float32 compositing of fewer than 30 layers against float64 (README of the reference).
    assert np.abs(frame.image - ref)[~ambiguous].max() <= 1e-5
    assert frame.stats["overflow_fragments"] == 0


@pytest.mark.parametrize("method", EXACT)
def test_exact_methods_with_hundreds_of_layers(renderer, method):
    rng = np.random.default_rng(3)
    n = 300
    meshes = [layer(float(z), (*rng.uniform(0, 1, 3), float(a)))
              for z, a in zip(rng.permutation(np.linspace(0.01, 0.99, n)), rng.uniform(0.0, 0.05, n))]
    scene = build_scene(meshes)
    r = renderer(4, 4)
    exact = r.render(scene, IDENTITY, "abuffer", background=(1.0, 1.0, 1.0))
    frame = r.render(scene, IDENTITY, method, background=(1.0, 1.0, 1.0))
    assert frame.stats["max_depth_complexity"] == n
    assert np.abs(frame.image - exact.image).max() <= 2e-6


def test_compact_abuffer_saves_memory_when_triangles_cover_many_pixels(renderer):
    # A few large triangles: fragments per triangle far above 176 / 12 = 15, where the compact
    # A-buffer's 12-byte nodes beat 24-byte ones despite 176 bytes of shading data per triangle.
    scene = build_scene([layer(z, (0.5, 0.5, 0.5, 0.3)) for z in (0.2, 0.4, 0.6, 0.8)])
    r = renderer(64, 64)
    full = r.render(scene, IDENTITY, "abuffer").stats
    compact = r.render(scene, IDENTITY, "compact_abuffer").stats
    fragments = full["fragments"]
    # Node pools: 24 vs 12 bytes a fragment; the rest (heads, sweep state) is the same.
    assert full["memory_bytes"] - compact["memory_bytes"] == 12 * fragments - 176 * 8


def test_pall_allocates_a_conservative_bound(renderer):
    scene = build_scene(random_meshes(4, transparent=6, triangles=4))
    frame = renderer(32, 32).render(scene, IDENTITY, "pall")
    assert frame.stats["extra"]["pool_nodes"] >= frame.stats["fragments"]


@pytest.mark.parametrize("method", ["depth_peeling", "dual_depth_peeling"])
def test_peeling_with_a_layer_limit_counts_what_it_left(renderer, method):
    scene = build_scene([layer(z, (0.2 * i, 0.5, 1 - 0.2 * i, 0.4)) for i, z in enumerate((0.1, 0.3, 0.5, 0.7, 0.9))])
    r = renderer(8, 8)
    full = r.render(scene, IDENTITY, method)
    assert full.stats["overflow_fragments"] == 0
    limited = r.render(scene, IDENTITY, method, layers=2)
    # Two layers of five peeled at every pixel (dual peels the nearest and the farthest).
    assert limited.stats["overflow_fragments"] == 3 * 64
    assert limited.stats["extra"]["peeled_fragments"] == 2 * 64
    assert not np.allclose(limited.image, full.image)


def test_peeling_separates_coplanar_fragments(renderer):
    # Three coplanar quads of different colors: a depth-only peel would merge or lose them;
    # the (depth, triangle) key peels them one by one, in submission order.
    meshes = [layer(0.5, (1, 0, 0, 0.5)), layer(0.5, (0, 1, 0, 0.5)), layer(0.5, (0, 0, 1, 0.5))]
    r = renderer(4, 4)
    for method in ("depth_peeling", "dual_depth_peeling"):
        f = r.render(build_scene(meshes), IDENTITY, method, background=(0.0, 0.0, 0.0))
        assert f.stats["overflow_fragments"] == 0
        np.testing.assert_allclose(f.image[0, 0], [0.5, 0.25, 0.125, 0.875], atol=1e-6)


def lit_coplanar_scene(order, normals, depth: float = 0.5) -> oit.Scene:
    """Full-screen quads at one depth, one vertex color, each with its own normal, lit from one
    side (two_sided False): they shade differently although depth and vertex color tie."""
    from oit import geometry

    scene = oit.Scene()
    for i in order:
        pos, idx = geometry.quad((0.0, 0.0, depth), 2.0)
        scene.add_mesh(pos, idx, (0.6, 0.5, 0.4, 0.5), normals=np.tile(np.float32(normals[i]), (len(pos), 1)),
                       shading="smooth", two_sided=False, specular=0.5)
    scene.add_light((0.3, -0.2, -1.0))
    return scene


@pytest.mark.parametrize("method", ["compact_abuffer", "abuffer"])
def test_lit_coplanar_layers_equal_but_for_their_normals_keep_one_order(renderer, method):
    # compact_abuffer sorts before it shades: the tie between equal depth and equal vertex color
    # is broken by the triangles' records, not by submission (nor by a shaded color it does
    # not have), so every submission order gives the same bits.
    normals = [(0.0, 0.0, 1.0), (0.6, 0.0, 0.8), (0.0, 0.6, 0.8), (-0.48, -0.6, 0.64)]
    r = renderer(8, 8)
    images = [r.render(lit_coplanar_scene(p, normals), IDENTITY, method).image
              for p in ([0, 1, 2, 3], [3, 2, 1, 0], [2, 0, 3, 1], [1, 3, 0, 2])]
    for image in images[1:]:
        np.testing.assert_array_equal(image, images[0])
    # The layers do shade differently, so the order matters to the image.
    one = [r.render(lit_coplanar_scene([i], normals), IDENTITY, method).image[0, 0] for i in range(4)]
    assert max(np.abs(a - b).max() for a in one for b in one) > 0.05
