"""Scene builders and float64 models for the tests (import them: `from scenes import ...`;
conftest.py holds the fixtures)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

import oit
from oit import geometry

IDENTITY = oit.Camera(np.eye(4))
# Looks down -z at the origin, where the random "world" scenes lie.
PERSPECTIVE = oit.Camera.look_at(eye=(0.3, 0.2, 4.0), target=(0.0, 0.0, 0.0), fov_y=45.0, near=1.0, far=10.0)


@dataclass(frozen=True)
class MeshData:
    """A mesh as arrays, so that a test can rebuild a scene in another order."""

    positions: np.ndarray
    indices: np.ndarray
    colors: np.ndarray
    opaque: bool = False

    def shuffled(self, rng: np.random.Generator) -> MeshData:
        """The same triangles (each keeping its vertex order) in another order, with the
        vertex array permuted too."""
        perm = rng.permutation(len(self.positions))
        inverse = np.argsort(perm)
        tris = inverse[self.indices[rng.permutation(len(self.indices))]]
        return replace(self, positions=self.positions[perm], indices=tris, colors=self.colors[perm])


def build_scene(meshes: Sequence[MeshData]) -> oit.Scene:
    scene = oit.Scene()
    for m in meshes:
        scene.add_mesh(m.positions, m.indices, m.colors, opaque=m.opaque)
    return scene


def layer(z: float, rgba: Sequence[float], opaque: bool = False, size: float = 2.0) -> MeshData:
    """A quad of side `size` centered on the view axis at NDC depth z (identity camera):
    size 2 covers the whole frame, every pixel center once."""
    positions, indices = geometry.quad((0.0, 0.0, z), size)
    return MeshData(positions, indices, np.tile(np.asarray(rgba, dtype=np.float32), (4, 1)), opaque)


def _random_alpha(rng: np.random.Generator, n: int) -> np.ndarray:
    """Per-vertex alpha: a whole triangle exactly 0 or exactly 1 now and then, else random."""
    kind = rng.choice(3, p=[0.15, 0.15, 0.7])
    if kind == 0:
        return np.zeros(n)
    if kind == 1:
        return np.ones(n)
    return rng.uniform(0.05, 0.95, n)


# Random triangles stay away from two effects of lavapipe's float32 color interpolation
# that are not compositing errors: slivers (a random-colored triangle 0.05 pixel thick,
# gradient ~20 per pixel, was off by 1.4e-5 on its own) and clipping at the frame border
# (the new vertices' colors carry float32 rounding: up to 1e-5 near edges). So: no
# triangle thinner than MIN_THICKNESS_NDC on screen (1.9 pixels at 32 pixels a side),
# and, unless asked, every vertex on screen.
MIN_THICKNESS_NDC = 0.12


def _thickness(ndc_xy: np.ndarray) -> float:
    """Smallest altitude of a 2D triangle."""
    e = [ndc_xy[(i + 1) % 3] - ndc_xy[i] for i in range(3)]
    twice_area = abs(e[0][0] * e[2][1] - e[0][1] * e[2][0])
    return twice_area / max(float(np.hypot(*v)) for v in e)


def _ndc_xy(camera: oit.Camera, positions: np.ndarray) -> np.ndarray:
    clip = np.c_[positions, np.ones(len(positions))] @ camera.view_proj.T
    return clip[:, :2] / clip[:, 3:]


def random_meshes(seed: int, transparent: int = 8, opaque: int = 2, triangles: int = 5,
                  space: str = "ndc", spread: float = 0.6, on_screen: bool = True) -> list[MeshData]:
    """Random meshes of independent triangles with random per-vertex colors; alphas
    include whole triangles of exactly 0 and exactly 1.

    space "ndc": for IDENTITY, z in [0.03, 0.97]; space "world": for PERSPECTIVE, inside
    about [-1.7, 1.7]^2 x [-1, 1]. `spread` is the largest vertex offset from a triangle's
    center in x and y. Opaque meshes are single triangles (occluders). No triangle is
    thinner than MIN_THICKNESS_NDC on screen; with `on_screen`, no vertex leaves the frame.
    """
    if space not in ("ndc", "world"):
        raise ValueError(f"space must be 'ndc' or 'world', got {space!r}")
    camera = IDENTITY if space == "ndc" else PERSPECTIVE
    rng = np.random.default_rng(seed)

    def triangle() -> np.ndarray:
        while True:
            if space == "ndc":
                center = np.array([*rng.uniform(-1, 1, 2), rng.uniform(0.15, 0.85)])
                p = np.clip(center + rng.uniform(-1, 1, (3, 3)) * (spread, spread, 0.12), -2, (2, 2, 0.97))
                p[:, 2] = np.maximum(p[:, 2], 0.03)
            else:
                center = np.array([*rng.uniform(-1, 1, 2), rng.uniform(-0.6, 0.6)])
                p = center + rng.uniform(-1, 1, (3, 3)) * (spread, spread, 0.4)
            ndc = _ndc_xy(camera, p)
            if _thickness(ndc) >= MIN_THICKNESS_NDC and (not on_screen or np.abs(ndc).max() < 1.0):
                return p

    meshes = []
    for k in range(transparent + opaque):
        is_opaque = k >= transparent
        n = 1 if is_opaque else triangles
        positions = np.stack([triangle() for _ in range(n)])
        colors = np.empty((n, 3, 4))
        colors[..., :3] = rng.uniform(0, 1, (n, 3, 3))
        for t in range(n):
            colors[t, :, 3] = 1.0 if is_opaque else _random_alpha(rng, 3)
        meshes.append(MeshData(
            positions.reshape(-1, 3).astype(np.float32),
            np.arange(3 * n, dtype=np.uint32).reshape(n, 3),
            colors.reshape(-1, 4).astype(np.float32),
            is_opaque,
        ))
    return meshes


def composite(layers: Sequence[tuple[float, Sequence[float]]], background: Sequence[float]) -> np.ndarray:
    """float64 front-to-back over-compositing of (depth, straight RGBA) layers at distinct
    depths: RGBA as the renderer returns it."""
    accum = np.zeros(3)
    trans = 1.0
    for _, c in sorted(layers, key=lambda layer: layer[0]):
        c = np.asarray(c, dtype=np.float64)
        accum += trans * c[3] * c[:3]
        trans *= 1.0 - c[3]
    return np.append(accum + trans * np.asarray(background, dtype=np.float64), 1.0 - trans)


