"""OBJ/MTL, PLY and STL as exporters write them, through `Scene.from_file`: an empty `usemtl`,
`l` lines as strands and `p` points as particles, MeshLab's `Tr 1.000000` opaque, errors
naming the line, every `solid` of an ASCII STL and bare `solid` headers, PLY face colors, and
a PLY whose header claims more than the file holds refused at once."""

from __future__ import annotations

import time
import warnings

import numpy as np
import pytest

import oit
from files import obj_lines_points_empty_usemtl, obj_meshlab_tr, ply_face_colors, stl_ascii_solids
from oit.imageio import srgb_to_linear


def test_obj_empty_usemtl_lines_and_points(tmp_path):
    scene = oit.Scene.from_file(obj_lines_points_empty_usemtl(tmp_path / "mixed.obj"))
    assert scene.mesh_names == ["tri", "wire", "dots"]
    assert scene.primitives() == ["triangles", "strands", "particles"]
    tri, wire, dots = scene.materials
    assert np.allclose(tri["color_mean"][:3], [1, 0, 0])
    # After the empty usemtl: no material, the default gray.
    assert np.allclose(wire["color_mean"][:3], 0.8) and np.allclose(dots["color_mean"][:3], 0.8)
    assert [n for _, n, _ in scene._native.mesh_summary()] == [3, 3, 2]


@pytest.mark.parametrize(("tr", "alpha"), [("1.000000", 1.0), ("0.3", 0.7), ("0", 1.0)])
def test_mtl_tr_as_exporters_mean_it(tmp_path, tr, alpha):
    scene = oit.Scene.from_file(obj_meshlab_tr(tmp_path / "meshlab.obj", tr))
    (m,) = scene.materials
    assert m["alpha_min"] == pytest.approx(alpha) and m["opaque"] == (alpha == 1.0)
    assert m["color_mean"][2] == pytest.approx(1.0) and m["color_mean"][0] == pytest.approx(float(srgb_to_linear(0.5)))


def test_obj_errors_name_the_line(tmp_path):
    path = tmp_path / "bad.obj"
    path.write_text("# four corners\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 9\n")
    with pytest.raises(ValueError, match=r"bad\.obj: line 6: face index 9 is past the 4 vertices"):
        oit.Scene.from_file(path)
    (tmp_path / "t.mtl").write_text("newmtl t\nKd 1 1 1\nmap_Kd gone.png\n")
    path.write_text("mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nusemtl t\nf 1/1 2/1 3/1\n")
    with pytest.raises(FileNotFoundError, match=r"t\.mtl, line 3: the image .*gone\.png is not there"):
        oit.Scene.from_file(path)


def test_stl_every_solid_and_bare_headers(tmp_path):
    scene = oit.Scene.from_file(stl_ascii_solids(tmp_path / "parts.stl", ["first", "second"], facets=2))
    assert scene.mesh_names == ["first", "second"] and scene.triangle_count == 4
    scene = oit.Scene.from_file(stl_ascii_solids(tmp_path / "bare.stl", [""]))
    assert scene.mesh_names == ["bare"] and scene.triangle_count == 1
    assert scene.materials[0]["opaque"]


@pytest.mark.parametrize("binary", [False, True])
def test_ply_face_colors(tmp_path, binary):
    scene = oit.Scene.from_file(ply_face_colors(tmp_path / "faces.ply", binary))
    ((triangles, vertices, opaque),) = scene._native.mesh_summary()
    # The two vertices on the shared edge are split: one copy a color.
    assert (triangles, vertices, opaque) == (2, 6, False)
    (m,) = scene.materials
    assert m["alpha_min"] == pytest.approx(128 / 255) and m["alpha_max"] == 1.0
    assert np.allclose(m["color_mean"][:3], [0.5, 0, 0.5])


def test_ply_claiming_more_than_it_holds_is_refused_at_once(tmp_path):
    path = tmp_path / "huge.ply"
    path.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                     b"property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                     b"end_header\n" + bytes(40))
    start = time.perf_counter()
    with pytest.raises(ValueError, match="need at least 48000000001 bytes of data, the file has 40"):
        oit.Scene.from_file(path)
    assert time.perf_counter() - start < 1.0


def test_obj_corners_naming_missing_uvs_or_normals_keep_their_vertices(tmp_path):
    # Some exporters write `f 1/1/1` with no `vt` or `vn` lines: the corners keep their
    # vertices and lose the attribute, and the loader says so.
    path = tmp_path / "dangling.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\nf 1//4 2//4 3//4\n")
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        scene = oit.Scene.from_file(path)
    assert scene.triangle_count == 2
    said = [str(w.message) for w in record if w.category is oit.OitLoadWarning]
    assert any("texture coordinate indices refer past" in m for m in said) and any("normal indices refer past" in m for m in said), said


def test_obj_of_vertices_only_is_a_point_cloud(tmp_path):
    path = tmp_path / "cloud.obj"
    path.write_text("".join(f"v {x} {x * x} 0\n" for x in range(5)))
    scene = oit.Scene.from_file(path, point_radius=0.1)
    assert scene.primitives() == ["particles"]
    assert [n for _, n, _ in scene._native.mesh_summary()] == [5]


def test_ascii_ply_words_past_the_header_properties_are_skipped(tmp_path):
    # A writer that adds words the header does not declare (a texture number, say) at the end
    # of each face: they are not read as the next face.
    path = tmp_path / "extra.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
                    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 9 1 1\n3 0 2 3 9 1 1\n")
    assert oit.Scene.from_file(path).triangle_count == 2
