"""Gaussian splats (issue 44): `Scene.add_gaussians` refuses bad input saying what to do, a
mixed scene of splats and meshes equals the float64 reference through the exact methods, and
a 3DGS PLY written here loads as splats with every field as written (docs/methods.md,
"Gaussian splats")."""

from __future__ import annotations

import struct
import subprocess
import sys

import numpy as np
import pytest

import oit
from scenes import PERSPECTIVE

# float32 footprints and compositing of a few layers against the float64 reference.
TOL = 1e-4
C0 = 0.28209479177387814


def splats(n: int = 30, seed: int = 0) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 4))
    return {
        "means": rng.uniform(-0.8, 0.8, (n, 3)).astype(np.float32),
        "scales": np.stack([rng.uniform(0.03, 0.3, n), rng.uniform(0.02, 0.15, n), rng.uniform(0.005, 0.1, n)], 1),
        "rotations": q / np.linalg.norm(q, axis=1, keepdims=True),
        "opacities": rng.uniform(0.1, 1.0, n),
        "colors": rng.uniform(0.0, 1.0, (n, 3)),
    }


def mixed(seed: int = 0) -> oit.Scene:
    s = oit.Scene()
    s.add_mesh(np.array([[-1, 1, -0.9], [1, 1, -0.9], [0, -1, -0.9]], np.float32), np.array([[0, 1, 2]]),
               [0.7, 0.2, 0.2, 1.0], opaque=True)
    s.add_gaussians(**splats(30, seed))
    s.add_mesh(np.array([[-1, -1, -0.2], [1, -1, 0.3], [0, 1, 0.0]], np.float32), np.array([[0, 1, 2]]),
               [0.1, 0.8, 0.3, 0.45])
    return s


@pytest.mark.parametrize("method", ["abuffer", "depth_peeling"])
def test_a_mixed_scene_of_splats_and_meshes_equals_the_reference(renderer, method):
    scene = mixed(1)
    frame = renderer(48, 48).render(scene, PERSPECTIVE, method)
    assert error(frame, scene, 48) <= TOL
    assert frame.stats["scene_bytes_by_primitive"]["gaussians"] > 0
    assert scene.primitives() == ["triangles", "gaussians", "triangles"]


def error(frame: oit.Frame, scene: oit.Scene, size: int, **kw) -> float:
    ref, ambiguous = oit.reference(scene, PERSPECTIVE, size, size, return_mask=True, **kw)
    assert ambiguous.mean() < 0.1
    err = np.abs(frame.image.astype(np.float64) - ref)
    err[ambiguous] = 0.0
    return float(err.max())


def test_splats_take_instances(renderer):
    # A rotated, unevenly scaled and tinted copy: the covariance goes as A Σ Aᵀ.
    scene = mixed(2)
    c, s = np.cos(0.6), np.sin(0.6)
    scene.add_instances(1, np.array([[[c, -s, 0, 0.2], [s, c, 0, 0.1], [0, 0, 1.5, 0.1], [0, 0, 0, 1]]]), [[1, 0.6, 0.8, 0.9]])
    frame = renderer(48, 48).render(scene, PERSPECTIVE, "abuffer")
    assert error(frame, scene, 48) <= TOL


def test_antialiased_splats_equal_the_antialiased_reference(renderer):
    scene = mixed(3)
    frame = renderer(40, 40).render(scene, PERSPECTIVE, "abuffer", antialias=4)
    assert error(frame, scene, 40, antialias=4) <= TOL


def test_chunks_and_tiles_change_no_splat(renderer):
    scene = mixed(4)
    whole = renderer(48, 48).render(scene, PERSPECTIVE, "abuffer")
    # 512 bytes hold 8 splats' corners (64 bytes each): the set takes 4 chunks.
    chunked = renderer(48, 48, max_binding_bytes=512).render(scene, PERSPECTIVE, "abuffer")
    assert chunked.stats["geometry_chunks"] > 4
    np.testing.assert_array_equal(chunked.image, whole.image)
    budget = whole.stats["target_bytes"] + whole.stats["memory_bytes"] // 3
    tiled = oit.Renderer(48, 48, memory_budget=budget).render(scene, PERSPECTIVE, "abuffer")
    assert tiled.stats["tiles"] > 1
    np.testing.assert_array_equal(tiled.image, whole.image)


@pytest.mark.parametrize("method", [m["name"] for m in oit.methods()])
def test_every_method_renders_splats(renderer, method):
    scene = mixed(5)
    frame = renderer(32, 32).render(scene, PERSPECTIVE, method, census=True)
    assert np.isfinite(frame.image).all()
    assert frame.stats["fragments"] == int(frame.depth_complexity.sum()) > 0
    ref = oit.reference(scene, PERSPECTIVE, 32, 32)
    # Every method draws the same fragments: none is far from the exact picture on average
    # ('additive' sums colors, no transparency answer).
    assert np.abs(frame.image - ref).mean() < (0.15 if method == "additive" else 0.08), method


