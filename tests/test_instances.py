"""Transforms and instancing: a mesh drawn under n transforms, from one uploaded copy, renders
what n transformed copies render. Transforms and positions here are dyadic (signed
permutations, scales by powers of two, translations by eighths; vertices on a 1/64 grid), so
that every transformed vertex is exact in float32 and the instanced frame must equal the copies'
frame bit for bit, for every method: same coverage, same drawn order, same triangle keys."""

from __future__ import annotations

import numpy as np
import pytest

import oit

WIDTH, HEIGHT = 40, 32
CAMERA = oit.Camera.look_at(eye=(0.3, 0.4, 6.0), target=(0.0, 0.0, 0.0), fov_y=40.0, aspect=WIDTH / HEIGHT)
EXACT = [m["name"] for m in oit.methods() if m["exact"]]


def dyadic_mesh(seed: int, triangles: int = 6):
    rng = np.random.default_rng(seed)
    positions = (rng.integers(-48, 49, size=(3 * triangles, 3)) / 64.0).astype(np.float32)
    indices = np.arange(3 * triangles, dtype=np.uint32).reshape(-1, 3)
    colors = rng.integers(1, 16, size=(3 * triangles, 4)) / 16.0
    colors[:, 3] = rng.integers(2, 14, size=3 * triangles) / 16.0
    return positions, indices, colors.astype(np.float32)


def dyadic_transforms(seed: int, n: int) -> np.ndarray:
    """Signed axis permutations times powers of two, translated by eighths; the first mirrors."""
    rng = np.random.default_rng(seed)
    out = np.zeros((n, 4, 4))
    for i in range(n):
        perm = rng.permutation(3)
        signs = rng.choice([-1.0, 1.0], size=3)
        if i == 0:
            signs[:] = (-1.0, 1.0, 1.0)  # a mirror
        elif np.prod(signs) < 0:
            signs[0] = -signs[0]
        scale = 2.0 ** rng.integers(-1, 2)
        out[i, :3, :3] = np.eye(3)[perm] * signs[:, None] * scale
        out[i, :3, 3] = rng.integers(-12, 13, size=3) / 8.0
        out[i, 3, 3] = 1.0
    return out


def factors(n: int) -> np.ndarray:
    """RGBA factors that are powers of two: products stay exact."""
    f = np.ones((n, 4), dtype=np.float32)
    f[1::2, 0] = 0.5
    f[2::3, 3] = 0.5
    return f


def pair(seed: int, n: int = 5, opaque: bool = True, triangles: int = 6):
    """(instanced scene, scene of transformed copies): one mesh n times, and an opaque mesh placed
    by a transform, after a plain mesh."""
    pos, idx, col = dyadic_mesh(seed, triangles)
    plain_pos, plain_idx, plain_col = dyadic_mesh(seed + 100, triangles=3)
    t, f = dyadic_transforms(seed, n), factors(n)
    inst, copies = oit.Scene(), oit.Scene()
    for s in (inst, copies):
        s.add_mesh(plain_pos, plain_idx, plain_col)
    m = inst.add_mesh(pos, idx, col)
    inst.set_instances(m, t, f)
    for ti, fi in zip(t, f):
        world = pos.astype(np.float64) @ ti[:3, :3].T + ti[:3, 3]
        copies.add_mesh(world.astype(np.float32), idx, col * fi)
    if opaque:
        o_pos, o_idx, o_col = dyadic_mesh(seed + 200, triangles=2)
        o_col[:, 3] = 1.0
        place = np.eye(4)
        place[:3, 3] = (0.0, 0.0, -1.5)
        inst.add_mesh(o_pos, o_idx, o_col, opaque=True, transform=place)
        copies.add_mesh(o_pos + np.float32([0.0, 0.0, -1.5]), o_idx, o_col, opaque=True)
    return inst, copies


def test_counts_and_bounds():
    inst, copies = pair(0)
    assert inst.triangle_count == copies.triangle_count == 3 + 5 * 6 + 2
    assert inst.unique_triangle_count == 3 + 6 + 2
    assert inst.instance_count == 1 + 5 + 1
    np.testing.assert_allclose(inst.bounds[0], copies.bounds[0], atol=1e-6)
    np.testing.assert_allclose(inst.bounds[1], copies.bounds[1], atol=1e-6)
    t, f = inst.instances(1)
    np.testing.assert_array_equal(t, dyadic_transforms(0, 5))
    np.testing.assert_array_equal(f, factors(5))


