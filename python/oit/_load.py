"""Files into scenes: `Scene.from_file` and the command line's `load_file` over the core's loader
(oit-core's `load`, which the viewer reads files with too), and the cameras files carry."""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _oit
from ._checks import SHADINGS, _number

if TYPE_CHECKING:
    from ._api import Camera, Scene


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
        from ._api import Camera

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


FORMATS = (".obj", ".gltf", ".glb", ".ply", ".stl", ".hair")


def load_file(path: str | os.PathLike, alpha: float | None = None, *, shading: str = "smooth", specular: float = 0.25,
              viewing: bool = False, point_radius: float | None = None) -> tuple[Scene, str | None]:
    """`Scene.from_file`, and with `viewing` the command line's convenience: when nothing in
    the file is transparent every mesh is drawn at alpha 0.4, and the second value says so."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name (str or os.PathLike), got {type(path).__name__}")
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"no such file: {path}: check the path")
    if os.path.splitext(path)[1].lower() not in FORMATS:
        raise ValueError(f"{path}: unknown file type {os.path.splitext(path)[1]!r}: oit reads {', '.join(FORMATS)} files")
    if alpha is not None and not 0.0 <= _number(alpha, "alpha") <= 1.0:
        raise ValueError(f"alpha must be in [0, 1], got {alpha}")
    if shading not in SHADINGS:
        raise ValueError(f"shading must be one of {SHADINGS}, got {shading!r}")
    if _number(specular, "specular") < 0:
        raise ValueError(f"specular must be >= 0, got {specular}")
    radius = None if point_radius is None else _number(point_radius, "point_radius")
    if path.lower().endswith(".hair"):
        return _hair_scene(path, alpha, specular), None
    native, names, cameras, note = _oit.load_file(path, shading, float(specular), alpha, viewing, radius)
    from ._api import Scene

    scene = Scene()
    scene._native, scene.mesh_names = native, list(names)
    scene.cameras = [FileCamera(c["name"], np.array(c["view"], dtype=np.float64),
                                {k: v for k, v in c.items() if k not in ("name", "view")}) for c in cameras]
    return scene, note


def _hair_scene(path: str, alpha: float | None, specular: float) -> Scene:
    """A `.hair` file as one strand set shaded "hair" (its thickness the width, its transparency
    alpha, or `alpha` for every point), named after the file."""
    from ._api import Scene
    from .hairfile import read_hair

    h = read_hair(path)
    colors = h.colors.copy()
    if alpha is not None:
        colors[:, 3] = alpha
    scene = Scene()
    scene.add_strands(h.points, h.counts, h.widths, colors, shading="hair", specular=float(specular), shininess=48.0)
    scene.mesh_names = [os.path.splitext(os.path.basename(path))[0]]
    return scene
