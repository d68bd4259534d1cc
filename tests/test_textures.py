"""Textures as GPU textures (docs/shading.md, "Sampling"): a mipmapped checker on a floor that
recedes to the horizon, so one frame spans magnification and a dozen mip levels, through every
exact method against the float64 reference; the mips average what a pixel covers; an image is
uploaded once however many meshes use it, at 4 bytes a texel plus its mips."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from test_shading import assert_within_the_shading_bound

SIZE = 64


def checker(n: int = 64, cells: int = 8) -> np.ndarray:
    """An n x n uint8 checker of red and white cells (sRGB), alpha 255 and 128."""
    i = (np.arange(n)[:, None] // (n // cells) + np.arange(n)[None, :] // (n // cells)) % 2
    tex = np.zeros((n, n, 4), np.uint8)
    tex[i == 0] = [230, 40, 30, 255]
    tex[i == 1] = [255, 255, 255, 128]
    return tex


def floor_scene(repeat: float = 12.0, meshes: int = 1, shading: str = "smooth") -> tuple[oit.Scene, oit.Camera]:
    p = np.array([[-10, 0, -30], [10, 0, -30], [10, 0, 2], [-10, 0, 2]], np.float32)
    idx = np.array([[0, 2, 1], [0, 3, 2]], np.uint32)
    uv = np.array([[0, 0], [repeat, 0], [repeat, repeat], [0, repeat]], np.float32)
    s = oit.Scene()
    tex = checker()
    for k in range(meshes):
        lifted = p + np.array([0, 0.01 * k, 0], np.float32)
        s.add_mesh(lifted, idx, (1.0, 1.0, 1.0, 0.9), uvs=uv, texture=tex, shading=shading, specular=0.2)
    return s, oit.Camera.look_at((0.2, 1.0, 2.5), (0, 0, -8), 50, near=0.5, far=60)


@pytest.mark.parametrize("method", [m["name"] for m in oit.methods() if m["exact"]])
def test_every_exact_method_samples_the_mips_as_the_reference_does(renderer, method):
    scene, camera = floor_scene()
    ref, ambiguous = oit.reference(scene, camera, SIZE, SIZE, return_mask=True)
    assert_within_the_shading_bound(method, renderer(SIZE, SIZE).render(scene, camera, method).image, ref, ambiguous)


def test_far_away_the_mips_average_what_a_pixel_covers(renderer):
    scene, camera = floor_scene(repeat=6.0, shading="unlit")
    img = renderer(SIZE, SIZE).render(scene, camera, "abuffer", background=(0.0, 0.0, 0.0)).image
    # Rows just under the horizon: hundreds of checker cells a pixel, so every pixel is close to
    # the checker's mean (no aliased red or white pixels), while near rows keep their cells.
    covered = np.flatnonzero((img[:, 8:-8, 3] > 0.5).all(1))
    far = img[covered[:2], 8:-8, 0]
    near = img[-6:, :, 0]
    assert far.std() < 0.02 and near.std() > 0.1, (far.std(), near.std())


def test_textures_take_four_bytes_a_texel_and_their_mips_in_the_atlas(renderer):
    # A 64 x 64 image and its mips (5,461 texels) in layers of 64 x 64: level 0 fills one, the
    # mips the next (docs/shading.md, "Where the data lives").
    one = renderer(8, 8).render(*floor_scene(meshes=1), "abuffer").stats
    assert one["texture_bytes"] == 4 * 64 * 64 * 2
    assert one["scene_bytes"] > one["texture_bytes"]
    # Each add_mesh brings its own array: three images, their level 0s in three layers and
    # their mips (3 x 1,365 texels) in two more.
    three = renderer(8, 8).render(*floor_scene(meshes=3), "abuffer").stats["texture_bytes"]
    assert three == 4 * 64 * 64 * 5
    plain = oit.Scene()
    plain.add_mesh(np.eye(3, dtype=np.float32), np.array([[0, 1, 2]], np.uint32), (1.0, 1.0, 1.0, 0.5))
    assert renderer(8, 8).render(plain, oit.Camera.look_at((0, 0, 3), (0, 0, 0)), "abuffer").stats["texture_bytes"] == 0
