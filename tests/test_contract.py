"""The frame contract: stats, array types and shapes, the pixel-center convention, the
method table, adapter info, the node pool split across bindings, and empty scenes."""

from __future__ import annotations

import ast
import inspect
import re
from pathlib import Path

import numpy as np
import pytest

import oit
from oit import geometry
from scenes import IDENTITY, MeshData, build_scene, layer

METHODS = ["abuffer", "unsorted", "sorted"]
STAT_KEYS = {"fragments", "max_depth_complexity", "memory_bytes", "gpu_time_ms", "overflow_fragments"}


@pytest.mark.parametrize("method", METHODS)
def test_stats_count_known_fragments(renderer, method):
    w, h = 24, 16
    r = renderer(w, h)
    scene = build_scene([layer(z, (0.5, 0.5, 0.5, 0.5)) for z in (0.2, 0.4, 0.6)])
    frame = r.render(scene, IDENTITY, method=method, census=True)
    s = frame.stats
    assert set(s) >= STAT_KEYS
    assert s["method"] == method
    # Full-screen quads: the shared diagonal of each quad's two triangles passes through
    # pixel centers, and is drawn once (top-left rule): exactly 3 fragments a pixel.
    assert s["fragments"] == 3 * w * h
    assert s["max_depth_complexity"] == 3
    assert (frame.depth_complexity == 3).all()
    assert s["overflow_fragments"] == 0
    if r.adapter_info["timestamps"]:
        assert isinstance(s["gpu_time_ms"], float) and s["gpu_time_ms"] > 0
    else:
        assert s["gpu_time_ms"] is None
    if method == "abuffer":
        # At least one 24-byte node (depth, next link, RGBA) a fragment.
        assert s["memory_bytes"] >= 24 * 3 * w * h
    else:
        assert s["memory_bytes"] >= 0


@pytest.mark.parametrize("method", METHODS)
def test_image_and_depth_complexity_types(renderer, method):
    frame = renderer(24, 16).render(build_scene([layer(0.5, (1, 0, 0, 0.5))]), IDENTITY, method=method, census=True)
    assert frame.image.dtype == np.float32 and frame.image.shape == (16, 24, 4)
    assert frame.depth_complexity.dtype == np.uint32 and frame.depth_complexity.shape == (16, 24)
    assert frame.image.flags.c_contiguous


def test_pixel_centers_and_row_zero_at_the_top(renderer):
    # 16 x 8 pixels; pixel (row, col) has its center at x = (col + 0.5) / 8 - 1,
    # y = 1 - (row + 0.5) / 4. A quad over x in [-0.75, -0.25], y in [0.25, 0.75] has its
    # edges on pixel boundaries and covers exactly columns 2-5 of rows 1-2 (near the top).
    positions, indices = geometry.quad((-0.5, 0.5, 0.5), (0.5, 0.5))
    scene = build_scene([MeshData(positions, indices, np.tile(np.float32([1, 0, 0, 0.5]), (4, 1)))])
    frame = renderer(16, 8).render(scene, IDENTITY, background=(0.0, 0.0, 0.0))
    expected = np.zeros((8, 16), dtype=np.uint32)
    expected[1:3, 2:6] = 1
    assert np.array_equal(frame.depth_complexity, expected)
    assert np.array_equal(frame.image[..., 3] > 0, expected > 0)


def test_small_triangle_lands_on_one_pixel(renderer):
    # A triangle around the center of pixel (row 0, col 15) of 16 x 8: the top-right corner.
    cx, cy = (15 + 0.5) / 8 - 1, 1 - (0 + 0.5) / 4
    d = 0.04
    positions = np.float32([[cx - d, cy - d, 0.5], [cx + d, cy - d, 0.5], [cx, cy + d, 0.5]])
    scene = build_scene([MeshData(positions, np.array([[0, 1, 2]]), np.tile(np.float32([0, 1, 0, 1]), (3, 1)))])
    frame = renderer(16, 8).render(scene, IDENTITY, background=(0.0, 0.0, 0.0))
    assert np.argwhere(frame.depth_complexity).tolist() == [[0, 15]]
    assert frame.image[0, 15].tolist() == [0.0, 1.0, 0.0, 1.0]


def test_orthographic_camera_in_pixel_units(renderer):
    # World units = pixels, y up: the frame is x in [0, 16], y in [0, 8]. A quad over
    # x in [3, 5], y in [6, 8] is the top two rows (0 and 1), columns 3 and 4.
    camera = oit.Camera.orthographic(0.0, 16.0, 0.0, 8.0, near=0.0, far=2.0)
    positions, indices = geometry.quad((4.0, 7.0, -1.0), (2.0, 2.0))
    scene = build_scene([MeshData(positions, indices, np.tile(np.float32([0, 0, 1, 1]), (4, 1)))])
    frame = renderer(16, 8).render(scene, camera, background=(0.0, 0.0, 0.0))
    assert sorted(map(tuple, np.argwhere(frame.depth_complexity).tolist())) == [(0, 3), (0, 4), (1, 3), (1, 4)]
    ref = oit.reference(scene, camera, 16, 8, background=(0.0, 0.0, 0.0))
    assert np.abs(frame.image - ref).max() <= 1e-7


