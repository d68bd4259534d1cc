"""What every seed's claims share: the Claim record, the verdicts, and small scenes and
measurements built on the public API."""

from __future__ import annotations

import statistics
from dataclasses import dataclass
from functools import partial
from typing import Callable

import numpy as np

from ... import Camera, Renderer, Scene, methods
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


def error_against(image: np.ndarray, exact) -> float:
    """Mean per-pixel RGB distance of `image` to the exact frame's over the pixels it covers."""
    return image_errors(image, exact.image, exact.depth_complexity > 0, flip=False)["mean_err"]


_last_exact: list = []  # [(scene, its A-buffer frame)]: a claim compares many methods with one scene's


def exact_frame(built: scene_lib.BuiltScene):
    """The A-buffer's frame of `built`, rendered once for consecutive calls on the same scene."""
    if not (_last_exact and _last_exact[0][0] is built):
        _last_exact[:] = [(built, render(built, "abuffer"))]
    return _last_exact[0][1]


def mean_err(built: scene_lib.BuiltScene, method: str, **params) -> float:
    """Mean per-pixel RGB distance of `method`'s image to the A-buffer's over covered pixels."""
    return error_against(render(built, method, **params).image, exact_frame(built))


def flat_quad(z: float) -> list[list[float]]:
    """The corners of a full-screen quad at window depth z (identity camera)."""
    return [[-1, -1, z], [1, -1, z], [1, 1, z], [-1, 1, z]]


def quad_scene(quads: list[tuple[np.ndarray, tuple[float, ...]]]) -> scene_lib.BuiltScene:
    scene = Scene()
    for corners, color in quads:
        scene.add_mesh(np.asarray(corners, np.float32), [[0, 1, 2], [0, 2, 3]], color)
    return scene_lib.BuiltScene(scene, Camera(np.eye(4)), (16, 16))


def full_screen_layers(alpha: float, n: int = 10, seed: int = 5, zs: np.ndarray | None = None) -> scene_lib.BuiltScene:
    """n full-screen quads at distinct depths (or at the window depths `zs`), random colors, one
    alpha, shuffled (identity camera, 16²)."""
    rng = np.random.default_rng(seed)
    zs = np.linspace(0.1, 0.9, n) if zs is None else zs
    return quad_scene([(flat_quad(z), (*rng.uniform(0, 1, 3), alpha)) for z in rng.permutation(zs)])


def method_passes(method: str) -> list[str]:
    """The passes oit.methods() lists for `method`."""
    return next(m["passes"] for m in methods() if m["name"] == method)


def timed_ms(renderer: Renderer, built: scene_lib.BuiltScene, method: str, repeat: int = 3, **params):
    """The last frame and the median GPU time of `repeat` renders of `built` with `method`
    (after one warm-up)."""
    frame, gpu, _ = timed(partial(renderer.render, built.scene, built.camera, method, **params), repeat)
    if not gpu:
        raise RuntimeError(f"{renderer.adapter_info['name']} has no timestamp queries: GPU times cannot be measured")
    return frame, statistics.median(gpu)


def median_ms(renderer: Renderer, built: scene_lib.BuiltScene, method: str, repeat: int = 3, **params) -> float:
    """The median GPU time of `repeat` renders of `built` with `method` (after one warm-up)."""
    return timed_ms(renderer, built, method, repeat, **params)[1]
