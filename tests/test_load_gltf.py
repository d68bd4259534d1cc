"""glTF as its specification has it, on files these tests write: strips and fans, lines as
strands and points as particles, GPU instancing, samplers and texture transforms (seen in the
CPU reference), emissive light, sparse accessors and accessors without a bufferView, data URIs
in a GLB; what oit does not draw said once as a warning; broken files refused naming the
object and the rule, a missing .bin as FileNotFoundError."""

from __future__ import annotations

import base64
import json
import re

import numpy as np
import pytest

import oit
from files import QUAD, QUAD_FACES, Gltf
from oit.imageio import encode_png
from scenes import IDENTITY

SIZE = 48
TRI = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)


def load(tmp_path, g: Gltf, name: str = "t.glb", **kw) -> oit.Scene:
    path = tmp_path / name
    path.write_bytes(g.glb())
    return oit.Scene.from_file(path, **kw)


def refused(tmp_path, g: Gltf, error=ValueError) -> str:
    with pytest.raises(error) as e:
        load(tmp_path, g)
    return str(e.value)


def red_blue(sampler: dict | None = None, **info) -> tuple[Gltf, int]:
    """A document with a 2 x 1 texture (red, blue) and an OPAQUE material using it."""
    g = Gltf()
    texels = np.array([[[255, 0, 0, 255], [0, 0, 255, 255]]], np.uint8)
    tex = g.texture(texels, sampler)
    return g, g.material(pbrMetallicRoughness={"baseColorTexture": {"index": tex, **info}}, doubleSided=True)


def screen_quad(g: Gltf, material: int, uvs) -> None:
    """A quad over the identity camera's whole view, at depth 0.5."""
    g.node(mesh=g.mesh(QUAD, QUAD_FACES, material, uvs=np.asarray(uvs, np.float32)), translation=[0, 0, 0.5])


def middle_row(tmp_path, g: Gltf) -> np.ndarray:
    scene = load(tmp_path, g, shading="unlit")
    return oit.reference(scene, IDENTITY, SIZE, SIZE)[SIZE // 2, :, :3]


def test_strips_and_fans_are_triangles_facing_the_same_way(tmp_path):
    g = Gltf()
    strip = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0, 2, 0]]
    g.node(mesh=g.mesh(strip, None, mode=5, name="strip"))
    fan = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [-1, 1, 0]]
    g.node(mesh=g.mesh(fan, None, mode=6, name="fan"))
    scene = load(tmp_path, g, shading="flat")
    assert scene.mesh_names == ["strip", "fan"] and scene.triangle_count == 6
    # Back faces are culled (no doubleSided): seen from +z every triangle is drawn.
    camera = oit.Camera.look_at((0, 0.8, 4), (0, 0.8, 0), fov_y=50, near=1, far=10)
    seen = oit.reference(scene, camera, SIZE, SIZE)[..., 3] > 0
    behind = oit.reference(scene, oit.Camera.look_at((0, 0.8, -4), (0, 0.8, 0), fov_y=50, near=1, far=10), SIZE, SIZE)[..., 3] > 0
    assert seen.sum() > 100 and not behind.any()


def test_lines_are_strands_and_points_particles(tmp_path):
    g = Gltf()
    square = np.array([[0, 0, 0], [3, 0, 0], [3, 4, 0], [0, 4, 0]], np.float32)
    g.node(mesh=g.mesh(square, [0, 1, 1, 2], mode=1, name="lines"))
    g.node(mesh=g.mesh(square, None, mode=2, name="loop"))
    g.node(mesh=g.mesh(square, None, mode=3, name="strip"))
    g.node(mesh=g.mesh(square, None, mode=0, name="points"))
    scene = load(tmp_path, g)
    assert scene._native.mesh_primitives() == ["strands", "strands", "strands", "particles"]
    # A polyline of 3 points and a loop of 5 (back to its start): 2 + 4 + 3 segments, 4 discs.
    assert scene.triangle_count == 2 * (2 + 4 + 3) + 2 * 4
    # Discs 1/200 of the box diagonal (5) in radius, seen from close by (the pixel is 0.02 wide).
    frame = oit.reference(scene, oit.Camera.look_at((3, 4, 1), (3, 4, 0), fov_y=50, near=0.5, far=20), SIZE, SIZE)
    assert (frame[..., 3] > 0).sum() >= 4


def test_gpu_instancing_draws_every_instance(tmp_path):
    g = Gltf()
    mesh = g.mesh(TRI, None, name="tri")
    t = g.accessor(np.array([[0, 0, 0], [10, 0, 0], [20, 0, 0]], np.float32), "VEC3")
    s = g.accessor(np.array([[1, 1, 1], [2, 2, 2], [1, 1, 1]], np.float32), "VEC3")
    g.doc["extensionsUsed"] = ["EXT_mesh_gpu_instancing"]
    g.node(mesh=mesh, translation=[0, 0, 5], extensions={"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": t, "SCALE": s}}})
    scene = load(tmp_path, g)
    assert scene.instance_count == 3 and scene.unique_triangle_count == 1 and scene.triangle_count == 3
    lo, hi = scene.bounds
    assert np.allclose(lo, [0, 0, 5]) and np.allclose(hi, [21, 2, 5])


