"""Built-in scenes: each builds without files, renders with the exact A-buffer, and has the
property it promises (layers at the worst pixel, soft or mixed alphas, `sorted` failing on
glass). Frames are 64 x 64: the depth complexities below hold there (the maximum over fewer
pixels is a little lower than at 512 x 512)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import oit
from oit import geometry, scenes

SIZE = 64


@pytest.fixture(scope="module")
def frames(renderer):
    """scene name -> (BuiltScene, abuffer frame) at SIZE; dragons with the built-in stand-in."""
    r = renderer(SIZE, SIZE)
    out = {}
    for name in scenes.SHOWCASE:
        built = scenes.dragons(path=None) if name == "dragons" else scenes.SCENES[name]()
        out[name] = (built, r.render(built.scene, built.camera, "abuffer"))
    return out


def max_depth(frames, name):
    return frames[name][1].stats["max_depth_complexity"]


@pytest.mark.parametrize("name", scenes.SHOWCASE)
def test_scene_renders_and_its_arrays_are_the_scene(frames, name):
    built, frame = frames[name]
    assert frame.image.shape == (SIZE, SIZE, 4) and np.isfinite(frame.image).all()
    assert frame.stats["fragments"] > 0
    # The meshes as arrays are exactly what the scene holds (strand and particle sets as the
    # triangles drawn of them under the camera): uploaded once each, drawn once per instance.
    drawn = [p.triangles(built.camera) for m in built.meshes for p in m.placed()]
    assert sum(len(m.indices) for m in drawn) == built.scene.triangle_count == built.meta["triangles"]
    assert sum(len(m.triangles(built.camera).indices) for m in built.meshes) == built.scene.unique_triangle_count
    assert built.scene.mesh_count == len(built.meshes)
    assert built.scene.instance_count == len(built.drawn_meshes())
    for m in built.drawn_meshes():
        assert m.colors.shape == (len(m.positions), 4) and m.colors.min() >= 0 and m.colors.max() <= 1
        assert m.indices.max() < len(m.positions)


def test_scenes_are_seeded():
    a, b, c = scenes.foliage(seed=1), scenes.foliage(seed=1), scenes.foliage(seed=2)
    np.testing.assert_array_equal(a.meshes[1].positions, b.meshes[1].positions)
    assert not np.array_equal(a.meshes[1].positions, c.meshes[1].positions)


def test_hair_has_hundreds_of_layers(frames):
    assert max_depth(frames, "hair") >= 200


def test_smoke_is_many_soft_low_alpha_particles(frames):
    assert max_depth(frames, "smoke") >= 100
    (particles,) = frames["smoke"][0].meshes
    assert particles.primitive["kind"] == "particles" and particles.primitive["falloff"] == "linear", \
        "alpha falls linearly to 0 at the rim"
    assert particles.colors[:, 3].min() >= 0.05 and particles.colors[:, 3].max() <= 0.25
    (fans,) = scenes.smoke(primitive="fans").meshes
    fan = fans.colors[:, 3].reshape(len(particles.positions), -1)
    assert (fan[:, 1:] == 0).all() and (fan[:, 0] == particles.colors[:, 3]).all()


def test_foliage_has_about_45_layers_of_mixed_alpha(frames):
    assert 30 <= max_depth(frames, "foliage") <= 60
    trunk, leaves = frames["foliage"][0].meshes
    assert trunk.opaque and not leaves.opaque
    alpha = leaves.colors[:, 3]
    assert alpha.min() < 0.2 and alpha.max() > 0.85 and ((alpha > 0.3) & (alpha < 0.7)).mean() > 0.4


def test_glass_defeats_sorting(frames, renderer):
    built, exact = frames["glass"]
    assert max_depth(frames, "glass") <= 8, "few layers"
    assert any(m.opaque for m in built.meshes)
    assert min(m.colors[0, 3] for m in built.meshes) >= 0.45, "high alpha"
    image = renderer(SIZE, SIZE).render(built.scene, built.camera, "sorted").image
    dist = np.sqrt(((image[..., :3] - exact.image[..., :3]) ** 2).sum(-1))[exact.depth_complexity > 0]
    assert dist.mean() > 0.1 and dist.max() > 0.5


def test_dragons_stand_in(frames):
    built, _ = frames["dragons"]
    assert built.meta["mesh"] == "stand-in blob"
    # One dragon uploaded, 22 instances with their alphas.
    assert len(built.meshes) == 1 and built.scene.instance_count == 22
    assert [m.colors[0, 3] for m in built.drawn_meshes()] == pytest.approx(scenes.DRAGON_ALPHAS)
    assert len(built.meshes[0].indices) <= 8000
    assert max_depth(frames, "dragons") >= 20


def test_dragons_from_a_file(tmp_path):
    path = tmp_path / "lump.obj"
    trimesh.Trimesh(*geometry.uv_sphere(rings=8, segments=12)).export(path)
    built = scenes.dragons(path=path, max_triangles=100)
    assert built.meta["mesh"] == "lump.obj" and len(built.drawn_meshes()) == 22
    assert len(built.meshes[0].indices) <= 100
    with pytest.raises(ValueError, match="no such mesh file"):
        scenes.dragons(path=tmp_path / "missing.obj")


def test_dragons_use_the_shared_mesh_when_present(shared_data, monkeypatch):
    monkeypatch.delenv("OIT_DATA", raising=False)
    built = scenes.dragons(max_triangles=500)
    assert built.meta["mesh"] == "dragon-100k.obj"


def test_the_data_folder_follows_oit_data(tmp_path, monkeypatch):
    monkeypatch.setenv("OIT_DATA", str(tmp_path))
    assert scenes.shared_data_dir() == tmp_path
    assert scenes.dragons(max_triangles=200).meta["mesh"] == "stand-in blob"  # no dragon there
    trimesh.Trimesh(*geometry.uv_sphere(rings=8, segments=12)).export(tmp_path / scenes.DRAGON_FILE)
    assert scenes.dragons(max_triangles=200).meta["mesh"] == scenes.DRAGON_FILE
    monkeypatch.setenv("OIT_DATA", str(tmp_path / "absent"))
    assert scenes.shared_data_dir() is None and scenes.dragons(max_triangles=200).meta["mesh"] == "stand-in blob"


def test_stacks_give_every_pixel_its_layers(renderer):
    built = scenes.stacks(layers=7, size=(8, 8))
    frame = renderer(8, 8).render(built.scene, built.camera, "abuffer")
    assert (frame.depth_complexity == 7).all()


# ---- geometry behind the scenes


def test_blob_is_closed_and_folds_over_itself(renderer):
    positions, indices = geometry.blob(size=(1.0, 0.55, 0.4), bumps=0.3, seed=3)
    mesh = trimesh.Trimesh(positions, indices, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    # Not convex: some view ray crosses the surface four times or more.
    scene = oit.Scene()
    scene.add_mesh(positions, indices, (0.5, 0.5, 0.5, 0.5))
    frame = renderer(SIZE, SIZE).render(scene, oit.Camera.fit(positions), "abuffer")
    assert frame.stats["max_depth_complexity"] >= 4


def test_decimate_bounds_triangles_and_keeps_a_clean_mesh():
    positions, indices = geometry.blob(rings=40, segments=80)
    p, idx = geometry.decimate(positions, indices, 1000)
    assert 300 < len(idx) <= 1000
    assert np.array_equal(np.unique(idx), np.arange(len(p))), "every vertex used"
    tri = p[idx].astype(np.float64)
    assert np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).min() > 0
    assert len({tuple(sorted(t)) for t in idx.tolist()}) == len(idx), "no repeated triangle"
    # The shape survives: the bounding box barely moves.
    np.testing.assert_allclose(p.min(0), positions.min(0), atol=0.1)
    np.testing.assert_allclose(p.max(0), positions.max(0), atol=0.1)
    same = geometry.decimate(positions, indices, len(indices))
    np.testing.assert_array_equal(same[1], indices)


def test_vertex_normals_of_a_sphere_point_outward():
    positions, indices = geometry.uv_sphere((1.0, 2.0, 3.0), 2.0, rings=16, segments=32)
    n = geometry.vertex_normals(positions, indices)
    radial = (positions - np.array([1.0, 2.0, 3.0])) / 2.0
    assert (np.sum(n * radial, axis=1) > 0.99).all()
