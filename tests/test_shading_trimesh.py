"""Scene.from_trimesh reads surfaces (normals, colors, textures, PBR factors, glTF alphaMode)
and lights meshes by default; `python -m oit render` shows a mesh's shape (docs/shading.md)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import trimesh
from PIL import Image

import oit

ORTHO = oit.Camera.orthographic(-1, 1, -1, 1, 0.5, 3.0, eye=(0, 0, 2), target=(0, 0, 0))
SIZE = 24


def render(scene: oit.Scene, method: str = "abuffer") -> np.ndarray:
    return oit.Renderer(SIZE, SIZE).render(scene, ORTHO, method).image


def textured_quad(image: Image.Image, material=None) -> trimesh.Trimesh:
    """A square over the view with trimesh's UVs (v up the image)."""
    v = np.array([[-1.5, -1.5, 0], [1.5, -1.5, 0], [1.5, 1.5, 0], [-1.5, 1.5, 0]], float)
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    visual = trimesh.visual.TextureVisuals(uv=uv, image=image, material=material)
    return trimesh.Trimesh(v, [[0, 1, 2], [0, 2, 3]], visual=visual, process=False)


def test_a_trimesh_mesh_is_lit_smooth_by_default_and_shows_its_shape():
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.9)
    lit = oit.Scene.from_trimesh(sphere, alpha=1.0)
    flat = oit.Scene.from_trimesh(sphere, alpha=1.0, shading="unlit")
    assert lit._native.mesh_surfaces() == [("smooth", False)]
    inside = render(flat)[..., 3] > 0.5  # covered pixels
    lit_rgb = render(lit)[..., 0][inside]
    assert np.ptp(render(flat)[..., 0][inside]) == 0  # unlit: one color
    assert np.ptp(lit_rgb) > 0.3  # the headlight darkens the rim: the shape shows
    assert lit_rgb.max() == pytest.approx(0.8 ** 2.2, abs=0.05)  # facing the light: the base color


def test_texture_visuals_bring_their_image_with_v_flipped():
    # Row 0 of the image (its top) is red, the bottom row blue; trimesh's v = 1 is the top.
    image = Image.fromarray(np.array([[[255, 0, 0, 255]], [[0, 0, 255, 255]]], np.uint8))
    scene = oit.Scene.from_trimesh(textured_quad(image), shading="unlit")
    assert scene._native.mesh_surfaces() == [("unlit", True)]
    img = render(scene)
    top, bottom = img[1, SIZE // 2, :3], img[-2, SIZE // 2, :3]
    assert top[0] > 0.8 and top[2] < 0.2 and bottom[2] > 0.8 and bottom[0] < 0.2


def test_pbr_base_color_factor_is_linear_and_blend_is_transparent():
    mat = trimesh.visual.material.PBRMaterial(baseColorFactor=[255, 128, 0, 128], alphaMode="BLEND")
    image = Image.new("RGBA", (1, 1), (255, 255, 255, 255))
    scene = oit.Scene.from_trimesh(textured_quad(image, mat), shading="unlit")
    got = render(scene)[SIZE // 2, SIZE // 2, :3]
    a = 128 / 255
    np.testing.assert_allclose(got, a * np.array([1.0, 128 / 255, 0.0]) + (1 - a), atol=2e-3)


@pytest.mark.parametrize("mode,cutoff,visible,opaque", [("OPAQUE", None, True, True), ("MASK", 0.5, False, False),
                                                       ("MASK", 0.2, True, False)])
def test_gltf_alpha_modes(mode, cutoff, visible, opaque):
    mat = trimesh.visual.material.PBRMaterial(baseColorFactor=[255, 0, 0, 77], alphaMode=mode, alphaCutoff=cutoff)
    scene = oit.Scene.from_trimesh(textured_quad(Image.new("RGBA", (2, 2), (255, 255, 255, 255)), mat), shading="unlit")
    assert scene._native.mesh_summary()[0][2] is opaque
    got = render(scene)[SIZE // 2, SIZE // 2, :3]
    if visible:  # alpha 1: the pure factor color
        np.testing.assert_allclose(got, [1.0, 0.0, 0.0], atol=1e-6)
    else:  # alpha 0.3 under a cutoff of 0.5: cut away
        np.testing.assert_allclose(got, [1.0, 1.0, 1.0], atol=1e-6)


def test_face_colors_keep_smooth_normals():
    box = trimesh.creation.box(extents=(1, 1, 1))
    box.visual.face_colors = np.tile([200, 100, 50, 255], (len(box.faces), 1))
    scene = oit.Scene.from_trimesh(box)
    assert scene._native.mesh_surfaces() == [("smooth", False)]
    assert np.isfinite(render(scene)).all()


def test_render_cli_lights_and_flat_shading(tmp_path):
    path = tmp_path / "sphere.obj"
    trimesh.creation.icosphere(subdivisions=2).export(path)
    out = tmp_path / "sphere.png"
    done = subprocess.run([sys.executable, "-m", "oit", "render", str(path), "-o", str(out), "--size", "24", "24",
                           "--shading", "flat", "--light", "0", "-1", "-1", "--light", "1", "0", "0",
                           "--ambient", "0.2", "0.2", "0.2"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "flat shading (2 lights)" in done.stdout and out.is_file()
    bad = subprocess.run([sys.executable, "-m", "oit", "render", str(path), "--shading", "phong"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and "phong" in bad.stderr


def test_a_mesh_from_shared_data_shows_its_shape(shared_data):
    # As `python -m oit render` loads it: trimesh, then from_trimesh with the defaults.
    mesh = trimesh.load(shared_data / "suzanne.obj", force="mesh")
    scene = oit.Scene.from_trimesh(mesh, alpha=1.0)
    camera = oit.Camera.fit(mesh.vertices)
    lit = oit.Renderer(48, 48).render(scene, camera).image
    flat = oit.Renderer(48, 48).render(oit.Scene.from_trimesh(mesh, alpha=1.0, shading="unlit"), camera).image
    covered = flat[..., 3] > 0.99
    assert covered.mean() > 0.2
    assert np.ptp(flat[..., 0][covered]) < 1e-5  # unlit: one flat grey silhouette
    assert np.std(lit[..., 0][covered]) > 0.05  # lit: the shape shows