@pytest.mark.parametrize(("wrap", "expect"), [
    (10497, ["red", "blue", "red"]),   # REPEAT: u -0.72, -0.22, 1.28 read 0.28, 0.78, 0.28
    (33071, ["red", "red", "blue"]),   # CLAMP_TO_EDGE: 0, 0, 1
    (33648, ["blue", "red", "blue"]),  # MIRRORED_REPEAT: 0.72, 0.22, 0.72
])
def test_sampler_wrap_modes_reach_the_material(tmp_path, wrap, expect):
    g, material = red_blue({"wrapS": wrap, "magFilter": 9728, "minFilter": 9728})
    # u runs from -1 to 2 across the view.
    screen_quad(g, material, [[-1, 1], [2, 1], [2, 0], [-1, 0]])
    row = middle_row(tmp_path, g)
    colors = {"red": [1, 0, 0], "blue": [0, 0, 1]}
    for column, name in zip([4, 12, 36], expect):
        assert np.allclose(row[column], colors[name], atol=1e-6), (column, row[column])


def test_scene_materials_show_the_sampler_transform_emission_and_cutoff(tmp_path):
    g, material = red_blue({"wrapS": 33648, "wrapT": 33071, "magFilter": 9728, "minFilter": 9985},
                           extensions={"KHR_texture_transform": {"offset": [0.5, 0], "scale": [2, 1]}})
    g.doc["materials"][material].update(alphaMode="MASK", alphaCutoff=0.3, emissiveFactor=[0.5, 0.25, 0])
    g.doc["extensionsUsed"] = ["KHR_texture_transform"]
    screen_quad(g, material, [[0, 1], [1, 1], [1, 0], [0, 0]])
    (m,) = load(tmp_path, g).materials
    assert m["alpha_cutoff"] == pytest.approx(0.3) and m["emissive"] == pytest.approx([0.5, 0.25, 0])
    t = m["texture"]
    assert t["size"] == (2, 1) and t["levels"] == 2
    assert t["wrap"] == ("mirrored_repeat", "clamp_to_edge") and t["filters"] == ("nearest", "linear", "nearest")
    assert np.allclose(t["transform"], [[2, 0, 0.5], [0, 1, 0]])


def test_texture_transform_moves_the_uvs(tmp_path):
    nearest = {"wrapS": 33071, "magFilter": 9728, "minFilter": 9728}
    g, material = red_blue(nearest)
    screen_quad(g, material, [[0, 1], [1, 1], [1, 0], [0, 0]])
    row = middle_row(tmp_path, g)
    assert np.allclose(row[8], [1, 0, 0]) and np.allclose(row[40], [0, 0, 1]), "untransformed: red, then blue"
    g, material = red_blue(nearest, extensions={"KHR_texture_transform": {"offset": [0.5, 0]}})
    g.doc["extensionsUsed"] = ["KHR_texture_transform"]
    screen_quad(g, material, [[0, 1], [1, 1], [1, 0], [0, 0]])
    row = middle_row(tmp_path, g)
    assert np.allclose(row[8], [0, 0, 1]) and np.allclose(row[40], [0, 0, 1]), "u + 0.5: blue, then clamped blue"