@pytest.mark.parametrize("camera", [
    oit.Camera.look_at((1.0, 2.0, 3.0), (0.0, 0.5, -1.0)),
    oit.Camera.orthographic(-1.0, 1.0, -1.0, 1.0, 0.1, 10.0, eye=(2.0, 0.0, 0.0), target=(0.0, 0.0, 0.0)),
])
def test_a_cameras_view_direction_is_its_middle_ray(camera):
    # From the near plane's center to the far plane's, in float64 with numpy.
    inv = np.linalg.inv(camera.view_proj)
    near, far = (inv @ np.array([0.0, 0.0, z, 1.0]) for z in (0.0, 1.0))
    ray = far[:3] / far[3] - near[:3] / near[3]
    np.testing.assert_allclose(camera.view_direction, ray / np.linalg.norm(ray), rtol=0, atol=1e-12)
    assert camera.view_direction.dtype == np.float64 and camera.view_direction.shape == (3,)


def test_method_table():
    table = {m["name"]: m for m in oit.methods()}
    assert set(METHODS) <= set(table)
    assert table["abuffer"]["exact"] is True and table["abuffer"]["bounded_memory"] is False
    assert table["unsorted"]["exact"] is False and table["sorted"]["exact"] is False
    for m in table.values():
        assert isinstance(m["summary"], str) and m["summary"]
        assert m["passes"] and all(isinstance(p, str) for p in m["passes"])
        assert isinstance(m["params"], list)
        for p in m["params"]:
            assert {"name", "type", "default", "doc"} <= set(p)


def test_adapter_info(renderer):
    info = renderer(16, 16).adapter_info
    assert isinstance(info["name"], str) and info["name"]
    assert info["max_storage_binding_bytes"] > 0


def test_node_pool_split_across_bindings_gives_the_same_image(renderer):
    # max_binding_bytes applies to every storage binding: at 4 x 4 the per-pixel sweep state
    # (48 B/pixel) needs 768 bytes. 1024-byte bindings hold 42 nodes each, 168 in all; nine
    # full-screen layers are 144 fragments, so nodes land in all four bindings.
    scene = build_scene([layer(0.1 * (i + 1), (0.1 * i, 0.5, 1 - 0.1 * i, 0.3)) for i in range(9)])
    whole = renderer(4, 4).render(scene, IDENTITY, background=(0.2, 0.2, 0.2))
    split = renderer(4, 4, max_binding_bytes=1024).render(scene, IDENTITY, background=(0.2, 0.2, 0.2))
    assert 3 * 42 < split.stats["fragments"] <= 4 * 42
    assert np.array_equal(split.image, whole.image)


def test_a_node_pool_too_small_for_the_frame_tiles_it(renderer):
    # 768-byte bindings hold 32 nodes each, 128 in all; 4 x 4 pixels x 9 layers = 144 go in
    # tiles (docs/methods.md, "Tiles"), with the image of the whole frame.
    r = renderer(4, 4, max_binding_bytes=768)
    scene = build_scene([layer(0.1 * (i + 1), (1, 0, 0, 0.5)) for i in range(9)])
    tiled = r.render(scene, IDENTITY)
    assert tiled.stats["tiles"] > 1
    assert np.array_equal(tiled.image, renderer(4, 4).render(scene, IDENTITY).image)
    # Only a pixel deeper than a whole pool is refused, by name.
    deep = build_scene([layer(0.9 * (i + 1) / 130, (1, 0, 0, 0.5)) for i in range(130)])
    with pytest.raises(MemoryError, match=r"pixel \(0, 0\) has 130 transparent fragments, more than one tile can hold"):
        r.render(deep, IDENTITY)
    ok = r.render(build_scene([layer(0.5, (1, 0, 0, 0.5))]), IDENTITY)
    assert ok.stats["fragments"] == 16


def test_per_pixel_buffers_past_a_lowered_limit_go_in_tiles(renderer):
    # 16 x 16 pixels of 48-byte sweep state do not fit 256-byte bindings: tiles of a few pixels do.
    scene = build_scene([layer(0.5, (1, 0, 0, 0.5))])
    tiled = renderer(16, 16, max_binding_bytes=256).render(scene, IDENTITY)
    assert tiled.stats["tiles"] >= 16 * 16 // 5
    assert np.array_equal(tiled.image, renderer(16, 16).render(scene, IDENTITY).image)


