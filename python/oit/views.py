"""Cameras for a scene nobody placed one in: one that frames its bounding box, and N views
around it (an orbit about the vertical axis through the box's center), for `python -m oit
render` and `compare`."""

from __future__ import annotations

import math

import numpy as np

from ._api import Camera, Scene

# The direction the default view looks from (towards the scene), as Camera.fit has it.
DIRECTION = (0.3, 0.35, 1.0)


def _corners(scene: Scene) -> np.ndarray:
    bounds = scene.bounds
    if bounds is None:
        raise ValueError("the scene is empty: add a mesh before placing cameras around it")
    lo, hi = bounds
    return np.array([[(lo, hi)[i >> k & 1][k] for k in range(3)] for i in range(8)], dtype=np.float64)


def fit_camera(scene: Scene, aspect: float = 1.0) -> Camera:
    """A perspective camera from DIRECTION that frames the scene's bounding box."""
    return Camera.fit(_corners(scene), direction=DIRECTION, aspect=aspect)


def orbit_cameras(scene: Scene, views: int, aspect: float = 1.0) -> list[Camera]:
    """`views` cameras evenly around the vertical axis, each framing the bounding box; the
    first is `fit_camera`'s."""
    if isinstance(views, bool) or not isinstance(views, int) or views < 1:
        raise ValueError(f"views must be a positive int, got {views!r}")
    x, y, z = DIRECTION
    start, flat = math.atan2(x, z), math.hypot(x, z)
    corners = _corners(scene)
    out = []
    for i in range(views):
        a = start + 2.0 * math.pi * i / views
        out.append(Camera.fit(corners, direction=(flat * math.sin(a), y, flat * math.cos(a)), aspect=aspect))
    return out


def scene_views(scene: Scene, views: int | None, aspect: float = 1.0) -> list[Camera]:
    """The views to measure a scene from: its file's cameras when it has some and `views` is
    None, else `views` (default 3) around it."""
    if views is None and scene.cameras:
        return [c.camera(aspect) for c in scene.cameras]
    return orbit_cameras(scene, 3 if views is None else views, aspect)