@pytest.mark.parametrize("method", [m["name"] for m in oit.methods()])
def test_every_method_renders_instances_as_copies(renderer, method):
    inst, copies = pair(1)
    r = renderer(WIDTH, HEIGHT)
    a = r.render(inst, CAMERA, method, census=True)
    b = r.render(copies, CAMERA, method, census=True)
    np.testing.assert_array_equal(a.depth_complexity, b.depth_complexity)
    np.testing.assert_array_equal(a.image, b.image, err_msg=method)
    assert a.stats["instances"] == 7 and b.stats["instances"] == 7
    assert a.stats["scene_bytes"] < b.stats["scene_bytes"] + 7 * 144


@pytest.mark.parametrize("method", ["abuffer", "hybrid", "pall", "compact_abuffer", "sorted", "unsorted", "stochastic"])
def test_instances_in_tiles_chunks_and_samples(renderer, method):
    inst, copies = pair(2, n=9)
    budget = oit.Renderer(WIDTH, HEIGHT, memory_budget=96 * 1024)
    for r, kw in ((budget, {}), (renderer(WIDTH, HEIGHT), dict(antialias=4))):
        a = r.render(inst, CAMERA, method, census=True, **kw)
        b = r.render(copies, CAMERA, method, census=True, **kw)
        np.testing.assert_array_equal(a.image, b.image, err_msg=f"{method} {kw}")
        if r is budget:
            assert a.stats["tiles"] > 1, a.stats["tiles"]
    # Chunks of 2 KiB: the instanced mesh is split across chunks, drawn instance by instance.
    inst, copies = pair(2, n=9, triangles=40)
    small = renderer(WIDTH, HEIGHT, max_binding_bytes=2048)
    a = small.render(inst, CAMERA, method, census=True)
    b = small.render(copies, CAMERA, method, census=True)
    assert a.stats["geometry_chunks"] > 1
    np.testing.assert_array_equal(a.image, b.image, err_msg=f"{method} chunked")


def test_reference_places_instances():
    inst, copies = pair(3)
    a = oit.reference(inst, CAMERA, WIDTH, HEIGHT)
    b = oit.reference(copies, CAMERA, WIDTH, HEIGHT)
    np.testing.assert_array_equal(a, b)


def rotation(axis, angle: float, scale=(1.0, 1.0, 1.0), offset=(0.0, 0.0, 0.0)) -> np.ndarray:
    axis = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    r = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    m = np.eye(4)
    m[:3, :3] = r @ np.diag(scale)
    m[:3, 3] = offset
    return m


@pytest.mark.parametrize("method", EXACT)
def test_exact_methods_match_the_reference_on_lit_culled_instances(renderer, method):
    # General transforms (rotations, non-uniform scales, a mirror) of a lit, back-face-culled
    # sphere: normals by the inverse transpose, culling flipped under the mirror.
    from oit import geometry

    pos, idx = geometry.uv_sphere(radius=0.6, rings=8, segments=12)
    col = np.tile(np.float32([0.8, 0.5, 0.3, 0.45]), (len(pos), 1))
    scene = oit.Scene()
    m = scene.add_mesh(pos, idx, col, shading="smooth", specular=0.3, cull_back_faces=True, two_sided=False)
    t = np.stack([
        rotation((0, 1, 0), 0.3, (1.0, 1.5, 0.7), (-0.8, 0.1, 0.0)),
        rotation((1, 1, 0), 1.1, (0.8, 0.8, 0.8), (0.7, -0.2, 0.3)),
        rotation((0, 0, 1), 0.0, (-1.0, 1.0, 1.0), (0.0, 0.5, -0.4)),
    ])
    scene.set_instances(m, t, np.float32([[1, 1, 1, 1], [0.5, 1, 1, 1], [1, 1, 0.5, 0.8]]))
    frame = renderer(48, 40).render(scene, CAMERA, method)
    ref, ambiguous = oit.reference(scene, CAMERA, 48, 40, return_mask=True)
    err = np.abs(frame.image.astype(np.float64) - ref)
    err[ambiguous] = 0.0
    # The transform runs in float32 on the GPU and in float64 here: positions and normals
    # differ by a few ulps, and shading by ~1e-6 (the same tolerance as the exact family's).
    assert ambiguous.mean() < 0.15
    assert err.max() <= 1e-4, (method, err.max())


