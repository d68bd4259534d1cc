"""Arrays from trimesh objects for `Scene.add_trimesh`: positions, faces, linear straight RGBA per
vertex from the visuals (vertex colors, a material's base color or texture, glTF alpha modes),
normals the file brought, UVs and the texture."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


@dataclass
class _TrimeshArrays:
    positions: np.ndarray
    faces: np.ndarray
    colors: np.ndarray  # linear straight RGBA per vertex
    normals: np.ndarray | None = None
    uvs: np.ndarray | None = None  # row 0 of the texture at v = 0 (trimesh's v flipped)
    texture: np.ndarray | None = None  # uint8 sRGB or float linear (h, w, 4)
    opaque: bool = False


def _unit_normals(n: Any, count: int) -> np.ndarray | None:
    """Vertex normals with zero or non-finite rows replaced by +z (unreferenced vertices)."""
    try:
        n = np.array(n, dtype=np.float64)
    except Exception:
        return None
    if n.shape != (count, 3):
        return None
    length = np.linalg.norm(n, axis=1)
    bad = ~np.isfinite(length) | (length < 1e-12)
    n[bad] = (0.0, 0.0, 1.0)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def _rgba_image(image: Any) -> np.ndarray | None:
    if image is None:
        return None
    try:
        a = np.asarray(image.convert("RGBA") if hasattr(image, "convert") else image)
    except Exception:
        return None
    if a.ndim == 2:
        a = np.stack([a, a, a, np.full_like(a, 255 if a.dtype == np.uint8 else 1)], -1)
    if a.ndim != 3 or a.shape[2] not in (3, 4) or a.size == 0:
        return None
    if a.shape[2] == 3:
        a = np.concatenate([a, np.full((*a.shape[:2], 1), 255 if a.dtype == np.uint8 else 1, a.dtype)], -1)
    return np.array(a, order="C")  # a writable copy: alphaMode edits it


def trimesh_arrays(m: Any) -> _TrimeshArrays:
    positions = np.asarray(m.vertices, dtype=np.float32)
    faces = np.asarray(m.faces, dtype=np.int64)
    rgba = np.tile([0.8, 0.8, 0.8, 1.0], (len(positions), 1))
    # Normals the file brought (trimesh computes missing ones slowly without scipy: the core
    # computes them instead, angle-weighted, when none are passed).
    cache = getattr(m, "_cache", None)
    has_normals = cache is not None and "vertex_normals" in cache and len(faces)
    normals = _unit_normals(m.vertex_normals, len(positions)) if has_normals else None
    uvs = texture = None
    opaque = False
    visual = getattr(m, "visual", None)
    kind = getattr(visual, "kind", None)
    linear_rgb = False
    if kind == "vertex":
        rgba = np.asarray(visual.vertex_colors, dtype=np.float64) / 255.0
    elif kind == "face":
        # One color per face: split vertices so that each face keeps its own color.
        fc = np.asarray(visual.face_colors, dtype=np.float64) / 255.0
        corner = faces.reshape(-1)
        if normals is None and len(faces):
            from .geometry import vertex_normals

            normals = _unit_normals(vertex_normals(positions, faces), len(positions))
        positions = positions[corner]
        normals = normals[corner] if normals is not None else None
        faces = np.arange(len(positions)).reshape(-1, 3)
        rgba = np.repeat(fc, 3, axis=0)
    elif kind == "texture" and hasattr(visual, "material"):
        mat = visual.material
        base = getattr(mat, "baseColorFactor", None)
        if base is not None:
            linear_rgb = True  # glTF: the factor is linear
        else:
            base = getattr(mat, "main_color", None)
        if base is not None:
            base = np.asarray(base, dtype=np.float64)
            base = base / (255.0 if base.max() > 1 else 1.0)
            rgba = np.tile(np.append(base, 1.0)[:4] if base.shape == (3,) else base, (len(positions), 1))
        image = getattr(mat, "baseColorTexture", None)
        if image is None:
            image = getattr(mat, "image", None)
        uv = getattr(visual, "uv", None)
        if image is not None and uv is not None and np.shape(uv) == (len(positions), 2):
            texture = _rgba_image(image)
            if texture is not None:
                if not linear_rgb:
                    # A plain material's diffuse color (trimesh's default grey when the file has
                    # none) is not applied over its image, as trimesh's viewer shows it.
                    rgba[:, :3] = 1.0
                uvs = np.asarray(uv, dtype=np.float64).copy()
                uvs[:, 1] = 1.0 - uvs[:, 1]  # trimesh's v points up the image; row 0 is v = 0 here
                uvs = uvs.astype(np.float32)
        mode = str(getattr(mat, "alphaMode", None) or "").upper()
        if mode == "OPAQUE":
            opaque = True
            rgba[:, 3] = 1.0
            if texture is not None:
                texture[..., 3] = 255 if texture.dtype == np.uint8 else 1.0
        elif mode == "MASK":
            cutoff = getattr(mat, "alphaCutoff", None)
            cutoff = 0.5 if cutoff is None else float(cutoff)
            if texture is not None:
                # Per texel (bilinear filtering then softens the cut's edges over a texel).
                a = texture[..., 3].astype(np.float64) / (255.0 if texture.dtype == np.uint8 else 1.0)
                texture[..., 3] = np.where(a * rgba[0, 3] >= cutoff, 255 if texture.dtype == np.uint8 else 1.0, 0)
                rgba[:, 3] = 1.0
            else:
                rgba[:, 3] = np.where(rgba[:, 3] >= cutoff, 1.0, 0.0)
    rgba = rgba.copy()
    if not linear_rgb:
        rgba[:, :3] = srgb_to_linear(rgba[:, :3])
    return _TrimeshArrays(positions, faces, np.clip(rgba, 0.0, 1.0), normals, uvs, texture, opaque)


@dataclass
class _TrimeshPoints:
    positions: np.ndarray  # (n, 3), placed
    colors: np.ndarray  # linear straight RGBA per point
    counts: np.ndarray  # points a strand (paths only)
    default_size: float  # 1/200 of the box's diagonal: a radius or a width


def _placed(points: np.ndarray, transform: np.ndarray) -> np.ndarray:
    t = np.asarray(transform, dtype=np.float64)
    return (np.asarray(points, dtype=np.float64) @ t[:3, :3].T + t[:3, 3]).astype(np.float32)


def _default_size(points: np.ndarray) -> float:
    diagonal = float(np.linalg.norm(points.max(0) - points.min(0))) if len(points) else 0.0
    return diagonal / 200.0 if diagonal > 0 else 0.01


def _rgba8_linear(c: Any, count: int) -> np.ndarray:
    """sRGB 8-bit RGBA (n, 3|4) or None to linear RGBA; trimesh's default grey without colors."""
    c = None if c is None else np.asarray(c, dtype=np.float64)
    if c is None or c.ndim != 2 or len(c) != count or c.shape[1] not in (3, 4):
        rgba = np.tile([0.8, 0.8, 0.8, 1.0], (count, 1))
    else:
        rgba = np.concatenate([c[:, :3], c[:, 3:4] if c.shape[1] == 4 else np.full((count, 1), 255.0)], 1) / 255.0
    rgba[:, :3] = srgb_to_linear(rgba[:, :3])
    return np.clip(rgba, 0.0, 1.0)


