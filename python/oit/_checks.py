"""Conversions of the public API's arguments into what the native layer takes (dtypes, shapes,
Python types), shared by its classes and the scene files; each error names the argument. The
values are checked once, in the core (ranges, finiteness, index bounds, counts)."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _oit
from ._trimesh import srgb_to_linear

# A surface's defaults, the core's (`Material::default()`): every keyword of the API that has one
# takes it from here.
SURFACE: dict[str, Any] = _oit.surface_defaults()


def _float_array(value: Any, name: str) -> np.ndarray:
    a = np.asarray(value)
    if a.dtype == object or not (np.issubdtype(a.dtype, np.floating) or np.issubdtype(a.dtype, np.integer)) or a.dtype == bool:
        raise TypeError(f"{name} must be a float array (float32 preferred), got dtype {a.dtype}")
    with np.errstate(over="ignore", invalid="ignore"):
        out = np.ascontiguousarray(a, dtype=np.float32)
    if np.isfinite(a).all() and not np.isfinite(out).all():
        # The conversion made it infinite: say so, since the core would see only the infinity.
        bad = np.argwhere(~np.isfinite(out))[0]
        raise ValueError(f"{name} has a value too large for float32 at index {tuple(int(i) for i in bad)}")
    return out


def _rows(a: np.ndarray, cols: int, name: str) -> np.ndarray:
    if a.ndim != 2 or a.shape[1] != cols:
        raise ValueError(f"{name} must have shape (n, {cols}), got {a.shape}")
    return a


def _bool(value: Any, name: str) -> bool:
    """A Python or numpy bool (not an int that happens to be 0 or 1)."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be a bool, got {type(value).__name__}")
    return bool(value)


def _colors(colors: Any, n: int, what: str) -> np.ndarray:
    """Straight RGBA as (n, 4) rows or one (4,) for all, as float32 (1, 4) or (n, 4); the
    values are the core's to check."""
    col = _float_array(colors, "colors")
    if col.shape == (4,):
        return col.reshape(1, 4)
    if col.ndim != 2 or col.shape[1] != 4:
        raise ValueError(f"colors must have shape ({n}, 4) (one RGBA per {what}) or (4,), got {col.shape}")
    return col


def _int(value: Any, name: str, what: str = "an int") -> int:
    """A Python or numpy integer (not a bool, not a float that happens to be whole)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be {what}, got {type(value).__name__}")
    return int(value)


# The native layer takes sizes as u32 and byte counts as i64; larger Python ints would
# surface as OverflowError without the argument's name.
_U32_MAX = 2 ** 32 - 1
_I64_MAX = 2 ** 63 - 1


def _number(value: Any, name: str) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} must be a number, got {type(value).__name__}")
    return float(value)


def _vector(value: Any, n: int, name: str) -> np.ndarray:
    a = _float_array(value, name)
    if a.shape != (n,):
        raise ValueError(f"{name} must be {n} numbers, got shape {a.shape}")
    return a


SHADINGS = ("unlit", "flat", "smooth")


def _texture(texture: Any) -> np.ndarray:
    """(h, w, 4) float32 linear RGBA: uint8 is decoded from sRGB (alpha stays linear)."""
    t = np.asarray(texture)
    if t.ndim != 3 or t.shape[2] != 4 or t.shape[0] == 0 or t.shape[1] == 0:
        raise ValueError(f"texture must have shape (h, w, 4) (straight RGBA), got {t.shape}: add an alpha channel "
                         "of 1 (or 255) to an RGB image")
    if t.dtype == np.uint8:
        out = t.astype(np.float64) / 255.0
        out[..., :3] = srgb_to_linear(out[..., :3])
        return np.ascontiguousarray(out, dtype=np.float32)
    return _float_array(t, "texture")


def _surface(n: int, normals: Any, uvs: Any, texture: Any, shading: str | None, specular: float, shininess: float,
             opacity: float, two_sided: bool, cull_back_faces: bool = SURFACE["cull_back_faces"]) -> dict[str, Any]:
    """The surface as the native layer takes it, one dict with every key (None: no such array),
    types checked (crates/oit-py/src/surface.rs)."""
    out: dict[str, Any] = {"normals": None, "uvs": None, "texture": None}
    if normals is not None:
        out["normals"] = _rows(_float_array(normals, "normals"), 3, "normals")
    if uvs is not None:
        out["uvs"] = _rows(_float_array(uvs, "uvs"), 2, "uvs")
    if texture is not None:
        out["texture"] = _texture(texture)
    if shading is None:
        shading = "smooth" if normals is not None else "unlit"
    if not isinstance(shading, str):
        raise TypeError(f"shading must be one of {SHADINGS}, got {shading!r}")
    out["shading"] = shading
    for name, v in (("specular", specular), ("shininess", shininess), ("opacity", opacity)):
        out[name] = _number(v, name)
    out["two_sided"] = _bool(two_sided, "two_sided")
    out["cull_back_faces"] = _bool(cull_back_faces, "cull_back_faces")
    return out


def _transforms(value: Any, name: str) -> np.ndarray:
    """(n, 4, 4) float64 from (n, 4, 4) or (4, 4); affinity and finiteness are the core's checks."""
    a = np.asarray(value)
    if a.dtype == object or a.dtype == bool or not (np.issubdtype(a.dtype, np.floating) or np.issubdtype(a.dtype, np.integer)):
        raise TypeError(f"{name} must be a float array of 4 x 4 matrices, got dtype {a.dtype}")
    if a.shape == (4, 4):
        a = a.reshape(1, 4, 4)
    if a.ndim != 3 or a.shape[1:] != (4, 4):
        raise ValueError(f"{name} must have shape (n, 4, 4) or (4, 4), got {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


def _instance_colors(value: Any, n: int) -> np.ndarray | None:
    if value is None:
        return None
    c = _float_array(value, "colors")
    if c.shape == (4,):
        c = np.tile(c, (n, 1))
    return np.ascontiguousarray(_rows(c, 4, "colors"))