@pytest.mark.parametrize("method", METHODS)
def test_empty_scene_is_the_background(renderer, method):
    r = renderer(16, 16)
    empty_mesh = oit.Scene()
    empty_mesh.add_mesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.uint32), (1.0, 0.0, 0.0, 1.0))
    for scene in (oit.Scene(), empty_mesh):
        frame = r.render(scene, IDENTITY, method=method, background=(0.1, 0.2, 0.3), census=True)
        assert np.array_equal(frame.image, np.broadcast_to(np.float32([0.1, 0.2, 0.3, 0.0]), (16, 16, 4)))
        assert frame.stats["fragments"] == 0 and frame.stats["max_depth_complexity"] == 0


@pytest.mark.parametrize("method", [m["name"] for m in oit.methods() if m["name"] in ("unsorted", "wboit", "hybrid", "hybrid64",
                                                                                       "abuffer", "depth_peeling")])
def test_the_census_runs_where_the_method_needs_it_or_the_caller_asks(renderer, method):
    """A method that plans from the census (oit.methods()'s "census") always runs it; the others
    run it only with census=True, and report no counts without it. The image is the same bits
    either way."""
    r = renderer(24, 16)
    scene = build_scene([layer(z, (0.5, 0.5, 0.5, 0.5)) for z in (0.2, 0.4, 0.6)])
    needs = next(m["census"] for m in oit.methods() if m["name"] == method)
    plain = r.render(scene, IDENTITY, method=method)
    counted = r.render(scene, IDENTITY, method=method, census=True)
    assert np.array_equal(plain.image, counted.image)
    assert counted.stats["census"] and counted.stats["fragments"] == 3 * 24 * 16 and (counted.depth_complexity == 3).all()
    assert plain.stats["census"] == needs
    if needs:
        assert plain.stats["fragments"] == counted.stats["fragments"]
        assert np.array_equal(plain.depth_complexity, counted.depth_complexity)
    else:
        assert plain.stats["fragments"] is None and plain.stats["max_depth_complexity"] is None
        assert plain.depth_complexity is None


@pytest.mark.parametrize("method", ["abuffer", "compact_abuffer"])
def test_a_capture_that_counts_replaces_the_census_after_the_first_frame(method):
    """abuffer and compact_abuffer count each pixel's fragments in their own capture once an
    earlier frame sized their pool: the frame then runs no census, and reports the counts the
    census gives, with the same image. A frame that asks for the census, or that has a budget,
    runs it."""
    r = oit.Renderer(24, 16)
    scene = build_scene([layer(z, (0.5, 0.5, 0.5, 0.5)) for z in (0.2, 0.4, 0.6)]
                        + [layer(0.3, (0.2, 0.9, 0.1, 0.7), size=1.0)])
    first = r.render(scene, IDENTITY, method=method)
    again = r.render(scene, IDENTITY, method=method)
    asked = r.render(scene, IDENTITY, method=method, census=True)
    assert first.stats["extra"]["counted_in_capture"] == 0.0
    assert again.stats["extra"]["counted_in_capture"] == 1.0
    assert asked.stats["extra"]["counted_in_capture"] == 0.0
    for f in (again, asked):
        assert np.array_equal(f.image, first.image)
        assert np.array_equal(f.depth_complexity, first.depth_complexity)
        assert f.stats["census"]
        for key in ("fragments", "max_depth_complexity", "memory_bytes"):
            assert f.stats[key] == first.stats[key], key
    assert first.stats["max_depth_complexity"] == 4 and first.depth_complexity.min() == 3
    # More fragments than the pool held: it grows to the count and the capture runs again.
    deeper = build_scene([layer(z, (0.5, 0.5, 0.5, 0.5)) for z in np.linspace(0.1, 0.9, 12)])
    grown = r.render(deeper, IDENTITY, method=method)
    assert grown.stats["extra"]["counted_in_capture"] == 1.0 and grown.stats["extra"]["pool_regrown"] == 1.0
    assert grown.stats["fragments"] == 12 * 24 * 16 and (grown.depth_complexity == 12).all()
    fresh = oit.Renderer(24, 16).render(deeper, IDENTITY, method=method)
    assert np.array_equal(grown.image, fresh.image)