def trimesh_points(cloud: Any, transform: np.ndarray) -> _TrimeshPoints:
    """A PointCloud's points under `transform`, with its colors."""
    positions = _placed(cloud.vertices, transform)
    colors = _rgba8_linear(cloud.colors, len(positions))
    return _TrimeshPoints(positions, colors, np.zeros(0, np.int64), _default_size(positions))


def trimesh_path(path: Any, transform: np.ndarray) -> _TrimeshPoints:
    """A Path3D's entities as polylines (each discretized: lines, arcs, curves) under `transform`,
    each in its entity's color."""
    vertices = np.asarray(path.vertices, dtype=np.float64)
    colors = None if path.colors is None else np.asarray(path.colors)
    lines, rows = [], []
    for k, entity in enumerate(path.entities):
        line = np.asarray(entity.discrete(vertices), dtype=np.float64)
        if line.ndim == 2 and len(line) >= 2:
            lines.append(line)
            rows.append(np.full(len(line), k))
    if not lines:
        return _TrimeshPoints(np.zeros((0, 3), np.float32), np.zeros((0, 4)), np.zeros(0, np.int64), 0.01)
    positions = _placed(np.concatenate(lines), transform)
    per_entity = _rgba8_linear(colors, len(path.entities))
    return _TrimeshPoints(positions, per_entity[np.concatenate(rows)], np.array([len(line) for line in lines], np.int64),
                          _default_size(positions))


def trimesh_camera(scene: Any) -> tuple[str, np.ndarray, dict[str, Any]]:
    """(name, view, projection) of a trimesh Scene's camera, as `FileCamera` takes them: its
    transform places it (looking down -z, y up), its fov (x, y degrees) gives yfov and aspect."""
    cam = scene.camera
    fx, fy = np.radians(np.asarray(cam.fov, dtype=np.float64))
    view = np.linalg.inv(np.asarray(scene.camera_transform, dtype=np.float64))
    projection = {"type": "perspective", "yfov": float(fy), "aspect": float(np.tan(fx / 2) / np.tan(fy / 2)),
                  "near": float(cam.z_near), "far": float(cam.z_far)}
    return str(getattr(cam, "name", None) or "camera"), view, projection