GOOD = splats(2)


def bad(**kw):
    return lambda s: s.add_gaussians(**{**GOOD, **kw})


@pytest.mark.parametrize("call, match", [
    (bad(means=np.full((2, 3), np.nan)), "not finite"),
    (bad(means=np.zeros((2, 2))), "means must have shape"),
    (bad(scales=np.zeros((2, 3))), "> 0.*np.exp"),
    (bad(scales=np.ones((3, 3))), "scales must have shape \\(2, 3\\)"),
    (bad(rotations=np.zeros((2, 4))), "nonzero wxyz"),
    (bad(rotations=np.ones((2, 3))), "rotations must have shape \\(2, 4\\)"),
    (bad(opacities=[0.5, 1.5]), "\\[0, 1\\].*logits"),
    (bad(opacities=[0.5, 0.5, 0.5]), "one number or \\(2,\\)"),
    (bad(colors=[[0, 0, 2], [0, 0, 0]]), "\\[0, 1\\]"),
    (bad(sh=np.zeros((2, 4, 3))), "colors or sh, not both"),
    (bad(colors=None, sh=np.zeros((2, 5, 3))), "k = 1, 4, 9 or 16"),
    (bad(colors=None, sh=np.zeros((1, 4, 3))), "must have shape \\(2, k, 3\\)"),
    (bad(colors=None, sh=np.full((2, 4, 3), np.nan)), "NaN or Inf"),
])
def test_bad_gaussians_are_refused_with_what_to_do(call, match):
    with pytest.raises(ValueError, match=match):
        call(oit.Scene())


def test_one_row_stands_for_every_splat_and_colors_default_to_white():
    from oit import cli

    s = oit.Scene()
    assert s.add_gaussians(np.zeros((3, 3)), [0.1, 0.1, 0.1], [1, 0, 0, 0], 0.5) == 0
    assert s.primitives() == ["gaussians"]
    assert cli.describe_contents(s) == "3 splats"


PLY_NAMES = ["x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2", "f_rest_0", "opacity",
             "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"]
PLY_ROWS = np.array([
    [0.5, -1.0, 2.0, 0, 0, 1, 0.3, -0.2, 1.0, 9, 0.0, -1.0, -2.0, -3.0, 1.0, 0.0, 0.0, 0.0],
    [1.0, 2.0, 3.0, 0, 1, 0, -5.0, 0.0, 0.5, 9, 2.0, 0.1, 0.2, 0.3, 0.5, 0.5, 0.5, 0.5],
], np.float32)


def write_ply(path):
    """A 3DGS PLY of PLY_ROWS, binary little endian (one f_rest value, read past)."""
    header = "ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
    header += "".join(f"property float {n}\n" for n in PLY_NAMES) + "end_header\n"
    path.write_bytes(header.encode() + b"".join(struct.pack("<18f", *r) for r in PLY_ROWS))
    return path


