"""Checks of the public API's arguments, shared by its classes and the scene files: each
error names the argument and says what to do."""

from __future__ import annotations

from typing import Any

import numpy as np

from ._trimesh import srgb_to_linear


def _float_array(value: Any, name: str) -> np.ndarray:
    a = np.asarray(value)
    if a.dtype == object or not (np.issubdtype(a.dtype, np.floating) or np.issubdtype(a.dtype, np.integer)) or a.dtype == bool:
        raise TypeError(f"{name} must be a float array (float32 preferred), got dtype {a.dtype}")
    with np.errstate(over="ignore", invalid="ignore"):
        out = np.ascontiguousarray(a, dtype=np.float32)
    if not np.isfinite(out).all():
        bad = np.argwhere(~np.isfinite(out))[0]
        raise ValueError(f"{name} has a NaN or Inf (or a value too large for float32) at index {tuple(int(i) for i in bad)}")
    return out


def _rows(a: np.ndarray, cols: int, name: str) -> np.ndarray:
    if a.ndim != 2 or a.shape[1] != cols:
        raise ValueError(f"{name} must have shape (n, {cols}), got {a.shape}")
    return a


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
    v = float(value)
    if not np.isfinite(v):
        raise ValueError(f"{name} must be finite, got {v}")
    return v


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
    out = _float_array(t, "texture")
    if out.min() < 0.0 or out.max() > 1.0:
        raise ValueError(f"a float texture must be linear RGBA in [0, 1], got values in [{out.min():g}, {out.max():g}]: "
                         "clip it, or pass uint8 sRGB")
    return out


def _surface(n: int, normals: Any, uvs: Any, texture: Any, shading: str | None, specular: float, shininess: float,
             opacity: float, two_sided: bool, cull_back_faces: bool = False) -> dict[str, Any]:
    """The keyword arguments of the native add_mesh that describe the surface, checked."""
    out: dict[str, Any] = {}
    if normals is not None:
        nrm = _float_array(normals, "normals")
        if nrm.shape != (n, 3):
            raise ValueError(f"normals must have shape ({n}, 3) (one per vertex), got {nrm.shape}")
        zero = np.flatnonzero(~np.any(nrm, axis=1))
        if len(zero):
            raise ValueError(f"normals[{zero[0]}] is zero: pass unit vertex normals, or none to have them computed")
        out["normals"] = nrm
    if uvs is not None:
        uv = _float_array(uvs, "uvs")
        if uv.shape != (n, 2):
            raise ValueError(f"uvs must have shape ({n}, 2) (one (u, v) per vertex), got {uv.shape}")
        out["uvs"] = uv
    if texture is not None:
        if uvs is None:
            raise ValueError("a texture needs uvs: pass one (u, v) per vertex")
        out["texture"] = _texture(texture)
    if shading is None:
        shading = "smooth" if normals is not None else "unlit"
    if not isinstance(shading, str) or shading not in SHADINGS:
        raise ValueError(f"shading must be one of {SHADINGS}, got {shading!r}")
    out["shading"] = shading
    for name, v in (("specular", specular), ("shininess", shininess), ("opacity", opacity)):
        out[name] = _number(v, name)
    if out["specular"] < 0:
        raise ValueError(f"specular must be >= 0, got {specular}")
    if out["shininess"] <= 0:
        raise ValueError(f"shininess must be > 0, got {shininess}")
    if not 0.0 <= out["opacity"] <= 1.0:
        raise ValueError(f"opacity must be in [0, 1], got {opacity}")
    if not isinstance(two_sided, (bool, np.bool_)):
        raise TypeError(f"two_sided must be a bool, got {type(two_sided).__name__}")
    out["two_sided"] = bool(two_sided)
    if not isinstance(cull_back_faces, (bool, np.bool_)):
        raise TypeError(f"cull_back_faces must be a bool, got {type(cull_back_faces).__name__}")
    out["cull_back_faces"] = bool(cull_back_faces)
    return out
