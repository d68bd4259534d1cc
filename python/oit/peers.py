"""Peers for the benchmark: the same scene and camera rendered by another library.

pygfx (optional, `pip install pygfx`) is what a Python user would pick instead of oit; its
`blend`, `weighted_blend` and `dither` alpha modes are measured beside our methods. The
inputs are matched as follows (docs/results.md says how the match was checked):

- colors: pygfx takes vertex colors as linear ("physical") RGBA, as oit does, so they pass
  unchanged; its background material takes sRGB, so our linear background is encoded.
- camera: pygfx draws with projection @ inverse(camera world matrix). We give it our
  view-projection matrix as the view (with z negated) and the z negation as the projection,
  so the product is exactly ours; both use wgpu's clip space (z in [0, 1], y up). The
  negation makes pygfx's view-space z (which it sorts objects by, looking down -z) increase
  toward the camera, as it expects.
- objects: one gfx.Mesh per mesh, placed at its vertex centroid, since pygfx sorts
  transparent objects by their position; opaque meshes use alpha mode `solid`.
- output: pygfx blends into an rgba8unorm-srgb target; `snapshot()` reads that target before
  the output pass (with `ppaa="none"` and `pixel_scale=1` nothing filters it) and we decode it
  to linear. Its 8-bit sRGB storage is part of what pygfx computes, so it stays in the error.
"""

from __future__ import annotations

import functools
import time
from typing import Any, Sequence

import numpy as np

from .imageio import linear_to_srgb, srgb_to_linear
from .scenes import BuiltScene

PYGFX_MODES = ("blend", "weighted_blend", "dither")


def pygfx_missing() -> str | None:
    """Why pygfx cannot be used here, or None when it can."""
    try:
        import pygfx  # noqa: F401
    except ImportError as e:
        return f"pygfx is not installed ({e}); `pip install pygfx` adds it"
    return None


def _matrix_camera(view_proj: np.ndarray) -> Any:
    import pygfx as gfx

    flip_z = np.diag([1.0, 1.0, -1.0, 1.0])
    flip_z.flags.writeable = False

    class MatrixCamera(gfx.Camera):
        """A camera whose projection @ view is a given view-projection matrix."""

        def _update_projection_matrix(self) -> np.ndarray:
            return flip_z

    camera = MatrixCamera()
    camera.local.state_basis = "matrix"  # keep the (projective) matrix as given, undecomposed
    camera.local.matrix = np.linalg.inv(flip_z @ np.asarray(view_proj, dtype=np.float64))
    return camera


class PygfxRenderer:
    """Renders BuiltScenes with pygfx at one size, offscreen, into linear RGBA like oit."""

    def __init__(self, width: int, height: int) -> None:
        import pygfx as gfx

        self.width, self.height = width, height
        # The target only receives pygfx's output pass; we read its internal color buffer.
        target = gfx.Texture(dim=2, size=(width, height, 1), format="rgba8unorm")
        self._renderer = gfx.WgpuRenderer(target, pixel_scale=1, ppaa="none")
        # pygfx scenes of the BuiltScene last rendered, by (mode, background); the reference to
        # it keeps its id from being reused by another scene while cached.
        self._built: BuiltScene | None = None
        self._scenes: dict[tuple[str, tuple[float, ...]], Any] = {}

    @property
    def adapter(self) -> str:
        from pygfx.renderers.wgpu import get_shared

        return f"pygfx on {get_shared().adapter.info['device']}"

    def _scene(self, built: BuiltScene, mode: str, background: Sequence[float]) -> Any:
        import pygfx as gfx

        if built is not self._built:
            self._built, self._scenes = built, {}  # drop the old scenes' GPU buffers
        key = (mode, tuple(background))
        if key not in self._scenes:
            scene = gfx.Scene()
            srgb = linear_to_srgb(np.asarray(background, dtype=np.float64))
            scene.add(gfx.Background.from_color(gfx.Color(*srgb)))
            for m in built.meshes:
                center = m.positions.astype(np.float64).mean(0)
                geometry = gfx.Geometry(positions=(m.positions - center).astype(np.float32),
                                        indices=m.indices, colors=m.colors)
                material = gfx.MeshBasicMaterial(color_mode="vertex", alpha_mode="solid" if m.opaque else mode)
                mesh = gfx.Mesh(geometry, material)
                mesh.local.position = center
                scene.add(mesh)
            self._scenes[key] = scene
        return self._scenes[key]

    def render(self, built: BuiltScene, mode: str, background: Sequence[float] = (1.0, 1.0, 1.0)) -> tuple[np.ndarray, float]:
        """(h, w, 4) float32 linear RGBA (A = 1: the background is opaque) and the wall time in
        milliseconds of the render and the readback."""
        if mode not in PYGFX_MODES + ("solid",):
            raise ValueError(f"unknown pygfx alpha mode '{mode}'; choose one of {', '.join(PYGFX_MODES)}")
        scene = self._scene(built, mode, background)
        camera = _matrix_camera(built.camera.view_proj)
        t0 = time.perf_counter()
        self._renderer.render(scene, camera)
        snap = self._renderer.snapshot()
        wall = (time.perf_counter() - t0) * 1e3
        image = np.empty(snap.shape, dtype=np.float32)
        image[..., :3] = srgb_to_linear(snap[..., :3] / 255.0)
        image[..., 3] = snap[..., 3] / 255.0
        return image, wall


@functools.lru_cache(maxsize=2)
def pygfx_renderer(width: int, height: int) -> PygfxRenderer:
    """A PygfxRenderer per size, kept: pygfx compiles its shaders once per renderer."""
    return PygfxRenderer(width, height)
