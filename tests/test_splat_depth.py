"""Gaussian splats at the depth of their peak along each pixel's ray (splat_depth="ray", as
StopThePop) beside the mean's (3DGS): the exact methods equal the float64 reference with either
choice, the two orders differ where splats cross, and a bad choice is refused (docs/methods.md,
"Gaussian splats")."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from scenes import PERSPECTIVE
from test_splats import TOL, error, splats

EXACT = ["abuffer", "depth_peeling", "compact_abuffer"]


def mixed_ray(seed: int, depth: str = "ray") -> oit.Scene:
    s = oit.Scene()
    s.add_mesh(np.array([[-1, 1, -0.9], [1, 1, -0.9], [0, -1, -0.9]], np.float32), np.array([[0, 1, 2]]),
               [0.7, 0.2, 0.2, 1.0], opaque=True)
    s.add_gaussians(**splats(30, seed), splat_depth=depth)
    s.add_mesh(np.array([[-1, -1, -0.2], [1, -1, 0.3], [0, 1, 0.0]], np.float32), np.array([[0, 1, 2]]),
               [0.1, 0.8, 0.3, 0.45])
    return s


@pytest.mark.parametrize("method", EXACT)
def test_ray_depth_splats_and_meshes_equal_the_reference(renderer, method):
    scene = mixed_ray(1)
    frame = renderer(48, 48).render(scene, PERSPECTIVE, method)
    assert error(frame, scene, 48) <= TOL


def test_ray_depth_splats_take_instances(renderer):
    scene = mixed_ray(2)
    c, s = np.cos(0.6), np.sin(0.6)
    scene.add_instances(1, np.array([[[c, -s, 0, 0.2], [s, c, 0, 0.1], [0, 0, 1.5, 0.1], [0, 0, 0, 1]]]), [[1, 0.6, 0.8, 0.9]])
    frame = renderer(48, 48).render(scene, PERSPECTIVE, "abuffer")
    assert error(frame, scene, 48) <= TOL


def crossing(depth: str) -> oit.Scene:
    """Two flat splats crossing like an X seen from above the crossing line: red's mean is the
    nearer, so by centers red is in front everywhere; along the rays each is in front on its
    own side of the crossing."""
    s = oit.Scene()
    tilt = 0.5
    rot = [np.cos(tilt / 2), 0.0, np.sin(tilt / 2), 0.0]
    s.add_gaussians(means=[[0.0, 0.0, 0.05], [0.0, 0.0, -0.05]], scales=[[0.5, 0.5, 0.002]] * 2,
                    rotations=[rot, [rot[0], 0.0, -rot[2], 0.0]], opacities=[0.8, 0.8],
                    colors=[[1, 0, 0], [0, 0, 1]], splat_depth=depth)
    return s


def test_crossing_splats_swap_order_along_the_ray_and_not_by_centers(renderer):
    cam = oit.Camera.look_at(eye=(0.0, 0.0, 4.0), target=(0.0, 0.0, 0.0), fov_y=30.0, near=1.0, far=10.0)
    frames = {}
    for depth in ("center", "ray"):
        scene = crossing(depth)
        frame = renderer(64, 64).render(scene, cam, "abuffer")
        ref, ambiguous = oit.reference(scene, cam, 64, 64, return_mask=True)
        err = np.abs(frame.image.astype(np.float64) - ref)
        assert err[~ambiguous].max() <= TOL, depth
        frames[depth] = frame.image
    # Left of the crossing (x < 0) and right of it, near the middle row: by centers red
    # (nearer mean) is in front on both sides; along the ray each side has its own front.
    row = 32
    left, right = (frames[d][row, 20] for d in ("center", "ray")), (frames[d][row, 44] for d in ("center", "ray"))
    (cl, rl), (cr, rr) = left, right
    assert cl[0] > cl[2] and cr[0] > cr[2]
    assert (rl[0] > rl[2]) != (rr[0] > rr[2])


def test_a_bad_splat_depth_is_refused():
    with pytest.raises(ValueError, match="splat_depth must be 'center' or 'ray'"):
        oit.Scene().add_gaussians(**splats(2), splat_depth="peak")


def test_sorted_blends_a_sets_splats_back_to_front_by_their_means(renderer):
    """`sorted` orders a splat set's splats by their means' depth (3DGS): the frame equals a
    numpy back-to-front blend of each splat's own alpha and color (each rendered alone), in
    that order; the set's order would give another picture."""
    n = 10
    data = splats(n, seed=7)
    # Stacked along the view axis in the wrong order (nearest first) and overlapping on screen.
    data["means"][:, 2] = np.linspace(0.8, -0.8, n)
    data["means"][:, :2] *= 0.2
    data["opacities"] = np.full(n, 0.7)
    scene = oit.Scene()
    scene.add_gaussians(**data)
    size, bg = 40, np.array([0.2, 0.3, 0.4])
    r = renderer(size, size)
    frame = r.render(scene, PERSPECTIVE, "sorted", background=bg)
    layers = []
    for k in range(n):
        one = oit.Scene()
        one.add_gaussians(**{key: v[k:k + 1] for key, v in data.items()})
        alpha = r.render(one, PERSPECTIVE, "abuffer", background=bg).image[..., 3].astype(np.float64)
        layers.append(alpha)
    vp = np.asarray(PERSPECTIVE.view_proj, dtype=np.float64)
    clip = np.c_[data["means"].astype(np.float64), np.ones(n)] @ vp.T
    out = np.broadcast_to(bg, (size, size, 3)).copy()
    for k in np.argsort(-clip[:, 2] / clip[:, 3], kind="stable"):
        a = layers[k][..., None]
        out = a * data["colors"][k] + (1 - a) * out
    assert np.abs(frame.image[..., :3] - out).max() < 1e-5
    unsorted = r.render(scene, PERSPECTIVE, "unsorted", background=bg).image[..., :3]
    assert np.abs(unsorted - out).max() > 0.05
