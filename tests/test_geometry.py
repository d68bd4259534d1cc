"""Procedural meshes: closed, consistently wound outwards, no degenerate triangles."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from oit import geometry

CLOSED = {
    "box": lambda: geometry.box((1.0, 2.0, 3.0), (1.0, 2.0, 0.5)),
    "uv_sphere": lambda: geometry.uv_sphere((0.0, 1.0, 0.0), 2.0, rings=8, segments=12),
    "uv_sphere_minimal": lambda: geometry.uv_sphere(rings=2, segments=3),
    "torus": lambda: geometry.torus((0.0, 0.0, 0.0), 1.0, 0.3, 24, 12),
    "torus_tilted": lambda: geometry.torus(axis=(1.0, 1.0, 0.0)),
}


def areas(positions, indices):
    p = positions[indices].astype(np.float64)
    return np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1) / 2


@pytest.mark.parametrize("name", CLOSED)
def test_closed_meshes(name):
    positions, indices = CLOSED[name]()
    assert positions.dtype == np.float32 and positions.shape[1] == 3
    assert indices.dtype == np.uint32 and indices.shape[1] == 3
    assert np.array_equal(np.unique(indices), np.arange(len(positions))), "every vertex used"
    assert areas(positions, indices).min() > 1e-4
    mesh = trimesh.Trimesh(positions, indices, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.volume > 0, "triangles wind counter-clockwise seen from outside"


def test_volumes():
    # Inscribed polygons of n sides lose about (2 pi / n)^2 / 6 of the area: 1.6e-3 for the
    # torus' 64-gon cross-section, 0.4e-3 for its 128-gon ring; less for the sphere.
    box = trimesh.Trimesh(*geometry.box(size=(1.0, 2.0, 3.0)), process=False)
    assert box.volume == pytest.approx(6.0)
    sphere = trimesh.Trimesh(*geometry.uv_sphere(radius=1.0, rings=64, segments=128), process=False)
    assert sphere.volume == pytest.approx(4 / 3 * np.pi, rel=2e-3)
    torus = trimesh.Trimesh(*geometry.torus(major_radius=1.0, minor_radius=0.25, major_segments=128,
                                            minor_segments=64), process=False)
    assert torus.volume == pytest.approx(2 * np.pi**2 * 0.25**2, rel=2.5e-3)


def test_sphere_counts_and_radius():
    positions, indices = geometry.uv_sphere((1.0, 2.0, 3.0), 0.5, rings=6, segments=10)
    assert len(positions) == 2 + 5 * 10 and len(indices) == 2 * 10 * 5
    np.testing.assert_allclose(np.linalg.norm(positions - (1.0, 2.0, 3.0), axis=1), 0.5, rtol=1e-6)


def test_quad_faces_its_normal():
    positions, indices = geometry.quad((0.0, 0.0, 0.5), (2.0, 1.0))
    np.testing.assert_array_equal(positions[:, 2], 0.5)
    assert positions[:, 0].min() == -1.0 and positions[:, 0].max() == 1.0
    assert positions[:, 1].min() == -0.5 and positions[:, 1].max() == 0.5
    p = positions[indices].astype(np.float64)
    normals = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    assert (normals[:, 2] > 0).all() and np.allclose(normals[:, :2], 0)
    side = geometry.quad((0.0, 0.0, 0.0), 1.0, normal=(1.0, 0.0, 0.0), up=(0.0, 0.0, 1.0))[0]
    np.testing.assert_array_equal(side[:, 0], 0.0)


@pytest.mark.parametrize("call,message", [
    (lambda: geometry.uv_sphere(rings=1), "rings must be an integer >= 2"),
    (lambda: geometry.uv_sphere(radius=0.0), "radius must be positive"),
    (lambda: geometry.torus(major_radius=1.0, minor_radius=1.0), "need 0 < minor_radius < major_radius"),
    (lambda: geometry.box(size=(1.0, 0.0, 1.0)), "size must be positive"),
    (lambda: geometry.quad(size=-1.0), "size must be positive"),
    (lambda: geometry.quad(normal=(0.0, 1.0, 0.0)), "up must not be parallel to normal"),
])
def test_bad_arguments(call, message):
    with pytest.raises(ValueError, match=message):
        call()
