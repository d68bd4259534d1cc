"""Strands and particles (issue 24): ribbons and discs built on the GPU from points give the
coverage and color their model says at single pixels, leave no gap and cover no pixel twice at
a joint, match the float64 reference mixed with meshes through the exact methods, and go
through every method, tiles, chunks and antialiasing; bad sets are refused with what to do."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from scenes import IDENTITY, PERSPECTIVE

WHITE = (1.0, 1.0, 1.0)
# float32 compositing of a few layers against the float64 reference (test_abuffer_reference.py).
TOL = 1e-5


def bent_strand(alpha: float = 0.5) -> oit.Scene:
    """One strand in NDC (identity camera) with a joint at the origin: a 90-degree bend."""
    s = oit.Scene()
    pts = np.array([[-0.8, 0.0, 0.5], [0.0, 0.0, 0.5], [0.0, 0.8, 0.5]], np.float32)
    s.add_strands(pts, [3], 0.25, [0.2, 0.4, 0.8, alpha])
    return s


def mixed(seed: int = 0, shading: str = "unlit", meshes: bool = True) -> oit.Scene:
    """Strands, particles of every falloff and two meshes (`meshes`), crossing in depth (world
    space)."""
    rng = np.random.default_rng(seed)
    s = oit.Scene()
    t = np.linspace(0.0, 1.0, 9)
    pts, counts = [], []
    for i in range(12):
        x0, z0 = rng.uniform(-0.9, 0.9), rng.uniform(-0.4, 0.4)
        pts.append(np.stack([x0 + 0.25 * np.sin(3 * t + i), 0.9 - 1.8 * t, z0 + 0.3 * np.cos(4 * t + i)], 1))
        counts.append(len(t))
    pts = np.concatenate(pts).astype(np.float32)
    colors = np.concatenate([rng.uniform(0.1, 0.9, (len(pts), 3)), rng.uniform(0.2, 0.8, (len(pts), 1))], 1)
    widths = rng.uniform(0.02, 0.06, len(pts))
    s.add_strands(pts, counts, widths, colors, shading=shading, specular=0.4, shininess=20.0)
    for falloff in ("hard", "linear", "gaussian"):
        s.add_particles(rng.uniform(-0.7, 0.7, (6, 3)), rng.uniform(0.1, 0.25, 6), rng.uniform(0.2, 0.9, (6, 4)),
                        falloff=falloff)
    if meshes:
        s.add_mesh(np.array([[-1, -1, -0.2], [1, -1, 0.3], [0, 1, 0.0]], np.float32), np.array([[0, 1, 2]]),
                   [0.1, 0.8, 0.3, 0.45])
        s.add_mesh(np.array([[-1, 1, -0.6], [1, 1, -0.6], [0, -1, -0.6]], np.float32), np.array([[0, 1, 2]]),
                   [0.7, 0.2, 0.2, 1.0], opaque=True)
    if shading != "unlit":
        s.add_light((-0.3, -0.5, -1.0), intensity=0.9)
        s.ambient = (0.15, 0.15, 0.15)
    return s


def against_reference(frame: oit.Frame, scene: oit.Scene, camera: oit.Camera, size: int, **kw) -> float:
    ref, ambiguous = oit.reference(scene, camera, size, size, return_mask=True, **kw)
    assert ambiguous.mean() < 0.1, "too many ambiguous pixels for a meaningful comparison"
    err = np.abs(frame.image.astype(np.float64) - ref)
    err[ambiguous] = 0.0
    return float(err.max())


# ---- single pixels


def test_a_strand_covers_its_ribbon_once_with_no_gap_at_the_joint(renderer):
    r = renderer(64, 64)
    frame = r.render(bent_strand(0.5), IDENTITY, "unsorted", background=WHITE, census=True)
    # One layer of alpha 0.5 covers 0.5 of a pixel (the image's alpha); two would cover 0.75.
    cover = frame.image[..., 3]
    assert set(np.unique(np.round(cover, 6))) <= {0.0, 0.5}, "a pixel is covered twice or partly"
    assert frame.depth_complexity.max() == 1
    # Pixel (row, col) of NDC (x, y): x = (col + 0.5) / 32 - 1, y = 1 - (row + 0.5) / 32.
    # The joint: the inner corner (29, 29) and the outer, chamfered one (33, 32).
    inside = [(31, 8), (31, 28), (31, 31), (30, 32), (20, 32), (8, 32), (29, 29), (33, 32)]
    for rc in inside:
        assert cover[rc] == 0.5, f"pixel {rc} inside the ribbon is not covered"
    for rc in [(24, 10), (40, 40), (10, 45), (31, 62)]:
        assert cover[rc] == 0.0, f"pixel {rc} outside the ribbon is covered"
    expected = 0.5 * np.array([0.2, 0.4, 0.8]) + 0.5
    np.testing.assert_allclose(frame.image[31, 10, :3], expected, atol=1e-6)


@pytest.mark.parametrize("falloff", ["hard", "linear", "gaussian"])
def test_a_particle_has_the_coverage_and_color_of_its_falloff(renderer, falloff):
    s = oit.Scene()
    s.add_particles([[0.0, 0.0, 0.5]], 0.5, [0.9, 0.3, 0.1, 0.8], falloff=falloff)
    frame = renderer(64, 64).render(s, IDENTITY, "abuffer", background=WHITE)
    model = {"hard": lambda r: 1.0, "linear": lambda r: 1.0 - r, "gaussian": lambda r: np.exp(-4.5 * r * r)}[falloff]
    for row, col in [(31, 31), (31, 40), (20, 31), (25, 38), (31, 46), (31, 48), (10, 10), (31, 60)]:
        x, y = (col + 0.5) / 32 - 1, 1 - (row + 0.5) / 32
        r = np.hypot(x, y) / 0.5
        a = 0.8 * model(r) if r <= 1 else 0.0
        expected = a * np.array([0.9, 0.3, 0.1]) + (1 - a)
        np.testing.assert_allclose(frame.image[row, col, :3], expected, atol=2e-6, err_msg=f"pixel {(row, col)}, r = {r:.3f}")


# ---- against the reference


@pytest.mark.parametrize("method", ["abuffer", "pall", "compact_abuffer", "depth_peeling"])
@pytest.mark.parametrize("shading", ["unlit", "hair"])
def test_a_mixed_scene_equals_the_reference(renderer, method, shading):
    scene = mixed(1, shading)
    frame = renderer(48, 48).render(scene, PERSPECTIVE, method)
    assert against_reference(frame, scene, PERSPECTIVE, 48) <= TOL


def test_strands_and_particles_take_instances(renderer):
    scene = mixed(2)
    scene.add_instances(0, np.array([[[1, 0, 0, 0.3], [0, 1, 0, 0], [0, 0, 1, 0.2], [0, 0, 0, 1]]]), [[1, 0.5, 0.5, 1]])
    scene.add_instances(1, np.array([[[0.5, 0, 0, 0], [0, 0.5, 0, 0.2], [0, 0, 0.5, 0], [0, 0, 0, 1]]]))
    frame = renderer(48, 48).render(scene, PERSPECTIVE, "abuffer")
    assert against_reference(frame, scene, PERSPECTIVE, 48) <= TOL


def test_antialiased_strands_equal_the_antialiased_reference(renderer):
    scene = mixed(3)
    frame = renderer(40, 40).render(scene, PERSPECTIVE, "abuffer", antialias=4)
    assert against_reference(frame, scene, PERSPECTIVE, 40, antialias=4) <= TOL


def test_chunks_and_tiles_change_nothing(renderer):
    scene = mixed(4, "hair")
    whole = renderer(48, 48).render(scene, PERSPECTIVE, "abuffer")
    chunked = renderer(48, 48, max_binding_bytes=2048).render(scene, PERSPECTIVE, "abuffer")
    assert chunked.stats["geometry_chunks"] > 3
    np.testing.assert_array_equal(chunked.image, whole.image)
    budget = whole.stats["target_bytes"] + whole.stats["memory_bytes"] // 3
    tiled = oit.Renderer(48, 48, memory_budget=budget).render(scene, PERSPECTIVE, "abuffer")
    assert tiled.stats["tiles"] > 1
    np.testing.assert_array_equal(tiled.image, whole.image)


@pytest.mark.parametrize("method", ["abuffer", "compact_abuffer", "unsorted"])
def test_sets_alone_draw_as_they_do_beside_meshes(renderer, method):
    # A scene of sets alone compiles without the mesh side (SETS_ONLY); the same sets beside a
    # mesh that draws nothing (behind the eye) go through the other side: the same picture.
    alone, beside = mixed(7, "hair", meshes=False), mixed(7, "hair", meshes=False)
    beside.add_mesh(np.array([[0, 0, 5], [1, 0, 5], [0, 1, 5]], np.float32), np.array([[0, 1, 2]]), [1, 1, 1, 0.5])
    a, b = (renderer(32, 32).render(s, PERSPECTIVE, method, census=True) for s in (alone, beside))
    assert a.stats["fragments"] == b.stats["fragments"] > 0
    np.testing.assert_array_equal(a.image, b.image)


def test_corners_are_built_again_only_when_the_view_changes(renderer):
    # The expansion runs when the camera (or the scene) changed since the corners were built,
    # and its absence changes nothing: each frame equals a fresh renderer's.
    scene = mixed(8, "hair")
    other = oit.Camera.look_at(eye=(-1.5, 0.8, 3.5), target=(0.0, 0.0, 0.0), fov_y=45.0, near=1.0, far=10.0)
    r = renderer(40, 40)
    frames = [r.render(scene, cam, "abuffer") for cam in (PERSPECTIVE, PERSPECTIVE, other, PERSPECTIVE)]
    expanded = ["expand" in f.stats["pass_times_ms"] for f in frames]
    if frames[0].stats["pass_times_ms"]:  # the adapter times passes
        assert expanded == [True, False, True, True]
    for f, cam in zip(frames, (PERSPECTIVE, PERSPECTIVE, other, PERSPECTIVE)):
        np.testing.assert_array_equal(f.image, renderer(40, 40).render(scene, cam, "abuffer").image)
    assert not np.array_equal(frames[0].image, frames[2].image)
    scene.add_particles(np.zeros((1, 3), np.float32), 0.3, [1.0, 0.0, 0.0, 0.5])  # a changed scene
    moved = r.render(scene, PERSPECTIVE, "abuffer")
    np.testing.assert_array_equal(moved.image, renderer(40, 40).render(scene, PERSPECTIVE, "abuffer").image)


@pytest.mark.parametrize("method", ["abuffer", "hybrid", "hybrid64", "compact_abuffer"])
def test_sets_in_any_order_give_the_same_bits(renderer, method):
    # The smoke's particles and the hair's strands submitted in another order: the methods that
    # promise order independence (test_stability.py for triangles) keep it for sets.
    rng = np.random.default_rng(3)
    hair, smoke = oit.scenes.hair(strands=120), oit.scenes.smoke(particles=150)
    (h,), (p,) = hair.meshes, smoke.meshes
    counts = h.primitive["counts"]
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    order = rng.permutation(len(counts))
    points = np.concatenate([np.arange(starts[i], starts[i] + counts[i]) for i in order])
    strands = oit.scenes.MeshArrays(h.positions[points], h.indices, h.colors[points], surface=h.surface,
                                    primitive={**h.primitive, "counts": counts[order], "widths": h.primitive["widths"][points]})
    q = rng.permutation(len(p.positions))
    particles = oit.scenes.MeshArrays(p.positions[q], p.indices, p.colors[q],
                                      primitive={**p.primitive, "radii": p.primitive["radii"][q]})
    for (a, b), built in [((h, strands), hair), ((p, particles), smoke)]:
        frames = [renderer(48, 48).render(oit.scenes.from_meshes([m], built.camera, lights=built.lights,
                                                                   ambient=built.ambient).scene, built.camera, method)
                  for m in (a, b)]
        np.testing.assert_array_equal(frames[0].image, frames[1].image)


@pytest.mark.parametrize("method", [m["name"] for m in oit.methods()])
def test_every_method_renders_strands_and_particles(renderer, method):
    scene = mixed(5, "hair")
    frame = renderer(32, 32).render(scene, PERSPECTIVE, method, census=True)
    assert np.isfinite(frame.image).all()
    assert frame.stats["fragments"] == int(frame.depth_complexity.sum()) > 0
    ref = oit.reference(scene, PERSPECTIVE, 32, 32)
    # Every method draws the same fragments: none is far from the exact picture on average.
    assert np.abs(frame.image - ref).mean() < 0.08, method


def test_to_triangles_draws_the_same_picture(renderer):
    scene = mixed(6, "hair")
    assert scene.primitives() == ["strands", "particles", "particles", "particles", "triangles", "triangles"]
    strands, triangles = oit.Scene(), oit.Scene()
    for s in (strands, triangles):
        s.add_light(*scene.lights[0])
        s.ambient = scene.ambient
    t = scene.to_triangles(0, PERSPECTIVE)
    assert t["indices"].shape == (len(t["positions"]) // 3, 3) and t["uvs"] is None
    points = scene.to_triangles(1, PERSPECTIVE)
    assert points["normals"] is None and np.abs(points["uvs"]).max() == 1.0
    # The same strands as a strand set and as the triangles it is drawn as.
    rng = np.random.default_rng(6)
    pts = (np.cumsum(rng.normal(0, 0.15, (40, 3)), 0) - [0.0, 0.0, 0.3]).astype(np.float32)
    colors = rng.uniform(0.2, 0.9, (40, 4)).astype(np.float32)
    strands.add_strands(pts, [10, 10, 20], 0.15, colors, shading="hair", specular=0.4, shininess=20.0)
    t = strands.to_triangles(0, PERSPECTIVE)
    triangles.add_mesh(t["positions"], t["indices"], t["colors"], normals=t["normals"], shading="hair", specular=0.4,
                       shininess=20.0)
    a = renderer(48, 48).render(strands, PERSPECTIVE, "abuffer")
    b = renderer(48, 48).render(triangles, PERSPECTIVE, "abuffer")
    _, ambiguous = oit.reference(strands, PERSPECTIVE, 48, 48, return_mask=True)
    assert a.stats["fragments"] > 100
    assert np.abs(a.image - b.image)[~ambiguous].max() <= TOL


# ---- what they cost and what they refuse


def test_strands_upload_their_points_not_triangles(renderer):
    rng = np.random.default_rng(7)
    pts = rng.uniform(-0.5, 0.5, (300, 3)).astype(np.float32)
    strands = oit.Scene()
    strands.add_strands(pts, [10] * 30, 0.02, rng.uniform(0.2, 0.9, (300, 4)))
    t = strands.to_triangles(0, PERSPECTIVE)
    triangles = oit.Scene()
    triangles.add_mesh(t["positions"], t["indices"], t["colors"])
    a = renderer(32, 32).render(strands, PERSPECTIVE, "unsorted")
    b = renderer(32, 32).render(triangles, PERSPECTIVE, "unsorted")
    # Uploaded: x, y, z, half width and RGBA a point (32 bytes), and a word a segment (4 bytes);
    # built on the GPU each frame: two corners and a tangent a point (48 bytes).
    assert a.stats["expanded_bytes"] == 300 * 48 and b.stats["expanded_bytes"] == 0
    assert a.stats["scene_bytes"] - a.stats["expanded_bytes"] == 300 * 32 + 270 * 4
    assert a.stats["scene_bytes_by_primitive"] == {"triangles": 0.0, "strands": a.stats["scene_bytes"], "particles": 0.0, "gaussians": 0.0}
    assert b.stats["scene_bytes"] >= 4 * (a.stats["scene_bytes"] - a.stats["expanded_bytes"])
    assert b.stats["scene_bytes"] > a.stats["scene_bytes"]


@pytest.mark.parametrize("call, match", [
    (lambda s: s.add_strands(np.zeros((3, 3)), [1, 2], 0.1, [1, 1, 1, 1]), "at least two points"),
    (lambda s: s.add_strands(np.zeros((3, 3)), [2], 0.1, [1, 1, 1, 1]), "add up to 2"),
    (lambda s: s.add_strands(np.zeros((2, 3)), [2], 0.0, [1, 1, 1, 1]), "> 0"),
    (lambda s: s.add_strands(np.zeros((2, 3)), [2], [0.1, 0.1, 0.1], [1, 1, 1, 1]), "3 entries for 2 points"),
    (lambda s: s.add_strands(np.full((2, 3), np.nan), [2], 0.1, [1, 1, 1, 1]), "not finite"),
    (lambda s: s.add_strands(np.zeros((2, 3)), [2], 0.1, [1, 1, 1, 2]), "outside \\[0, 1\\]"),
    (lambda s: s.add_strands(np.zeros((2, 3)), [2], 0.1, [1, 1, 1, 1], shading="smooth"), "'unlit' or 'hair'"),
    (lambda s: s.add_strands(np.zeros((2, 3)), [-2], 0.1, [1, 1, 1, 1]), "counts has an entry -2"),
    (lambda s: s.add_particles(np.zeros((2, 3)), 0.1, [1, 1, 1, 1], falloff="soft"), "'hard', 'linear' or 'gaussian'"),
    (lambda s: s.add_particles(np.zeros((2, 3)), -1.0, [1, 1, 1, 1]), "> 0"),
    (lambda s: s.add_particles(np.zeros((2, 3)), 0.1, np.ones((3, 4))), "colors has 3 rows"),
    (lambda s: s.add_particles(np.zeros((2, 3)), 0.1, [1, 1, 1, 1], opacity=2.0), "opacity"),
    (lambda s: s.add_mesh(np.zeros((3, 3)), [[0, 1, 2]], [1, 1, 1, 1], shading="hair"), "pass the tangents as normals"),
])
def test_bad_sets_are_refused_with_what_to_do(call, match):
    with pytest.raises(ValueError, match=match):
        call(oit.Scene())


def test_bad_array_types_are_refused():
    with pytest.raises(TypeError, match="counts must be an integer array"):
        oit.Scene().add_strands(np.zeros((2, 3)), [2.0], 0.1, [1, 1, 1, 1])
    with pytest.raises(ValueError, match="points must have shape"):
        oit.Scene().add_strands(np.zeros((2, 2)), [2], 0.1, [1, 1, 1, 1])


def test_hair_and_smoke_built_on_strands_and_particles_look_as_their_triangles(renderer):
    r = renderer(64, 64)
    for build, kinds in [(oit.scenes.hair, ("ribbons", "strands")), (oit.scenes.smoke, ("fans", "particles"))]:
        a, b = (build(**({"strands": 400} if build is oit.scenes.hair else {"particles": 150}), primitive=k) for k in kinds)
        assert b.scene.primitives() == [kinds[1]] and b.meta["primitive"] == kinds[1]
        assert a.scene.triangle_count == b.scene.triangle_count or build is oit.scenes.smoke
        fa, fb = r.render(a.scene, a.camera, "abuffer"), r.render(b.scene, b.camera, "abuffer")
        # The same look: ribbons facing +z against ribbons facing the eye, fans against discs.
        assert np.abs(fa.image - fb.image).mean() < 0.02, build.__name__
        uploaded = fb.stats["scene_bytes"] - fb.stats["expanded_bytes"]
        assert uploaded * 3 <= fa.stats["scene_bytes"], build.__name__
        assert fb.stats["scene_bytes"] < fa.stats["scene_bytes"], build.__name__
    with pytest.raises(ValueError, match="primitive must be one of"):
        oit.scenes.hair(strands=10, primitive="cards")


def test_peers_get_triangles_that_look_as_the_sets(renderer):
    # drawn_meshes() gives peers triangles: strand hair lit as the ribbons are (the highlight
    # baked into the normals), smoke as fans whose rim carries the falloff.
    r = renderer(64, 64)
    for build, kinds in [(oit.scenes.hair, ("ribbons", "strands")), (oit.scenes.smoke, ("fans", "particles"))]:
        a, b = (build(**({"strands": 400} if build is oit.scenes.hair else {"particles": 150}), primitive=k) for k in kinds)
        peer = oit.scenes.from_meshes(b.drawn_meshes(), b.camera, b.size, lights=b.lights, ambient=b.ambient)
        assert peer.scene.primitives() == ["triangles"] * len(peer.meshes)
        assert all(m.surface.get("shading") != "hair" for m in peer.meshes)
        fa, fb, fp = (r.render(x.scene, x.camera, "abuffer").image for x in (a, b, peer))
        assert np.abs(fa - fp).mean() < 0.02 and np.abs(fb - fp).mean() < 0.02, build.__name__


def test_unlit_keeps_strand_and_particle_sets(renderer):
    # scenes.unlit drops the surfaces, not the sets: unlit strands still draw their ribbons.
    r = renderer(64, 64)
    for built in (oit.scenes.hair(strands=40, primitive="strands"), oit.scenes.smoke(particles=60, primitive="particles")):
        plain = oit.scenes.unlit(built)
        assert plain.scene.primitives() == built.scene.primitives()
        assert not oit.scenes.is_lit(plain)
        lit, flat = (r.render(b.scene, b.camera, "abuffer") for b in (built, plain))
        assert flat.stats["fragments"] == lit.stats["fragments"] > 0
        assert against_reference(flat, plain.scene, plain.camera, 64) < TOL


# ---- files


def test_a_ply_of_points_loads_as_particles(tmp_path, renderer):
    from files import ply_points

    path = ply_points(tmp_path / "points.ply")
    scene = oit.Scene.from_file(path)
    assert scene.primitives() == ["particles"] and scene.triangle_count == 6
    # By default 1/200 of the box's diagonal; the points' colors are kept.
    t = scene.to_triangles(0, IDENTITY)
    diagonal = np.linalg.norm(np.array([0.5, 0.5, 0.2]) - [-0.5, 0.0, 0.0])
    corner = np.linalg.norm(t["positions"][:6] - [-0.5, 0.0, 0.0], axis=1)
    np.testing.assert_allclose(corner, diagonal / 200 * np.sqrt(2), rtol=1e-5)
    np.testing.assert_allclose(t["colors"][0], [1.0, 0.0, 0.0, 128 / 255], rtol=1e-6)
    big = oit.Scene.from_file(path, point_radius=0.25)
    frame = renderer(64, 64).render(big, IDENTITY, "abuffer", background=WHITE)
    ref = oit.reference(big, IDENTITY, 64, 64, background=WHITE)
    assert np.abs(frame.image - ref).max() <= TOL
    # The red point's disc at NDC (-0.5, 0): row 31, column 16; radius 0.25 is 8 pixels.
    assert frame.image[31, 16, 0] > 0.9 and frame.image[31, 16, 1] < 0.6
    assert np.all(frame.image[31, 26, :3] == 1.0)
    with pytest.raises(ValueError, match="radius"):
        oit.Scene.from_file(path, point_radius=-1.0)


def test_a_hair_file_loads_as_strands(tmp_path, renderer):
    from oit.hairfile import read_hair, write_hair

    rng = np.random.default_rng(9)
    pts = np.cumsum(rng.normal(0, 0.1, (30, 3)), 0).astype(np.float32)
    colors = rng.uniform(0.2, 0.9, (30, 4)).astype(np.float32)
    path = tmp_path / "model.hair"
    write_hair(path, pts, [10, 20], widths=np.full(30, 0.05, np.float32), colors=colors)
    scene = oit.Scene.from_file(path)
    assert scene.primitives() == ["strands"] and scene.mesh_names == ["model"]
    assert scene.triangle_count == 2 * 28
    # The file keeps transparency, 1 - alpha: the colors as read back, to the bit.
    h = read_hair(path)
    np.testing.assert_allclose(h.colors, colors, atol=1e-7)
    direct = oit.Scene()
    direct.add_strands(pts, [10, 20], 0.05, h.colors, shading="hair", specular=0.25, shininess=48.0)
    a = renderer(48, 48).render(scene, PERSPECTIVE, "abuffer")
    b = renderer(48, 48).render(direct, PERSPECTIVE, "abuffer")
    np.testing.assert_array_equal(a.image, b.image)


def test_scene_files_carry_strands_and_particles(tmp_path, renderer):
    from oit import scenefile

    hair = oit.scenes.hair(strands=60, primitive="strands")
    smoke = oit.scenes.smoke(particles=40, primitive="particles")
    meshes = hair.meshes + smoke.meshes
    path = tmp_path / "mixed.oitscene"
    scenefile.save_scene(meshes, path, camera=hair.camera, lights=hair.lights, ambient=hair.ambient)
    assert path.read_bytes()[8:12] == (3).to_bytes(4, "little")
    back, camera, _ = scenefile.load_scene(path)
    lights, ambient = scenefile.load_lights(path)
    assert [m.primitive["kind"] for m in back] == ["strands", "particles"]
    original = oit.scenes.from_meshes(meshes, hair.camera, lights=hair.lights, ambient=hair.ambient)
    again = scenefile.scene_of(back, lights, ambient)
    assert again.primitives() == ["strands", "particles"]
    a = renderer(48, 48).render(original.scene, camera, "abuffer")
    b = renderer(48, 48).render(again, camera, "abuffer")
    np.testing.assert_array_equal(a.image, b.image)
    # Peers get triangles: each segment two, each particle a fan.
    drawn = original.drawn_meshes()
    assert [len(m.indices) for m in drawn] == [original.scene.triangle_count - 80, 40 * oit.scenes.PEER_FAN_SEGMENTS]


def test_compare_and_render_take_strand_and_point_files(tmp_path):
    import csv
    import subprocess
    import sys

    from files import ply_points
    from oit.hairfile import write_hair

    rng = np.random.default_rng(11)
    hair = tmp_path / "model.hair"
    write_hair(hair, np.cumsum(rng.normal(0, 0.1, (60, 3)), 0).astype(np.float32), [20, 40], widths=0.04)
    for path in (hair, ply_points(tmp_path / "points.ply")):
        out = tmp_path / path.stem
        done = subprocess.run([sys.executable, "-m", "oit", "compare", str(path), "--size", "24", "24", "--views", "1",
                               "--methods", "abuffer", "unsorted", "--no-plots", "--out", str(out)],
                              cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        with open(out / "compare.csv") as f:
            rows = list(csv.DictReader(f))
        assert {r["method"] for r in rows} == {"abuffer", "unsorted"}
        done = subprocess.run([sys.executable, "-m", "oit", "render", str(path), "--size", "24", "24", "-o", str(out / "r.png")],
                              cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        assert (out / "r.png").stat().st_size > 0