def test_a_mirror_keeps_the_outside_outside(renderer):
    # A back-face-culled closed mesh shows the same coverage mirrored as not: its outside stays
    # its front, as glTF asks of nodes with a negative determinant.
    from oit import geometry

    pos, idx = geometry.uv_sphere(radius=0.8, rings=8, segments=12)
    col = np.tile(np.float32([0.2, 0.6, 0.9, 0.5]), (len(pos), 1))
    counts = []
    for sign in (1.0, -1.0):
        scene = oit.Scene()
        m = np.diag([sign, 1.0, 1.0, 1.0])
        scene.add_mesh(pos, idx, col, shading="smooth", cull_back_faces=True, transform=m)
        counts.append(renderer(32, 32).render(scene, CAMERA, "abuffer", census=True).stats["fragments"])
    assert counts[0] == counts[1] > 0


def test_zero_instances_draw_nothing(renderer):
    pos, idx, col = dyadic_mesh(4)
    scene = oit.Scene()
    m = scene.add_mesh(pos, idx, col)
    scene.set_instances(m, np.zeros((0, 4, 4)))
    assert scene.triangle_count == 0 and scene.unique_triangle_count == 6 and scene.bounds is None
    frame = renderer(16, 16).render(scene, CAMERA, "abuffer", census=True)
    assert frame.stats["fragments"] == 0


@pytest.mark.parametrize(
    "transforms, colors, error, match",
    [
        (np.zeros((2, 3, 4)), None, ValueError, r"shape \(n, 4, 4\)"),
        (np.full((1, 4, 4), np.nan), None, ValueError, "NaN or Inf"),
        (np.ones((1, 4, 4)), None, ValueError, "affine"),
        (np.eye(4)[None], np.float32([[1, 1, 1, 2]]), ValueError, r"outside \[0, 1\]"),
        (np.eye(4)[None].repeat(2, 0), np.ones((3, 4)), ValueError, r"colors has 3 rows but transforms has 2"),
        (np.array([[["a"] * 4] * 4]), None, TypeError, "float array"),
    ],
)
def test_bad_instances_are_refused(transforms, colors, error, match):
    pos, idx, col = dyadic_mesh(5)
    scene = oit.Scene()
    m = scene.add_mesh(pos, idx, col)
    with pytest.raises(error, match=match):
        scene.add_instances(m, transforms, colors)
    with pytest.raises(ValueError, match="out of range"):
        scene.add_instances(3, np.eye(4))
    with pytest.raises(ValueError, match=r"shape \(4, 4\)"):
        scene.add_mesh(pos, idx, col, transform=np.eye(3))
    assert scene.instance_count == 1


def test_dragons_upload_one_dragon_and_render_as_its_copies(renderer):
    # The 22 dragons are one mesh and 22 translations. Copies translated in float32, as the
    # vertex shader translates (1 * x + 0 * y + 0 * z + t rounds once), cover the same pixels;
    # the shading normal is renormalized under an instance (a unit float32 vector moves by an
    # ulp at most), so lit pixels may differ by ~1e-7.
    from oit import scenes

    built = scenes.dragons(max_triangles=600)
    assert built.scene.unique_triangle_count * 22 == built.scene.triangle_count
    (dragon,) = built.meshes
    copies = []
    for t, f in zip(dragon.transforms, dragon.instance_colors):
        pos = dragon.positions + t[:3, 3].astype(np.float32)
        copies.append(scenes.MeshArrays(pos, dragon.indices, dragon.colors * f, False, dict(dragon.surface)))
    flat = scenes.from_meshes(copies, built.camera, lights=built.lights, ambient=built.ambient)
    r = renderer(64, 64)
    for method in EXACT:
        a = r.render(built.scene, built.camera, method, census=True)
        b = r.render(flat.scene, flat.camera, method, census=True)
        np.testing.assert_array_equal(a.depth_complexity, b.depth_complexity)
        assert np.abs(a.image - b.image).max() <= 1e-5, method
        assert a.stats["scene_bytes"] < b.stats["scene_bytes"] / 10
