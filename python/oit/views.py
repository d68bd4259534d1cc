"""Mesh files and cameras for the command line's `render` and `compare`: the file with the
command line's alpha and lights, a camera that frames the bounding box, and N views around it
(an orbit about the vertical axis through the box's center)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._api import Camera, Scene, load_file

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


def load_for_viewing(args: Any) -> Scene:
    """The FILE of `render` and `compare` through the core's loader, with the command line's
    alpha (--alpha, or 0.4 for every mesh when nothing is transparent: said on stdout) and
    lighting (--light, --ambient where the command has them)."""
    if args.specular < 0:
        raise ValueError(f"--specular must be >= 0, got {args.specular}")
    scene, note = load_file(args.file, args.alpha, shading=args.shading, specular=args.specular, viewing=True)
    if note:
        print(f"{args.file}: {note}")
    args.alpha_note = note  # `render` says which alpha it drew at
    for light in getattr(args, "light", []):
        scene.add_light(light)
    scene.ambient = tuple(getattr(args, "ambient", (0.1, 0.1, 0.1)))
    return scene