def test_the_cli_renders_a_3dgs_ply(tmp_path):
    out = tmp_path / "splats.png"
    done = subprocess.run([sys.executable, "-m", "oit", "render", str(write_ply(tmp_path / "s.ply")), "-o", str(out),
                           "--size", "32", "32"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "2 splats" in done.stdout and out.exists()


def test_a_3dgs_ply_loads_as_splats_with_every_field_as_written(tmp_path):
    names, rows = PLY_NAMES, PLY_ROWS
    path = write_ply(tmp_path / "splats.ply")
    scene = oit.Scene.from_file(path)
    assert scene.primitives() == ["gaussians"]
    # The loaded splats render as the same splats added by hand from the decoded fields.
    col = lambda k: rows[:, names.index(k)]  # noqa: E731
    by_hand = oit.Scene()
    by_hand.add_gaussians(
        rows[:, :3],
        np.exp(np.stack([col("scale_0"), col("scale_1"), col("scale_2")], 1)),
        np.stack([col("rot_0"), col("rot_1"), col("rot_2"), col("rot_3")], 1),
        1 / (1 + np.exp(-col("opacity"))),
        np.clip(0.5 + C0 * np.stack([col("f_dc_0"), col("f_dc_1"), col("f_dc_2")], 1), 0, 1),
    )
    cam = oit.Camera.look_at(eye=(1.0, 0.5, 9.0), target=(0.7, 0.5, 2.5), fov_y=40.0, near=1.0, far=20.0)
    a = oit.reference(scene, cam, 32, 32)
    b = oit.reference(by_hand, cam, 32, 32)
    assert np.abs(a - b).max() < 1e-6
    assert a[..., 3].max() > 0.05


def sh_numpy(c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """3DGS's eval_sh (its basis and signs) for coefficients c (k, 3) in unit direction d,
    plus 0.5, clamped to [0, 1]."""
    x, y, z = d
    basis = [0.28209479177387814,
             -0.4886025119029199 * y, 0.4886025119029199 * z, -0.4886025119029199 * x,
             1.0925484305920792 * x * y, -1.0925484305920792 * y * z, 0.31539156525252005 * (2 * z * z - x * x - y * y),
             -1.0925484305920792 * x * z, 0.5462742152960396 * (x * x - y * y),
             -0.5900435899266435 * y * (3 * x * x - y * y), 2.890611442640554 * x * y * z,
             -0.4570457994644658 * y * (4 * z * z - x * x - y * y), 0.3731763325901154 * z * (2 * z * z - 3 * x * x - 3 * y * y),
             -0.4570457994644658 * x * (4 * z * z - x * x - y * y), 1.445305721320277 * z * (x * x - y * y),
             -0.5900435899266435 * x * (x * x - 3 * y * y)]
    return np.clip(0.5 + np.asarray(basis[:len(c)]) @ c, 0.0, 1.0)


@pytest.mark.parametrize("degree", [0, 1, 2, 3])
def test_sh_colors_match_a_numpy_evaluation(renderer, degree):
    k = (degree + 1) ** 2
    rng = np.random.default_rng(degree)
    eye, mean = np.array([0.7, 0.4, 3.0]), np.array([0.1, -0.2, 0.3])
    cam = oit.Camera.look_at(eye=tuple(eye), target=tuple(mean), fov_y=40.0, near=0.5, far=10.0)
    want = []
    for _ in range(3):
        sh = rng.uniform(-0.6, 0.6, (1, k, 3)).astype(np.float32)
        s = oit.Scene()
        s.add_gaussians(mean[None].astype(np.float32), [0.2, 0.1, 0.15], [1, 0, 0, 0], [1.0], sh=sh)
        d = (mean - eye) / np.linalg.norm(mean - eye)
        color = 0.99 * sh_numpy(sh[0].astype(np.float64), d)
        # The mean projects onto the center of pixel (16, 16) of 33 x 33.
        gpu = renderer(33, 33).render(s, cam, "abuffer", background=(0, 0, 0)).image[16, 16, :3]
        ref = oit.reference(s, cam, 33, 33, background=(0, 0, 0))[16, 16, :3]
        np.testing.assert_allclose(ref, color, atol=1e-6)
        np.testing.assert_allclose(gpu, color, atol=2e-5)
        want.append(color)
    assert np.ptp(np.array(want)) > 0.05, "the colors differ from draw to draw"


@pytest.mark.parametrize("harmonics", [False, True])
def test_scene_files_carry_splats(tmp_path, harmonics):
    from oit import scenefile
    from oit.scenes import MeshArrays

    g = splats(12, 7)
    n = len(g["means"])
    colors = np.concatenate([g["colors"], g["opacities"][:, None]], 1).astype(np.float32)
    primitive = {"kind": "gaussians", "scales": g["scales"], "rotations": g["rotations"]}
    if harmonics:
        primitive |= {"sh": np.random.default_rng(1).uniform(-0.5, 0.5, (n, 9, 3)), "degree": 2}
    m = MeshArrays(g["means"], np.zeros((0, 3), np.uint32), colors, False, {}, primitive=primitive)
    path = tmp_path / "splats.oitscene"
    scenefile.save_scene([m], path, camera=PERSPECTIVE)
    back, _, _ = scenefile.load_scene(path)
    assert back[0].primitive["kind"] == "gaussians"
    assert (back[0].primitive["sh"] is not None) == harmonics
    original, again = oit.Scene(), scenefile.scene_of(back)
    m.add_to(original)
    assert again.primitives() == ["gaussians"]
    a = oit.reference(original, PERSPECTIVE, 24, 24)
    b = oit.reference(again, PERSPECTIVE, 24, 24)
    np.testing.assert_array_equal(a, b)
    assert a[..., 3].max() > 0.1


@pytest.mark.parametrize("kind", ["surface", "cloud"])
def test_the_splat_scenes_render_exactly_with_abuffer(renderer, kind):
    """oit.scenes.splats: flat Gaussians on a surface and a faint anisotropic cloud, one set
    each; the A-buffer equals the float64 reference off the ambiguous pixels."""
    built = oit.scenes.splats(2000, kind=kind, seed=3)
    frame = renderer(64, 64).render(built.scene, built.camera, "abuffer")
    ref, ambiguous = oit.reference(built.scene, built.camera, 64, 64, return_mask=True)
    assert frame.stats["max_depth_complexity"] > 4
    err = np.abs(frame.image[..., :3].astype(np.float64) - ref[..., :3])[~ambiguous]
    assert err.max() < 1e-4, err.max()
    again = oit.scenes.splats(2000, kind=kind, seed=3)
    assert np.array_equal(again.meshes[0].positions, built.meshes[0].positions)


def test_the_splat_scenes_refuse_what_they_cannot_build():
    with pytest.raises(ValueError, match="kind must be"):
        oit.scenes.splats(10, kind="smoke")
    with pytest.raises(ValueError, match="count must be at least 1"):
        oit.scenes.splats(0)
