"""Strands, particles and Gaussian splats on a Scene: polylines drawn as camera-facing ribbons,
points drawn as camera-facing discs and 3D Gaussians drawn as their projected ellipses, all built
on the GPU from the points (docs/methods.md, "Strands and particles", "Gaussian splats").
Arguments are converted here; their values are checked in the core."""

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

    def add_gaussians(self, means: Any, scales: Any, rotations: Any, opacities: Any, colors: Any = None,
                      sh: Any = None, splat_depth: str = "center") -> int:
        """Adds a set of 3D Gaussian splats (Kerbl et al. 2023) and returns its index (a mesh
        index).

        means: (n, 3) float; scales: (n, 3) standard deviations along each Gaussian's axes
        (world units, > 0: not their logs, as a 3DGS file stores them); rotations: (n, 4) wxyz
        quaternions (normalized here, nonzero); opacities: (n,) in [0, 1] (not logits);
        colors: (n, 3) straight linear RGB in [0, 1], or (3,) for all, white when None; or
        sh: (n, k, 3) spherical-harmonic coefficients of degree 0 to 3 (k = 1, 4, 9 or 16, the
        DC first, 3DGS's basis) instead, the color 0.5 + sum Y_lm(d) c_lm in the direction d
        from the eye to the mean, clamped to [0, 1]. Each row argument may also be one row for
        all. A Gaussian is drawn as its EWA-projected
        ellipse (a 0.3-pixel² low-pass added) on a 3-sigma quad built on the GPU, its alpha
        opacity * exp(-d'Σ'⁻¹d / 2) at most 0.99 and 0 below 1/255 or past 3 sigma, at the depth
        of its mean (splat_depth="center", one depth a splat, as 3DGS sorts them) or of the
        Gaussian's peak along each pixel's ray (splat_depth="ray", t* = d'Σ⁻¹(μ - o) / d'Σ⁻¹d
        for the ray o + t d, as StopThePop: a depth a fragment, what exact methods then sort
        by; docs/methods.md, "Gaussian splats").
        """
        if splat_depth not in ("center", "ray"):
            raise ValueError(f"splat_depth must be 'center' or 'ray', got {splat_depth!r}")
        m = _rows(_float_array(means, "means"), 3, "means")
        n = len(m)

        def per_splat(value: Any, cols: int, name: str, what: str) -> np.ndarray:
            a = _float_array(value, name)
            if a.shape == (cols,):
                return a.reshape(1, cols)
            if a.ndim != 2 or a.shape[1] != cols or len(a) not in (1, n):
                raise ValueError(f"{name} must have shape ({n}, {cols}) (one {what} per splat) or ({cols},), got {a.shape}")
            return a

        s = per_splat(scales, 3, "scales", "standard deviation per axis")
        if not (np.isfinite(s).all() and (s > 0).all()):
            raise ValueError("scales must be finite and > 0 (standard deviations in world units); "
                             "a 3DGS file stores their logs: pass np.exp(scales)")
        q = per_splat(rotations, 4, "rotations", "wxyz quaternion")
        if not np.isfinite(q).all() or (np.abs(q).sum(axis=1) == 0).any():
            raise ValueError("rotations must be finite nonzero wxyz quaternions (they are normalized here)")
        o = _float_array(opacities, "opacities").reshape(-1)
        if len(o) not in (1, n):
            raise ValueError(f"opacities must be one number or ({n},), got {len(o)} values")
        if not ((o >= 0) & (o <= 1)).all():
            raise ValueError("opacities must be in [0, 1]; a 3DGS file stores logits: pass 1 / (1 + np.exp(-opacity))")
        c = per_splat(np.ones(3, dtype=np.float32) if colors is None else colors, 3, "colors", "RGB")
        if not ((c >= 0) & (c <= 1)).all():
            raise ValueError("colors must be straight linear RGB in [0, 1] (clip them: np.clip(colors, 0, 1))")
        harmonics = None
        if sh is not None:
            if colors is not None:
                raise ValueError("pass colors or sh, not both: sh's first coefficient is the color's (DC) part")
            h = _float_array(sh, "sh")
            degrees = {1: 0, 4: 1, 9: 2, 16: 3}
            if h.ndim != 3 or h.shape[0] != n or h.shape[2] != 3 or h.shape[1] not in degrees:
                raise ValueError(f"sh must have shape ({n}, k, 3) with k = 1, 4, 9 or 16 coefficients "
                                 f"(degree 0 to 3), got {h.shape}")
            if not np.isfinite(h).all():
                raise ValueError("sh has NaN or Inf coefficients")
            harmonics = (np.ascontiguousarray(h.reshape(-1, 3)), degrees[h.shape[1]])
        return self._native.add_gaussians(m, s, q, np.ascontiguousarray(o), c, (harmonics, splat_depth))

    def primitives(self) -> list[str]:
        """What each mesh is: "triangles", "strands", "particles" or "gaussians"."""
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
