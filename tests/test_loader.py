"""The one loader (oit-core's) behind `Scene.from_file` and `python -m oit render`: each format
keeps its materials, glTF its node transforms, sides and cameras; `cull_back_faces` drops back
faces on the GPU and in the reference alike; bad files end in exceptions that say what to do."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import oit
from files import box_and_panel_glb, obj_with_dissolve, ply_rgba, stl_cube, textured_multi_node_glb
from oit.imageio import srgb_to_linear, to_srgb8
from oit.views import fit_camera

SIZE = 64


def run_oit(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "oit", *args], cwd=cwd, capture_output=True, text=True, timeout=120)


def read_png(path: Path) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"))


def test_obj_dissolve_and_tr_become_alpha(tmp_path):
    scene = oit.Scene.from_file(obj_with_dissolve(tmp_path / "two.obj"))
    assert scene.mesh_names == ["glass", "wall"]
    assert [t for t, _, _ in scene._native.mesh_summary()] == [2, 2]
    glass, wall = scene.materials
    assert not glass["opaque"] and glass["alpha_min"] == glass["alpha_max"] == 0.25
    assert np.allclose(glass["color_mean"][:3], [1, 0, 0])
    assert wall["alpha_max"] == pytest.approx(0.5)
    assert wall["color_mean"][2] == pytest.approx(float(srgb_to_linear(0.5)), abs=1e-6)  # Kd is sRGB


def test_ply_rgba_and_stl(tmp_path):
    ply = oit.Scene.from_file(ply_rgba(tmp_path / "quad.ply"))
    (m,) = ply.materials
    assert ply.triangle_count == 2 and not m["opaque"]
    assert m["alpha_min"] == pytest.approx(128 / 255) and np.allclose(m["color_mean"][:3], [0, 1, 0])
    stl = oit.Scene.from_file(stl_cube(tmp_path / "cube.stl"))
    assert stl.triangle_count == 12 and stl.materials[0]["opaque"] and stl.materials[0]["alpha_min"] == 1.0


def test_glb_keeps_the_opaque_box_opaque(tmp_path, renderer):
    path = box_and_panel_glb(tmp_path / "two.glb")
    scene = oit.Scene.from_file(path, shading="unlit")
    box, panel = scene.materials
    assert scene.mesh_names == ["box", "panel"] and scene.triangle_count == 14
    # No alphaMode is the spec's OPAQUE; no doubleSided is false: back faces are culled.
    assert box["opaque"] and box["alpha_min"] == 1.0 and box["cull_back_faces"] and not box["two_sided"]
    assert not panel["opaque"] and panel["alpha_max"] == 0.5 and panel["two_sided"] and not panel["cull_back_faces"]
    lo, hi = scene.bounds
    assert np.allclose(lo, [-2, -2, -0.5]) and np.allclose(hi, [2, 2, 1.0])  # the box's node moved it to z = 0.5
    frame = renderer(SIZE, SIZE).render(scene, fit_camera(scene), "abuffer")
    assert (frame.image[SIZE // 2, SIZE // 2, :3] == [1, 0, 0]).all(), "the box is exactly opaque red"
    half_blue = np.all(np.isclose(frame.image[..., :3], [0.5, 0.5, 1.0], atol=1e-6), axis=-1)
    assert half_blue.any(), "the panel blends at alpha 0.5 over the white background"


def test_cli_renders_the_box_opaque_and_says_when_it_makes_a_file_transparent(tmp_path):
    out = tmp_path / "two.png"
    done = run_oit("render", str(box_and_panel_glb(tmp_path / "two.glb")), "--shading", "unlit", "--size", str(SIZE), str(SIZE),
                   "-o", str(out), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "alpha 0.4" not in done.stdout
    image = read_png(out)
    assert (image[SIZE // 2, SIZE // 2] == [255, 0, 0]).all(), "the opaque box stays red, not pink-grey"
    done = run_oit("render", str(box_and_panel_glb(tmp_path / "box.glb", panel=False)), "--size", "16", "16",
                   "-o", str(tmp_path / "box.png"), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "nothing in the file is transparent: every mesh is drawn at alpha 0.4" in done.stdout


def test_alpha_makes_every_mesh_transparent(tmp_path):
    scene = oit.Scene.from_file(box_and_panel_glb(tmp_path / "two.glb"), alpha=0.3)
    assert all(not m["opaque"] and m["alpha_min"] == m["alpha_max"] == pytest.approx(0.3) for m in scene.materials)


def test_textured_double_sided_multi_node_gltf(tmp_path, renderer):
    path = textured_multi_node_glb(tmp_path / "quads.glb")
    scene = oit.Scene.from_file(path)
    # Two nodes share the quad's mesh: uploaded once, drawn as two instances.
    assert scene.mesh_names == ["quad"] and scene.triangle_count == 4 and scene.unique_triangle_count == 2
    assert scene.instance_count == 2
    for m in scene.materials:
        assert m["textured"] and m["has_uvs"] and m["two_sided"] and not m["cull_back_faces"] and not m["opaque"]
    lo, hi = scene.bounds
    # The child quad: scaled by 0.5 and moved to x = 1; the other turned about y and moved to x = -1.
    assert np.allclose(lo, [-2, -1, 0]) and np.allclose(hi, [1.5, 1, 0])
    (cam,) = scene.cameras
    expect = oit.Camera.look_at((0, 0, 4), (0, 0, 0), fov_y=np.degrees(0.9), near=0.1, far=20.0)
    assert np.allclose(cam.camera().view_proj, expect.view_proj, atol=1e-6)
    # The GPU agrees with the reference, and the command line writes the same frame.
    frame = renderer(SIZE, SIZE).render(scene, cam.camera(), "abuffer")
    ref, ambiguous = oit.reference(scene, cam.camera(), SIZE, SIZE, return_mask=True)
    assert np.abs(frame.image - ref)[~ambiguous].max() < 1e-5
    assert (frame.image[..., 3] < 1).any(), "the quads are in view"
    out = tmp_path / "quads.png"
    done = run_oit("render", str(path), "--size", str(SIZE), str(SIZE), "-o", str(out), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (read_png(out) == to_srgb8(frame.image[..., :3])).all()


@pytest.mark.parametrize("cull", [False, True])
def test_cull_back_faces_on_the_gpu_and_in_the_reference(renderer, cull):
    from files import CUBE, CUBE_FACES

    scene = oit.Scene()
    scene.add_mesh(CUBE, CUBE_FACES, (0.2, 0.4, 0.8, 0.5), cull_back_faces=cull)
    camera = oit.Camera.look_at((0.4, 0.5, 2.5), (0, 0, 0), near=0.5, far=5.0)
    frame = renderer(SIZE, SIZE).render(scene, camera, "abuffer", census=True)
    ref, ambiguous = oit.reference(scene, camera, SIZE, SIZE, return_mask=True)
    assert np.abs(frame.image - ref)[~ambiguous].max() < 1e-5
    covered = frame.depth_complexity > 0
    assert covered.any()
    # A convex body: culled, a pixel holds its front face alone; else front and back.
    assert set(np.unique(frame.depth_complexity[covered & ~ambiguous])) == ({1} if cull else {2})


@pytest.mark.parametrize(("name", "data", "error", "match"), [
    ("missing.obj", None, FileNotFoundError, "no such file"),
    ("x.fbx", b"", ValueError, "unknown file type '.fbx'"),
    ("bad.glb", b"glTF\x02\0\0\0junk", ValueError, "not a readable glTF"),
    ("bad.stl", b"\0" * 90, ValueError, "bad.stl"),
    ("empty.obj", b"# vertices only are a point cloud; none is nothing\no empty\n", ValueError, "no triangles"),
])
def test_bad_files_say_what_to_do(tmp_path, name, data, error, match):
    if data is not None:
        (tmp_path / name).write_bytes(data)
    with pytest.raises(error, match=match):
        oit.Scene.from_file(tmp_path / name)


def test_bad_arguments(tmp_path):
    path = stl_cube(tmp_path / "cube.stl")
    with pytest.raises(TypeError, match="path must be a file name"):
        oit.Scene.from_file(3)
    with pytest.raises(ValueError, match=r"alpha must be in \[0, 1\]"):
        oit.Scene.from_file(path, alpha=2.0)
    with pytest.raises(ValueError, match="shading must be one of"):
        oit.Scene.from_file(path, shading="phong")
    done = run_oit("render", str(tmp_path / "nope.glb"), cwd=tmp_path)
    assert done.returncode == 2 and "no such file" in done.stderr


def test_obj_textures_map_kd_and_map_d(tmp_path, renderer):
    """map_Kd (sRGB) times map_d (its first channel as alpha) on the file's UVs (v up the image)."""
    from oit.imageio import encode_png

    color = np.zeros((1, 2, 4), np.uint8)
    color[0, 0], color[0, 1] = (255, 0, 0, 255), (0, 0, 255, 255)
    (tmp_path / "kd.png").write_bytes(encode_png(color))
    (tmp_path / "d.png").write_bytes(encode_png(np.full((1, 1, 4), 128, np.uint8)))
    (tmp_path / "t.mtl").write_text("newmtl t\nKd 1 1 1\nmap_Kd kd.png\nmap_d d.png\n")
    (tmp_path / "t.obj").write_text("mtllib t.mtl\nusemtl t\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                                    "vt 0.25 0\nvt 0.25 0\nvt 0.25 1\nvt 0.25 1\nf 1/1 2/2 3/3 4/4\n")
    scene = oit.Scene.from_file(tmp_path / "t.obj", shading="unlit")
    (m,) = scene.materials
    assert m["textured"] and m["has_uvs"] and not m["opaque"]
    camera = oit.Camera.look_at((0, 0, 3), (0, 0, 0), fov_y=30.0, near=1.0, far=5.0)
    frame = renderer(SIZE, SIZE).render(scene, camera, "abuffer", background=(0.0, 0.0, 0.0))
    # u = 0.25 is the red texel's center; alpha 128/255 from map_d, over black.
    assert np.allclose(frame.image[SIZE // 2, SIZE // 2, :3], [128 / 255, 0, 0], atol=1e-6)
