"""Strands and particles on a Scene: polylines drawn as camera-facing ribbons and points drawn
as camera-facing discs, both built on the GPU from the points (docs/methods.md, "Strands and
particles"). Arguments are converted here; their values are checked in the core."""

from __future__ import annotations

from typing import Any

import numpy as np

from ._checks import _U32_MAX, SURFACE, _bool, _colors, _float_array, _rows


def _sizes(value: Any, name: str) -> np.ndarray:
    a = _float_array(value, name)
    if a.ndim > 1:
        raise ValueError(f"{name} must be a number or one per point (n,), got shape {a.shape}")
    return a.reshape(-1)


class PrimitiveMethods:
    """The strand and particle half of `Scene` (its `_native` is the core's scene)."""

    _native: Any
    _mesh_index: Any

    def add_strands(self, points: Any, counts: Any, width: Any, colors: Any, opaque: bool = False, *,
                    shading: str = SURFACE["shading"], specular: float = SURFACE["specular"],
                    shininess: float = SURFACE["shininess"], opacity: float = SURFACE["opacity"]) -> int:
        """Adds a strand set and returns its index (a mesh index: `add_instances`,
        `set_mesh_alpha` and the rest take it).

        points: (n, 3) float, strand after strand; counts: (strands,) integers >= 2, the points
        of each strand, adding up to n; width: world units, one number or (n,) per point;
        colors: (n, 4) per point or (4,), straight linear RGBA in [0, 1]. Each segment is drawn
        as a ribbon facing the eye, two triangles built on the GPU; joints share their corners.
        `shading`: "unlit" (the point colors) or "hair" (Kajiya-Kay from the strand's tangent,
        docs/shading.md), with `specular` and `shininess` weighing its highlight; `opacity`
        multiplies alpha.
        """
        pts = _rows(_float_array(points, "points"), 3, "points")
        cnt = np.asarray(counts)
        if cnt.dtype == bool or not np.issubdtype(cnt.dtype, np.integer):
            raise TypeError(f"counts must be an integer array (points per strand), got dtype {cnt.dtype}")
        cnt = cnt.reshape(-1)
        if cnt.size and (int(cnt.min()) < 0 or int(cnt.max()) > _U32_MAX):
            raise ValueError(f"counts has an entry {int(cnt.min()) if cnt.min() < 0 else int(cnt.max())}: "
                             "counts[i] is the number of points of strand i, at least 2")
        cnt = np.ascontiguousarray(cnt, dtype=np.uint32)
        return self._native.add_strands(pts, cnt, _sizes(width, "width"), _colors(colors, len(pts), "point"),
                                        _bool(opaque, "opaque"), {"shading": shading, "specular": float(specular),
                                        "shininess": float(shininess), "opacity": float(opacity)})

    def add_particles(self, centers: Any, radius: Any, colors: Any, opaque: bool = False, *,
                      falloff: str = "hard", opacity: float = SURFACE["opacity"]) -> int:
        """Adds a particle set and returns its index (a mesh index).

        centers: (n, 3) float; radius: world units, one number or (n,); colors: (n, 4) per
        particle or (4,), straight linear RGBA in [0, 1]. Each particle is a disc facing the
        eye, drawn on a quad built on the GPU, its alpha times `falloff` of the distance r from
        the center in radii: "hard" (1 inside the disc), "linear" (1 - r) or "gaussian"
        (exp(-4.5 r²)), 0 outside; `opacity` multiplies alpha.
        """
        c = _rows(_float_array(centers, "centers"), 3, "centers")
        return self._native.add_particles(c, _sizes(radius, "radius"), _colors(colors, len(c), "particle"),
                                          _bool(opaque, "opaque"), falloff=falloff, opacity=float(opacity))

    def primitives(self) -> list[str]:
        """What each mesh is: "triangles", "strands" or "particles"."""
        return list(self._native.mesh_primitives())

    def to_triangles(self, mesh: int, camera: Any) -> dict[str, np.ndarray | None]:
        """Mesh `mesh` as the triangles it is drawn as under `camera` (strand ribbons and
        particle quads face it; a triangle mesh comes back as it is), world space, its
        instances not applied: positions, indices, colors, and normals (a strand set's
        tangents, what "hair" shading reads) and uvs (a particle's disc coordinates, what its
        falloff reads), None where the set has none. For peers and files that take only
        triangles; strands come back as they look under that camera through
        `add_mesh(..., normals=tangents, shading="hair")` (or unlit), particles without their
        falloff."""
        pos, idx, col, normals, uvs = self._native.to_triangles(self._mesh_index(mesh), np.asarray(camera.view_proj, dtype=np.float64))
        return {"positions": pos, "indices": idx, "colors": col, "normals": normals, "uvs": uvs}
