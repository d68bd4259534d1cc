"""`oit.Camera`, a view-projection matrix with its constructors, and `oit.FileCamera`, a camera
as a loaded file has it."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _oit


class Camera:
    """A 4x4 view-projection matrix, column-vector convention (clip = M @ [x, y, z, 1]),
    wgpu clip space: x, y in [-1, 1] with y up, z in [0, 1] (smaller is nearer)."""

    def __init__(self, view_proj: Any) -> None:
        if np.iscomplexobj(view_proj):
            raise TypeError("view_proj must be a 4 x 4 array of real numbers, got complex values")
        try:
            m = np.asarray(view_proj, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise TypeError(f"view_proj must be a 4 x 4 array of numbers, got {view_proj!r:.60}") from e
        if m.shape != (4, 4):
            raise ValueError(f"view_proj must be a 4 x 4 matrix, got shape {m.shape}")
        if not np.isfinite(m).all():
            raise ValueError("view_proj has NaN or Inf entries")
        if abs(np.linalg.det(m)) < 1e-300:
            raise ValueError("view_proj is singular: build it with Camera.look_at or Camera.orthographic")
        # The GPU gets the matrix in float32: entries past its range become Inf, and tiny ones
        # flush to 0 (a matrix regular in float64 can be singular there).
        big = float(np.abs(m).max())
        if big > float(np.finfo(np.float32).max):
            raise ValueError(f"view_proj has an entry of magnitude {big:.3g}, past float32 (the GPU's precision): "
                             "rescale it")
        if abs(np.linalg.det(m.astype(np.float32).astype(np.float64))) < 1e-300:
            raise ValueError("view_proj is singular in float32 (the GPU's precision): build it with Camera.look_at "
                             "or Camera.orthographic")
        self.view_proj = np.ascontiguousarray(m)

    def __repr__(self) -> str:
        return f"Camera(view_proj={self.view_proj.tolist()})"

    @property
    def view_direction(self) -> np.ndarray:
        """The unit world-space direction the camera looks along at the center of the picture
        (from the near plane to the far one): the way the headlight travels."""
        return np.array(_oit.view_direction(self.view_proj), np.float64)

    @staticmethod
    def _view(eye: Sequence[float], target: Sequence[float], up: Sequence[float]) -> np.ndarray:
        eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
        f = target - eye
        if np.linalg.norm(f) == 0:
            raise ValueError("eye and target must differ")
        f /= np.linalg.norm(f)
        s = np.cross(f, up)
        if np.linalg.norm(s) < 1e-12:
            raise ValueError("up must not be parallel to the viewing direction")
        s /= np.linalg.norm(s)
        u = np.cross(s, f)
        view = np.eye(4)
        view[0, :3], view[1, :3], view[2, :3] = s, u, -f
        view[:3, 3] = -view[:3, :3] @ eye
        return view

    @classmethod
    def look_at(cls, eye: Sequence[float], target: Sequence[float], fov_y: float = 45.0, near: float = 0.1,
                far: float = 100.0, up: Sequence[float] = (0.0, 1.0, 0.0), aspect: float = 1.0) -> Camera:
        """Right-handed perspective camera; fov_y in degrees; depth 0 at `near`, 1 at `far`."""
        if not (0.0 < fov_y < 180.0):
            raise ValueError(f"fov_y must be in (0, 180) degrees, got {fov_y}")
        if not (0.0 < near < far) or not np.isfinite(far):
            raise ValueError(f"need 0 < near < far (finite), got near={near}, far={far}")
        if not aspect > 0:
            raise ValueError(f"aspect must be positive, got {aspect}")
        f = 1.0 / np.tan(np.radians(fov_y) / 2.0)
        proj = np.zeros((4, 4))
        proj[0, 0], proj[1, 1] = f / aspect, f
        proj[2, 2], proj[2, 3] = far / (near - far), near * far / (near - far)
        proj[3, 2] = -1.0
        return cls(proj @ cls._view(eye, target, up))

    @classmethod
    def orthographic(cls, left: float, right: float, bottom: float, top: float, near: float, far: float,
                     eye: Sequence[float] | None = None, target: Sequence[float] | None = None,
                     up: Sequence[float] = (0.0, 1.0, 0.0)) -> Camera:
        """Orthographic projection of the view volume (right-handed: looking down -z),
        optionally placed with eye/target."""
        if right == left or top == bottom or far == near:
            raise ValueError("orthographic volume must have non-zero extent on every axis")
        proj = np.eye(4)
        proj[0, 0], proj[0, 3] = 2.0 / (right - left), -(right + left) / (right - left)
        proj[1, 1], proj[1, 3] = 2.0 / (top - bottom), -(top + bottom) / (top - bottom)
        proj[2, 2], proj[2, 3] = 1.0 / (near - far), near / (near - far)
        view = cls._view(eye, target, up) if eye is not None and target is not None else np.eye(4)
        return cls(proj @ view)

    @classmethod
    def fit(cls, positions: np.ndarray, direction: Sequence[float] = (0.3, 0.35, 1.0), fov_y: float = 40.0,
            aspect: float = 1.0) -> Camera:
        """A perspective camera that frames the given points' bounding sphere."""
        p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        center = (p.min(0) + p.max(0)) / 2 if len(p) else np.zeros(3)
        radius = max(float(np.linalg.norm(p - center, axis=1).max()) if len(p) else 1.0, 1e-6)
        d = np.asarray(direction, dtype=np.float64)
        d /= np.linalg.norm(d)
        dist = radius / np.sin(np.radians(fov_y) / 2) * 1.05
        near, far = max(dist - radius * 1.5, dist * 1e-3), dist + radius * 1.5
        return cls.look_at(center + d * dist, center, fov_y, near=near, far=far, aspect=aspect)


@dataclass
class FileCamera:
    """A camera of a loaded file: `view` (4 x 4, world to camera, looking down -z with y up) and
    its `projection` dict ("type" "perspective" with yfov in radians, aspect (the file's, or
    None), near and far; or "orthographic" with xmag, ymag, near and far)."""

    name: str
    view: np.ndarray
    projection: dict[str, Any]

    def camera(self, aspect: float | None = None) -> Camera:
        """The oit.Camera of this view at `aspect` (width / height; default: the file's, else 1)."""
        p = self.projection
        if p["type"] == "orthographic":
            return Camera(Camera.orthographic(-p["xmag"], p["xmag"], -p["ymag"], p["ymag"], p["near"], p["far"]).view_proj
                          @ self.view)
        aspect = aspect or p["aspect"] or 1.0
        f = 1.0 / np.tan(p["yfov"] / 2.0)
        proj = np.zeros((4, 4))
        proj[0, 0], proj[1, 1] = f / aspect, f
        proj[2, 2], proj[2, 3] = p["far"] / (p["near"] - p["far"]), p["near"] * p["far"] / (p["near"] - p["far"])
        proj[3, 2] = -1.0
        return Camera(proj @ self.view)
