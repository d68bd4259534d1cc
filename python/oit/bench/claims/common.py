"""What every seed's claims share: the Claim record, the verdicts, and small scenes and
measurements built on the public API."""

from __future__ import annotations

import statistics
from dataclasses import dataclass
from functools import partial
from typing import Callable

import numpy as np

from ... import Camera, Renderer, Scene
from ... import scenes as scene_lib
from ..harness import image_errors, timed

HOLDS, FAILS, NOT_HERE = "holds", "does not hold", "not measurable here"
TOL = 1 / 255  # one 8-bit step of a color channel
TIE = 1.3  # lavapipe's GPU times differ by up to ~30 % from run to run: a smaller ratio is a tie


@dataclass(frozen=True)
class Claim:
    id: str
    source: str
    claim: str
    quick: bool
    measure: Callable[[], tuple[str, str]]  # (the measurement, the verdict)


def render(built: scene_lib.BuiltScene, method: str, **params):
    return Renderer(*built.size).render(built.scene, built.camera, method, **params)


def mean_err(built: scene_lib.BuiltScene, method: str, **params) -> float:
    """Mean per-pixel RGB distance of `method`'s image to the A-buffer's over covered pixels."""
    exact = render(built, "abuffer")
    image = render(built, method, **params).image
    return image_errors(image, exact.image, exact.depth_complexity > 0, flip=False)["mean_err"]


def full_screen_layers(alpha: float, n: int = 10, seed: int = 5) -> scene_lib.BuiltScene:
    """n full-screen quads at distinct depths, random colors, one alpha, shuffled (identity camera)."""
    rng = np.random.default_rng(seed)
    scene = Scene()
    for z in rng.permutation(np.linspace(0.1, 0.9, n)):
        quad = np.array([[-1, -1, z], [1, -1, z], [1, 1, z], [-1, 1, z]], np.float32)
        scene.add_mesh(quad, [[0, 1, 2], [0, 2, 3]], (*rng.uniform(0, 1, 3), alpha))
    return scene_lib.BuiltScene(scene, Camera(np.eye(4)), (16, 16))


def quad_scene(quads: list[tuple[np.ndarray, tuple[float, ...]]]) -> scene_lib.BuiltScene:
    scene = Scene()
    for corners, color in quads:
        scene.add_mesh(np.asarray(corners, np.float32), [[0, 1, 2], [0, 2, 3]], color)
    return scene_lib.BuiltScene(scene, Camera(np.eye(4)), (16, 16))


def median_ms(renderer: Renderer, built: scene_lib.BuiltScene, method: str, repeat: int = 3, **params) -> float:
    """The median GPU time of `repeat` renders of `built` with `method` (after one warm-up)."""
    return statistics.median(timed(partial(renderer.render, built.scene, built.camera, method, **params), repeat)[1])