def test_emissive_light_adds_to_the_color(tmp_path):
    g = Gltf()
    glow = g.material(pbrMetallicRoughness={"baseColorFactor": [0, 0, 0, 1]}, emissiveFactor=[0, 0.25, 0.125],
                      extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}}, doubleSided=True)
    g.doc["extensionsUsed"] = ["KHR_materials_emissive_strength"]
    g.node(mesh=g.mesh(QUAD, QUAD_FACES, glow), translation=[0, 0, 0.5])
    assert np.allclose(middle_row(tmp_path, g)[SIZE // 2], [0, 0.5, 0.25], atol=1e-6)


def test_sparse_accessors_and_accessors_without_a_buffer_view(tmp_path):
    g = Gltf()
    ix = g._view(np.array([1, 2], np.uint16).tobytes())
    values = g._view(np.array([[2, 0, 0], [0, 3, 0]], np.float32).tobytes())
    g.doc["accessors"].append({"componentType": 5126, "count": 3, "type": "VEC3", "max": [2, 3, 0], "min": [0, 0, 0],
                               "sparse": {"count": 2, "indices": {"bufferView": ix, "componentType": 5123},
                                          "values": {"bufferView": values}}})
    pos = len(g.doc["accessors"]) - 1
    g.doc["accessors"].append({"componentType": 5121, "normalized": True, "count": 3, "type": "VEC4"})  # zeros: black
    g.doc["meshes"].append({"name": "sparse", "primitives": [{"attributes": {"POSITION": pos, "COLOR_0": pos + 1}}]})
    g.node(mesh=len(g.doc["meshes"]) - 1)
    scene = load(tmp_path, g)
    lo, hi = scene.bounds
    assert np.allclose(lo, [0, 0, 0]) and np.allclose(hi, [2, 3, 0])
    (m,) = scene.materials
    assert np.allclose(m["color_mean"], [0, 0, 0, 1]), "zeros times white, OPAQUE's alpha 1"


def test_data_uri_image_in_a_glb_and_a_texture_without_source(tmp_path):
    g = Gltf()
    png = encode_png(np.full((2, 2, 4), 255, np.uint8))
    g.doc["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png).decode()}]
    g.doc["textures"] = [{"source": 0}, {}]
    for t in (0, 1):
        m = g.material(pbrMetallicRoughness={"baseColorTexture": {"index": t}})
        g.node(mesh=g.mesh(QUAD, QUAD_FACES, m, uvs=np.zeros((4, 2))))
    with pytest.warns(UserWarning, match=r"1 texture has no image oit reads"):
        scene = load(tmp_path, g)
    assert [m["textured"] for m in scene.materials] == [True, False]


def test_animations_skins_and_unknown_extensions_are_warnings(tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh(TRI, None))
    g.doc["animations"] = [{"channels": [{"sampler": 0, "target": {"path": "rotation"}}], "samplers": []}]
    g.doc["skins"] = [{"joints": [0]}]
    g.doc["extensionsUsed"] = ["KHR_materials_sheen"]
    g.doc["nodes"][0]["extras"] = "anything at all"
    with pytest.warns(UserWarning) as seen:
        scene = load(tmp_path, g)
    text = [str(w.message) for w in seen]
    assert scene.triangle_count == 1
    assert any("1 animation is not drawn: oit shows the base pose" in t for t in text), text
    assert any("1 skin is not applied" in t for t in text), text
    assert any("KHR_materials_sheen" in t for t in text), text


def test_node_cycles_are_refused_naming_the_node(tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh(TRI, None))
    g.doc["nodes"] += [{"children": [2]}, {"children": [1]}]
    assert "nodes[1] is its own ancestor" in refused(tmp_path, g)
    g.doc["nodes"][2]["children"] = [0]
    assert "scenes[0].nodes lists nodes[0], a child of nodes[2]" in refused(tmp_path, g)


def test_a_missing_bin_is_file_not_found_naming_it(tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh(TRI, None))
    path = g.gltf(tmp_path / "t.gltf", "t.bin")
    assert oit.Scene.from_file(path).triangle_count == 1
    (tmp_path / "t.bin").unlink()
    with pytest.raises(FileNotFoundError, match=r"t\.gltf: buffers\[0\] refers to 't\.bin', which is not there"):
        oit.Scene.from_file(path)
    # The same document with its buffer as a data URI needs no other file.
    assert oit.Scene.from_file(g.gltf(tmp_path / "inline.gltf")).triangle_count == 1


def test_broken_rules_are_value_errors_naming_object_and_rule(tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh(np.zeros((5, 3)), None))
    # A count TRIANGLES does not use whole is the validator's warning, not an error: the
    # leftover vertices are not drawn, and the loader says so naming the accessor.
    with pytest.warns(oit.OitLoadWarning, match=re.escape("accessors[0]: count 5 is not a multiple of 3 for TRIANGLES")):
        assert load(tmp_path, g).triangle_count == 1
    g.doc["accessors"][0]["count"] = 4_000_000_000
    assert "accessors[0]: count 4000000000" in refused(tmp_path, g)
    g.doc["accessors"][0]["count"] = 3
    g.doc["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    assert "extensionsRequired lists KHR_draco_mesh_compression, which oit does not read" in refused(tmp_path, g)
    del g.doc["extensionsRequired"]
    g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 9
    assert "POSITION: accessors[9] does not exist" in refused(tmp_path, g)
    g.doc["images"] = [{}]
    g.doc["textures"] = [{"source": 0}]
    g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 0
    g.doc["meshes"][0]["primitives"][0]["material"] = g.material(pbrMetallicRoughness={"baseColorTexture": {"index": 0}})
    g.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = g.accessor(np.zeros((3, 2)), "VEC2")
    assert "images[0] has neither a uri nor a bufferView" in refused(tmp_path, g)
    (tmp_path / "x.gltf").write_bytes(b"{not json")
    with pytest.raises(ValueError, match="not a readable glTF file: its JSON is broken"):
        oit.Scene.from_file(tmp_path / "x.gltf")


def test_integers_written_as_floats_load(tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh(TRI, [0, 1, 2]))
    text = json.dumps(g.doc)
    g.doc = json.loads(text.replace('"count": 3', '"count": 3.0').replace('"mesh": 0', '"mesh": 0.0'))
    assert load(tmp_path, g).triangle_count == 1
