"""`unsorted` and `sorted` against abuffer: equal where over-blending in their order is
right, different (and where expected) where it is not."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from oit import geometry
from scenes import IDENTITY, MeshData, build_scene, layer

# Separate quads at NDC depths 0.2 .. 0.9 with straight RGBA, one mesh each; one has alpha
# exactly 1 and one exactly 0.
LAYERS = [
    (0.2, (0.9, 0.1, 0.1, 0.4)),
    (0.3, (0.1, 0.9, 0.2, 0.0)),
    (0.45, (0.2, 0.3, 0.9, 0.6)),
    (0.6, (0.8, 0.8, 0.1, 0.25)),
    (0.75, (0.5, 0.2, 0.7, 1.0)),
    (0.9, (0.1, 0.7, 0.7, 0.5)),
]
BG = (0.3, 0.3, 0.3)


def ndc_layers(order):
    """Full-screen quads in `order` (indices into LAYERS), and an opaque quad on the left
    half at z=0.5 that hides the layers behind it there."""
    positions, indices = geometry.quad((-0.5, 0.0, 0.5), (1.0, 2.0))
    wall = MeshData(positions, indices, np.tile(np.float32([0.6, 0.5, 0.4, 1.0]), (4, 1)), opaque=True)
    return build_scene([wall] + [layer(*LAYERS[i]) for i in order])


def world_layers(order):
    """The same layers as world-space quads under a perspective camera (3 to 8 units away)."""
    scene = oit.Scene()
    for i in order:
        z, rgba = LAYERS[i]
        positions, indices = geometry.quad((0.0, 0.0, -10.0 * z + 1.0), 12.0)
        scene.add_mesh(positions, indices, rgba)
    return scene


PERSPECTIVE = oit.Camera.look_at(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), fov_y=50.0, near=0.5, far=20.0)
BACK_TO_FRONT = [5, 4, 3, 2, 1, 0]
FRONT_TO_BACK = BACK_TO_FRONT[::-1]


@pytest.mark.parametrize("kind", ["ndc", "world"])
def test_unsorted_equals_abuffer_back_to_front(renderer, kind):
    build, camera = (ndc_layers, IDENTITY) if kind == "ndc" else (world_layers, PERSPECTIVE)
    r = renderer(16, 16)
    exact = r.render(build(BACK_TO_FRONT), camera, method="abuffer", background=BG).image
    blended = r.render(build(BACK_TO_FRONT), camera, method="unsorted", background=BG).image
    # Blending back to front and compositing front to back round differently: a few ulps.
    assert np.abs(blended - exact).max() <= 1e-6


@pytest.mark.parametrize("kind", ["ndc", "world"])
def test_unsorted_differs_front_to_back(renderer, kind):
    build, camera = (ndc_layers, IDENTITY) if kind == "ndc" else (world_layers, PERSPECTIVE)
    r = renderer(16, 16)
    exact = r.render(build(FRONT_TO_BACK), camera, method="abuffer", background=BG).image
    blended = r.render(build(FRONT_TO_BACK), camera, method="unsorted", background=BG).image
    assert np.abs(blended - exact).max() > 0.05


@pytest.mark.parametrize("kind", ["ndc", "world"])
def test_sorted_equals_abuffer_for_separate_meshes(renderer, kind):
    build, camera = (ndc_layers, IDENTITY) if kind == "ndc" else (world_layers, PERSPECTIVE)
    r = renderer(16, 16)
    rng = np.random.default_rng(1)
    for _ in range(3):
        order = list(rng.permutation(len(LAYERS)))
        exact = r.render(build(order), camera, method="abuffer", background=BG).image
        blended = r.render(build(order), camera, method="sorted", background=BG).image
        assert np.abs(blended - exact).max() <= 1e-6, f"submission order {order}"


def test_sorted_is_wrong_exactly_where_meshes_interpenetrate(renderer):
    # A: full-screen red at z=0.5. B: blue over x, y in [-0.5, 0.5], tilted from z=0.35 on
    # its left edge to 0.75 on its right, so it pierces A at x=-0.125. B's centroid (0.55)
    # is behind A's, so `sorted` draws B first: wrong where B is in front of A, i.e. pixel
    # columns 8-13 of rows 8-23 at 32 x 32 (no pixel center lies on B's edges or on x=-0.125).
    red, blue = (1.0, 0.0, 0.0, 0.5), (0.0, 0.0, 1.0, 0.5)
    b_positions = np.array([[-0.5, -0.5, 0.35], [0.5, -0.5, 0.75], [0.5, 0.5, 0.75], [-0.5, 0.5, 0.35]])
    b = MeshData(b_positions.astype(np.float32), np.array([[0, 1, 2], [0, 2, 3]]), np.tile(np.float32(blue), (4, 1)))
    scene = build_scene([layer(0.5, red), b])
    r = renderer(32, 32)
    exact = r.render(scene, IDENTITY, method="abuffer", background=(0.0, 0.0, 0.0)).image
    blended = r.render(scene, IDENTITY, method="sorted", background=(0.0, 0.0, 0.0)).image
    diff = np.abs(blended - exact).max(axis=-1)
    expected_wrong = np.zeros((32, 32), dtype=bool)
    expected_wrong[8:24, 8:14] = True
    assert diff[expected_wrong].min() > 0.05
    assert diff[~expected_wrong].max() <= 1e-6
    # And abuffer is the right one there: blue over red in front of the crossing.
    np.testing.assert_allclose(exact[8:24, 8:14], np.broadcast_to([0.25, 0.0, 0.5, 0.75], (16, 6, 4)), atol=1e-7)
    np.testing.assert_allclose(exact[8:24, 14:24], np.broadcast_to([0.5, 0.0, 0.25, 0.75], (16, 10, 4)), atol=1e-7)