@pytest.mark.parametrize("method", ["abuffer", "compact_abuffer"])
def test_a_count_past_the_largest_pool_falls_back_to_the_census_and_tiles(method):
    # 768-byte bindings hold at most 128 nodes of either method's pool; a first frame of 3
    # layers (48 fragments) sizes the pool, the next has 9 (144): its capture counts more than
    # any pool holds, and the frame is planned again from the census, in tiles.
    r = oit.Renderer(4, 4, max_binding_bytes=768)
    r.render(build_scene([layer(0.1 * (i + 1), (1, 0, 0, 0.5)) for i in range(3)]), IDENTITY, method=method)
    scene = build_scene([layer(0.1 * (i + 1), (0.1 * i, 0.5, 1 - 0.1 * i, 0.3)) for i in range(9)])
    tiled = r.render(scene, IDENTITY, method=method)
    assert tiled.stats["tiles"] > 1 and tiled.stats["extra"]["counted_in_capture"] == 0.0
    assert tiled.stats["fragments"] == 144 and (tiled.depth_complexity == 9).all()
    assert np.array_equal(tiled.image, oit.Renderer(4, 4).render(scene, IDENTITY, method=method).image)


def test_census_must_be_a_bool(renderer):
    with pytest.raises(TypeError, match="census must be True or False"):
        renderer(4, 4).render(oit.Scene(), IDENTITY, method="unsorted", census=1)


def test_the_stats_types_are_the_cores():
    """`oit.Stats` names the core's keys (crates/oit-core/src/stats/) with its types, in its
    order; the native module's stub takes it from there rather than writing the keys again."""
    schema = [(name, ty) for name, ty, _ in oit._oit.stats_schema()]
    # Annotations are kept as written (this module's `from __future__ import annotations`):
    # TypedDict wraps each in a ForwardRef.
    written = [(k, getattr(v, "__forward_arg__", v)) for k, v in oit.Stats.__annotations__.items()]
    assert written == schema
    assert all(doc for _, _, doc in oit._oit.stats_schema())
    stub = ast.parse((Path(oit.__file__).parent / "_oit.pyi").read_text())
    imports = [(n.module, a.name, a.asname) for n in stub.body if isinstance(n, ast.ImportFrom) for a in n.names]
    assert ("oit._api", "Stats", "_Stats") in imports
    assert not any(isinstance(n, ast.ClassDef) and n.name == "_Stats" for n in stub.body)


def test_the_stats_comments_are_the_schemas_meanings():
    """Each key's comment in `oit.Stats` is the meaning the core's schema gives it, word for word."""
    source = inspect.getsource(oit.Stats)
    comments = dict(re.findall(r"^ +(\w+): [^#\n]+# (.+)$", source, re.M))
    assert comments == {name: doc for name, _, doc in oit._oit.stats_schema()}


@pytest.mark.parametrize("method", ["hybrid", "abuffer"])
def test_a_frame_has_the_schemas_keys(renderer, method):
    """Every key of the schema is in a frame's stats, error_bound_max only with a bound."""
    r = renderer(16, 16)
    frame = r.render(build_scene([layer(0.5, (1.0, 0.0, 0.0, 0.5))]), IDENTITY, method=method)
    names = [name for name, _, _ in oit._oit.stats_schema()]
    assert (frame.error_bound is not None) == (method == "hybrid")
    expected = names if frame.error_bound is not None else [n for n in names if n != "error_bound_max"]
    assert list(frame.stats) == expected
    assert frame.stats["adapter"] == r.adapter_info["name"]
    if frame.error_bound is not None:
        assert frame.stats["error_bound_max"] == pytest.approx(float(frame.error_bound.max()))


@pytest.mark.parametrize("method", [m["name"] for m in oit.methods()])
def test_every_extra_a_method_reports_has_a_declared_merge_rule(renderer, method):
    """Tiles and antialiasing samples merge a method's extras by rules declared once in the core."""
    if method not in oit.Renderer(1, 1).adapter_info["methods"]:
        pytest.skip(f"the adapter cannot run {method}")
    rules = dict(oit._oit.extra_merge_rules())
    assert set(rules.values()) <= {"sum", "max", "mean"}
    scene = build_scene([layer(0.3, (1.0, 0.0, 0.0, 0.5)), layer(0.6, (0.0, 0.0, 1.0, 0.5))])
    frame = renderer(16, 16).render(scene, IDENTITY, method=method)
    assert set(frame.stats["extra"]) <= set(rules), set(frame.stats["extra"]) - set(rules)


def test_the_surface_keywords_default_to_the_cores_material():
    """Every surface keyword with a default takes the core's (`Material::default()`), held once."""
    core = oit._oit.surface_defaults()
    assert core == {"shading": "unlit", "specular": 0.0, "shininess": 32.0, "opacity": 1.0, "two_sided": True,
                    "cull_back_faces": False}
    for fn in (oit.Scene.add_mesh, oit.Scene.add_strands, oit.Scene.add_particles, oit.Scene.from_trimesh):
        params = inspect.signature(fn).parameters
        for name, default in core.items():
            if name in params and name != "shading":
                assert params[name].default == default, (fn.__name__, name)
    assert inspect.signature(oit.Scene.add_strands).parameters["shading"].default == core["shading"]
