"""abuffer is exact: it matches the CPU float64 reference and hand-computed composites."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from oit import geometry
from scenes import IDENTITY, PERSPECTIVE, MeshData, build_scene, composite, layer, random_meshes

# Absolute tolerance against the float64 reference. Compositing n layers in float32 loses
# about n * 2^-24 relative (6e-8 a layer): 30 layers cost ~2e-6, and measured errors on
# these scenes stay below 1.5e-6 (lavapipe). Not a place to loosen: a sorting or coverage
# bug shows up as 1e-2 or more; if this fails, find out which pixel and why.
TOL = 1e-5

CAMERAS = {"ndc": IDENTITY, "world": PERSPECTIVE}


def check_against_reference(renderer, meshes, camera, width, height, background):
    scene = build_scene(meshes)
    frame = renderer(width, height).render(scene, camera, method="abuffer", background=background)
    ref, ambiguous = oit.reference(scene, camera, width, height, background=background, return_mask=True)
    assert ambiguous.mean() < 0.1, "too many ambiguous pixels for a meaningful comparison"
    err = np.abs(frame.image.astype(np.float64) - ref)
    err[ambiguous] = 0.0
    worst = np.unravel_index(np.argmax(err), err.shape)
    assert err.max() <= TOL, (
        f"abuffer differs from the reference by {err.max():.3g} at (row, col, channel) {worst}: "
        f"gpu {frame.image[worst[:2]]}, reference {ref[worst[:2]]}, {frame.depth_complexity[worst[:2]]} layers"
    )
    return frame


@pytest.mark.parametrize("size", [(32, 32), (64, 48)], ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("space", ["ndc", "world"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_scene_matches_reference(renderer, seed, space, size):
    meshes = random_meshes(seed, transparent=8, opaque=2, triangles=5, space=space)
    check_against_reference(renderer, meshes, CAMERAS[space], *size, background=(0.2, 0.5, 0.8))


@pytest.mark.parametrize("space", ["ndc", "world"])
@pytest.mark.parametrize("seed", [10, 11])
def test_dense_random_scene_matches_reference(renderer, seed, space):
    # Large triangles: 15 to 30 layers a pixel, alpha 0 and 1 layers among them.
    meshes = random_meshes(seed, transparent=16, opaque=2, triangles=6, space=space, spread=1.0)
    frame = check_against_reference(renderer, meshes, CAMERAS[space], 48, 48, background=(1.0, 1.0, 1.0))
    assert frame.stats["max_depth_complexity"] >= 15


@pytest.mark.parametrize("seed", [20, 21])
def test_clipped_triangles_match_reference(renderer, seed):
    # Triangles crossing the frame border are clipped by the rasterizer, whose new vertices'
    # colors carry float32 rounding; lavapipe then shifts the interpolated color by up to
    # ~3e-4 pixel times the color gradient (measured on 300 random triangles), i.e. up to
    # ~1.5e-4 for the steepest random triangles here (40 seeds of this scene measured at
    # most 5e-6). Coverage or sorting bugs are >= 1e-2.
    meshes = random_meshes(seed, transparent=10, opaque=2, triangles=5, space="ndc", spread=0.9, on_screen=False)
    scene = build_scene(meshes)
    frame = renderer(32, 32).render(scene, IDENTITY, background=(0.5, 0.5, 0.5))
    ref, ambiguous = oit.reference(scene, IDENTITY, 32, 32, background=(0.5, 0.5, 0.5), return_mask=True)
    err = np.abs(frame.image - ref)[~ambiguous]
    assert err.max() <= 2e-4


def many_layers(n, seed):
    """n full-screen layers at distinct depths in random submission order, faint alphas."""
    rng = np.random.default_rng(seed)
    depths = rng.permutation(np.linspace(0.01, 0.99, n))
    colors = np.column_stack([rng.uniform(0, 1, (n, 3)), rng.uniform(0.001, 0.01, n)]).astype(np.float32)
    return [layer(z, c) for z, c in zip(depths, colors)], composite(list(zip(depths, colors)), (0.3, 0.6, 0.9))


def check_many_layers(renderer, n, seed):
    meshes, expected = many_layers(n, seed)
    frame = renderer(4, 4).render(build_scene(meshes), IDENTITY, background=(0.3, 0.6, 0.9))
    assert frame.stats["fragments"] == 16 * n
    assert frame.stats["max_depth_complexity"] == n
    # The running transmittance is a product of n float32 factors and the color a sum of n
    # float32 terms: each has a first-order relative error bound of n * 2^-24, and every
    # channel is at most 1 (2e-5 for 300 layers; measured 3.5e-7).
    tol = 2 * n * 2.0**-24
    err = np.abs(frame.image - expected).max()
    assert err <= tol, f"{n} layers: off by {err:.3g} (alpha {frame.image[0, 0, 3]}, expected {expected[3]})"
    # Every pixel composites the same list: one value, whatever the allocation order.
    assert (frame.image == frame.image[0, 0]).all()


def test_hundreds_of_layers_in_one_pixel(renderer):
    # 300 layers on a 4 x 4 frame: ten sweeps of the resolve's 32-fragment batches, and a
    # node pool regrown from its first guess (one node a pixel).
    check_many_layers(renderer, 300, seed=5)


@pytest.mark.parametrize("layers", [1000, 4000])
def test_thousands_of_layers_in_one_pixel(renderer, layers):
    # Mesa's llvmpipe (lavapipe) ends every shader invocation's loops after 65535 iterations
    # in all. The resolve sorts a deep list in runs of 32 and merges them, pausing each
    # invocation within that budget and resuming in the next dispatch.
    check_many_layers(renderer, layers, seed=5)


def test_identical_coplanar_layers_each_count_once(renderer):
    # 100 equal fragments a pixel (same depth, same color) straddle the resolve's runs and
    # merges: none may be dropped or counted twice.
    n, alpha = 100, 0.05
    meshes = [layer(0.5, (0.9, 0.2, 0.1, alpha)) for _ in range(n)]
    frame = renderer(4, 4).render(build_scene(meshes), IDENTITY, background=(0.0, 0.0, 1.0))
    trans = (1 - np.float64(np.float32(alpha))) ** n
    expected = np.array([0.9 * (1 - trans), 0.2 * (1 - trans), 0.1 * (1 - trans) + trans, 1 - trans])
    assert np.abs(frame.image - expected).max() <= 2 * n * 2.0**-24


def test_hand_computed_stack(renderer):
    # Front to back: red a=0.5 at z=0.2, green a=0.25 at z=0.5, blue a=0.75 at z=0.8,
    # over the background (0.1, 0.2, 0.3):
    #   R = 0.5                                     = 0.5
    #   G = 0.5 * 0.25                              = 0.125
    #   B = 0.5 * 0.75 * 0.75                       = 0.28125
    #   T = 0.5 * 0.75 * 0.25                       = 0.09375 (background weight)
    #   RGB + T * (0.1, 0.2, 0.3) = (0.509375, 0.14375, 0.309375), A = 1 - T = 0.90625
    stack = [layer(0.8, (0, 0, 1, 0.75)), layer(0.2, (1, 0, 0, 0.5)), layer(0.5, (0, 1, 0, 0.25))]
    expected = np.array([0.509375, 0.14375, 0.309375, 0.90625], dtype=np.float32)
    for order in ([0, 1, 2], [2, 1, 0], [1, 2, 0]):
        frame = renderer(16, 16).render(build_scene([stack[i] for i in order]), IDENTITY, background=(0.1, 0.2, 0.3))
        assert np.abs(frame.image - expected).max() <= 1e-7
        assert (frame.depth_complexity == 3).all()


def test_opaque_surface_hides_what_is_behind(renderer):
    # An opaque quad over the left half (pixel columns 0-7 of 16) at z=0.5, transparent
    # full-screen layers in front (z=0.3) and behind (z=0.7).
    positions, indices = geometry.quad((-0.5, 0.0, 0.5), (1.0, 2.0))
    gray = (0.2, 0.4, 0.6, 1.0)
    wall = MeshData(positions, indices, np.tile(np.float32(gray), (4, 1)), opaque=True)
    front, behind = (1.0, 0.0, 0.0, 0.5), (0.0, 1.0, 0.0, 0.5)
    scene = build_scene([layer(0.7, behind), wall, layer(0.3, front)])
    frame = renderer(16, 16).render(scene, IDENTITY, background=(0.0, 0.0, 0.0))
    left = composite([(0.3, front), (0.5, gray)], (0.0, 0.0, 0.0))
    right = composite([(0.3, front), (0.7, behind)], (0.0, 0.0, 0.0))
    assert left[3] == 1.0
    np.testing.assert_allclose(frame.image[:, :8], np.broadcast_to(left, (16, 8, 4)), rtol=0, atol=1e-7)
    np.testing.assert_allclose(frame.image[:, 8:], np.broadcast_to(right, (16, 8, 4)), rtol=0, atol=1e-7)
    # Fragments behind the opaque surface are not even counted.
    assert (frame.depth_complexity[:, :8] == 1).all() and (frame.depth_complexity[:, 8:] == 2).all()

    # Behind the wall only: nothing changes there, whatever the color.
    only_behind = renderer(16, 16).render(build_scene([wall, layer(0.7, behind)]), IDENTITY, background=(0.0, 0.0, 0.0))
    assert (only_behind.image[:, :8] == np.float32(gray)).all()
    assert (only_behind.depth_complexity[:, :8] == 0).all()


def test_alpha_zero_layers_change_nothing(renderer):
    base = [layer(0.2, (0.9, 0.1, 0.1, 0.4)), layer(0.6, (0.1, 0.1, 0.9, 0.7))]
    clear = [layer(z, (1.0, 1.0, 0.0, 0.0)) for z in (0.1, 0.4, 0.8, 0.6)]
    r = renderer(16, 16)
    without = r.render(build_scene(base), IDENTITY, background=(0.5, 0.5, 0.5))
    with_clear = r.render(build_scene(clear[:2] + base + clear[2:]), IDENTITY, background=(0.5, 0.5, 0.5))
    # a * c = 0 and (1 - a) = 1 exactly: the same float operations on the same values.
    assert np.array_equal(without.image, with_clear.image)
    assert with_clear.stats["fragments"] == without.stats["fragments"] + 4 * 16 * 16


def test_alpha_one_layer_hides_everything_behind(renderer):
    front = layer(0.3, (0.2, 0.8, 0.4, 0.5))
    wall = layer(0.5, (0.7, 0.6, 0.1, 1.0))
    r = renderer(16, 16)
    images = []
    for behind_color in ((1.0, 0.0, 0.0, 0.5), (0.0, 0.0, 1.0, 0.9)):
        scene = build_scene([layer(0.9, behind_color), wall, layer(0.7, behind_color), front])
        images.append(r.render(scene, IDENTITY, background=(0.0, 1.0, 1.0)).image)
    assert np.array_equal(images[0], images[1])
    expected = composite([(0.3, front.colors[0]), (0.5, wall.colors[0])], (0.0, 1.0, 1.0))
    assert expected[3] == 1.0
    assert np.abs(images[0] - expected).max() <= 1e-7
