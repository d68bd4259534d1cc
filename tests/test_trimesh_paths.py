"""Scene.from_trimesh beyond triangle meshes: a PointCloud is a particle set, a Path3D a strand
set (in their colors, placed by a Scene's nodes), and a Scene's camera is kept."""

from __future__ import annotations

import numpy as np
import pytest

import oit

trimesh = pytest.importorskip("trimesh")
from trimesh.path.entities import Line  # noqa: E402


def test_a_point_cloud_is_particles_in_its_colors(renderer):
    rng = np.random.default_rng(2)
    colors = np.tile([255, 0, 0, 128], (30, 1)).astype(np.uint8)
    cloud = trimesh.PointCloud(rng.uniform(-0.5, 0.5, (30, 3)), colors=colors)
    scene = oit.Scene.from_trimesh(cloud, point_radius=0.05)
    assert scene.primitives() == ["particles"]
    material = scene.materials[0]
    assert material["color_mean"][0] == pytest.approx(1.0) and material["alpha_max"] == pytest.approx(128 / 255, abs=1e-6)
    camera = oit.Camera.look_at(eye=(0, 0, 3), target=(0, 0, 0), near=1.0, far=5.0)
    frame = renderer(32, 32).render(scene, camera, "abuffer", background=(0.0, 0.0, 0.0))
    exact = oit.reference(scene, camera, 32, 32, (0.0, 0.0, 0.0))
    assert (frame.image[..., 0] > 0.1).sum() > 20 and np.abs(frame.image[..., 1:3]).max() < 1e-6
    assert np.abs(frame.image[..., :3] - exact[..., :3]).max() < 1e-4


def test_a_path_is_strands_one_per_entity_placed_by_the_scene():
    path = trimesh.path.Path3D(entities=[Line([0, 1, 2]), Line([3, 4])],
                               vertices=np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 0, 1], [0, 1, 1]], float),
                               colors=np.array([[255, 0, 0, 255], [0, 255, 0, 255]], np.uint8))
    alone = oit.Scene.from_trimesh(path)
    assert alone.primitives() == ["strands"]
    triangles = alone.to_triangles(0, oit.Camera.look_at(eye=(3, 2, 4), target=(0.5, 0.5, 0.5)))
    assert len(triangles["indices"]) == 2 * 3  # a ribbon of two triangles a segment, three segments
    scene = trimesh.Scene()
    scene.add_geometry(path, transform=trimesh.transformations.translation_matrix((10.0, 0.0, 0.0)))
    placed = oit.Scene.from_trimesh(scene, line_width=0.1)
    lo, hi = placed.bounds
    assert lo[0] >= 9.9 and hi[0] <= 11.1


def test_a_scene_brings_its_camera():
    scene = trimesh.Scene(trimesh.creation.box())
    assert oit.Scene.from_trimesh(scene).cameras == []
    scene.set_camera(angles=(0.0, 0.0, 0.0), distance=4.0, fov=(60.0, 45.0))
    loaded = oit.Scene.from_trimesh(scene)
    assert len(loaded.cameras) == 1
    cam = loaded.cameras[0]
    assert cam.projection["yfov"] == pytest.approx(np.radians(45.0))
    # The box's center lands in the middle of the picture.
    clip = cam.camera().view_proj @ np.array([*scene.centroid, 1.0])
    assert np.abs(clip[:2] / clip[3]).max() < 1e-6 and 0 < clip[2] / clip[3] < 1
