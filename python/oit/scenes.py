"""Built-in scenes, seeded and self-contained (no files needed). Each function returns a
`BuiltScene`: unpack it as `scene, camera = oit.scenes.hair()`; it also carries the size it
is meant for and, for synthetic scenes, what was generated (`meta`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterator

import numpy as np

from ._api import Camera, Scene

__all__ = ["BuiltScene", "hair", "stacks", "ALPHA_KINDS", "SCENES"]


@dataclass
class BuiltScene:
    scene: Scene
    camera: Camera
    size: tuple[int, int] = (512, 512)
    meta: dict[str, Any] = field(default_factory=dict)

    def __iter__(self) -> Iterator[Any]:
        yield self.scene
        yield self.camera


ALPHA_KINDS = ("random", "increasing", "worst", "constant")


def stack_alphas(kind: str, n: int, rng: np.random.Generator) -> np.ndarray:
    """Alphas front to back, as in the hybrid paper's Figure 7: random; uniformly increasing
    along depth; its worst case (the front half at 0.05, the back half at 0.9); constant 0.25."""
    if kind == "random":
        return rng.uniform(0.0, 1.0, n)
    if kind == "increasing":
        return np.linspace(0.05, 0.95, n)
    if kind == "worst":
        return np.r_[np.full(n // 2, 0.05), np.full(n - n // 2, 0.9)]
    if kind == "constant":
        return np.full(n, 0.25)
    raise ValueError(f"unknown alpha distribution '{kind}'; choose one of {', '.join(ALPHA_KINDS)}")


def stacks(layers: int = 20, alphas: str = "random", size: tuple[int, int] = (10, 10), seed: int = 0) -> BuiltScene:
    """Synthetic per-pixel fragment stacks: every pixel gets `layers` tiny quads (one per
    layer, covering only that pixel's center) at distinct random depths, with random colors
    and the chosen alpha distribution along depth, submitted in a shuffled order. The camera
    is the identity. `meta` holds each pixel's stack in submission order: z (P, n), rgb
    (P, n, 3), alpha (P, n), with P = width * height in row-major order."""
    w, h = size
    rng = np.random.default_rng(seed)
    pixels = w * h
    z = np.sort(rng.uniform(0.05, 0.95, (pixels, layers)), axis=1)
    alpha = np.stack([stack_alphas(alphas, layers, rng) for _ in range(pixels)])
    rgb = rng.uniform(0.0, 1.0, (pixels, layers, 3))
    # Submission order: a global shuffle of all quads.
    order = rng.permutation(pixels * layers)
    pix, lay = np.divmod(order, layers)
    row, col = np.divmod(pix, w)
    cx = (col + 0.5) * 2.0 / w - 1.0
    cy = 1.0 - (row + 0.5) * 2.0 / h
    hx, hy = 0.3 * 2.0 / w, 0.3 * 2.0 / h
    zz = z[pix, lay]
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], np.float64)
    pos = np.empty((len(order), 4, 3))
    pos[:, :, 0] = cx[:, None] + corners[None, :, 0] * hx
    pos[:, :, 1] = cy[:, None] + corners[None, :, 1] * hy
    pos[:, :, 2] = zz[:, None]
    colors = np.concatenate([rgb[pix, lay], alpha[pix, lay][:, None]], axis=1)
    quad = np.array([[0, 1, 2], [0, 2, 3]])
    idx = (np.arange(len(order))[:, None, None] * 4 + quad[None]).reshape(-1, 3)
    scene = Scene()
    scene.add_mesh(pos.reshape(-1, 3).astype(np.float32), idx, np.repeat(colors, 4, axis=0).astype(np.float32))
    # Each pixel's stack in submission order.
    sub = np.argsort(order, kind="stable")  # position of each quad in the submission
    rank = np.empty((pixels, layers), np.int64)
    rank[pix, lay] = np.arange(len(order))
    per_pixel = np.argsort(rank, axis=1)
    take = lambda a: np.take_along_axis(a, per_pixel if a.ndim == 2 else per_pixel[..., None], axis=1)
    meta = {"z": take(z), "rgb": take(rgb), "alpha": take(alpha), "layers": layers, "alphas": alphas}
    del sub
    return BuiltScene(scene, Camera(np.eye(4)), (w, h), meta)


def hair(strands: int = 6000, segments: int = 16, seed: int = 0, width: float = 0.01,
         alpha: tuple[float, float] = (0.1, 0.4)) -> BuiltScene:
    """Procedural hair: strands grown from a scalp, falling under gravity and converging into
    a tail, drawn as thin ribbons facing the camera (+z), alpha in `alpha`. The defaults give
    several hundred layers at the worst pixel at 512 x 512."""
    rng = np.random.default_rng(seed)
    theta = rng.uniform(0.15 * np.pi, 0.85 * np.pi, strands)  # around the top of the head
    phi = rng.uniform(-0.6, 0.6, strands)
    root = np.stack([0.5 * np.cos(theta) * np.cos(phi), 0.45 + 0.5 * np.sin(theta) * 0.6, 0.5 * np.sin(phi)], 1)
    tip = np.stack([rng.normal(0.0, 0.035, strands), np.full(strands, -0.9) + rng.normal(0, 0.04, strands),
                    rng.normal(-0.1, 0.05, strands)], 1)
    t = np.linspace(0.0, 1.0, segments + 1)[None, :, None]
    bulge = np.stack([root[:, 0] * 1.2, np.zeros(strands), root[:, 2] * 0.8], 1)[:, None, :]
    pts = (1 - t) ** 2 * root[:, None] + 2 * t * (1 - t) * (root[:, None] + bulge) + t ** 2 * tip[:, None]
    pts += rng.normal(0, 0.01, pts.shape) * t  # frizz toward the tips
    # Ribbon: offset perpendicular to the strand in the image plane (camera looks down -z).
    d = np.gradient(pts, axis=1)
    side = np.stack([-d[..., 1], d[..., 0], np.zeros_like(d[..., 0])], -1)
    side /= np.linalg.norm(side, axis=-1, keepdims=True) + 1e-12
    half = (width * (1 - 0.3 * t[..., 0]))[..., None] / 2
    left, right = pts - side * half, pts + side * half
    verts = np.stack([left, right], 2).reshape(strands, -1, 3)  # (strands, 2 * (segments + 1), 3)
    base = np.arange(strands)[:, None] * verts.shape[1] + 2 * np.arange(segments)[None, :]
    tris = np.stack([np.stack([base, base + 1, base + 3], -1), np.stack([base, base + 3, base + 2], -1)], 2).reshape(-1, 3)
    hue = rng.uniform(0, 1, strands)
    rgb = np.stack([0.15 + 0.7 * hue, 0.08 + 0.45 * hue, 0.03 + 0.2 * hue], 1)  # dark brown to blond
    a = rng.uniform(alpha[0], alpha[1], strands)
    colors = np.repeat(np.concatenate([rgb, a[:, None]], 1), verts.shape[1], axis=0)
    scene = Scene()
    scene.add_mesh(verts.reshape(-1, 3).astype(np.float32), tris, colors.astype(np.float32))
    camera = Camera.look_at(eye=(0.0, 0.0, 2.6), target=(0.0, -0.1, 0.0), fov_y=45.0, near=1.0, far=4.0)
    return BuiltScene(scene, camera, (512, 512), {"strands": strands, "triangles": len(tris)})


SCENES = {"hair": hair, "stacks": stacks}
