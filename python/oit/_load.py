"""Files into the native scene for `Scene.from_file` and the command line (`_api.load_file`):
the core's loader (oit-core's `load`, which the viewer reads files with too) and `.hair`
strand models (oit.hairfile), with the checks of the arguments."""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from . import _oit
from ._checks import SHADINGS, _number
from .hairfile import read_hair

FORMATS = (".obj", ".gltf", ".glb", ".ply", ".stl", ".hair")


class OitLoadWarning(UserWarning):
    """Something in a file that oit reads but does not draw (animations, skins, an unknown
    extension...): one warning a feature, naming it and how many objects use it."""


def warn(path: str | os.PathLike, messages: list[str], stacklevel: int = 2) -> None:
    """Each of the loader's `messages` about `path` as one OitLoadWarning."""
    import warnings

    for m in messages:
        warnings.warn(f"{os.fspath(path)}: {m}", OitLoadWarning, stacklevel=stacklevel + 1)


def read(path: str | os.PathLike, alpha: float | None, shading: str, specular: float, viewing: bool,
         point_radius: float | None) -> tuple[Any, list[str], list[dict[str, Any]], str | None, list[str]]:
    """The native scene of `path`, its mesh names, its cameras (as the native loader gives
    them), the viewing note and the loader's warnings (`_api.load_file`)."""
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
        return _hair_scene(path, alpha, float(specular)), [os.path.splitext(os.path.basename(path))[0]], [], None, []
    native, names, cameras, note, warnings = _oit.load_file(path, shading, float(specular), alpha, viewing, radius)
    return native, list(names), list(cameras), note, list(warnings)


def _hair_scene(path: str, alpha: float | None, specular: float) -> Any:
    """A `.hair` file as one native strand set shaded "hair" (its thickness the width, its
    transparency alpha, or `alpha` for every point)."""
    h = read_hair(path)
    colors = np.ascontiguousarray(h.colors, dtype=np.float32)
    if alpha is not None:
        colors[:, 3] = alpha
    native = _oit.Scene()
    native.add_strands(np.ascontiguousarray(h.points, dtype=np.float32), np.ascontiguousarray(h.counts, dtype=np.uint32),
                       np.ascontiguousarray(h.widths, dtype=np.float32), colors, False,
                       {"shading": "hair", "specular": specular, "shininess": 48.0, "opacity": 1.0})
    return native
