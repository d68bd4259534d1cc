"""Small procedural meshes for scenes, demos and tests.

Each function returns (positions float32 (n, 3), indices uint32 (m, 3)). Triangles wind
counter-clockwise seen from outside (from the front for a quad), no triangle is
degenerate, and every vertex is used.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

Mesh = tuple[np.ndarray, np.ndarray]
Vec3 = Sequence[float]


def _vec3(v: float | Vec3, name: str) -> np.ndarray:
    a = np.asarray(v, dtype=np.float64)
    if a.shape == ():
        a = np.full(3, float(a))
    if a.shape != (3,) or not np.isfinite(a).all():
        raise ValueError(f"{name} must be a finite 3-vector (or a scalar where allowed), got {v!r}")
    return a


def _frame(normal: Vec3, up: Vec3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An orthonormal (right, up, normal) frame; `up` is made orthogonal to `normal`."""
    n = _vec3(normal, "normal")
    if np.linalg.norm(n) == 0:
        raise ValueError("normal must be non-zero")
    n /= np.linalg.norm(n)
    u = _vec3(up, "up")
    u = u - n * u.dot(n)
    if np.linalg.norm(u) < 1e-9:
        raise ValueError("up must not be parallel to normal")
    u /= np.linalg.norm(u)
    return np.cross(u, n), u, n


def _count(v: int, name: str, least: int) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < least:
        raise ValueError(f"{name} must be an integer >= {least}, got {v!r}")
    return int(v)


def _out(positions: np.ndarray, indices: np.ndarray) -> Mesh:
    return np.ascontiguousarray(positions, dtype=np.float32), np.ascontiguousarray(indices, dtype=np.uint32)


def quad(center: Vec3 = (0.0, 0.0, 0.0), size: float | Sequence[float] = (1.0, 1.0),
         normal: Vec3 = (0.0, 0.0, 1.0), up: Vec3 = (0.0, 1.0, 0.0)) -> Mesh:
    """A rectangle of `size` (width along right, height along `up`) facing `normal`:
    4 vertices (bottom-left, bottom-right, top-right, top-left) and 2 triangles."""
    s = np.asarray(size, dtype=np.float64)
    s = np.full(2, float(s)) if s.shape == () else s
    if s.shape != (2,) or not (s > 0).all() or not np.isfinite(s).all():
        raise ValueError(f"size must be positive (a scalar or (width, height)), got {size!r}")
    c = _vec3(center, "center")
    right, u, _ = _frame(normal, up)
    hw, hh = s / 2
    positions = np.array([c - hw * right - hh * u, c + hw * right - hh * u, c + hw * right + hh * u, c - hw * right + hh * u])
    return _out(positions, [[0, 1, 2], [0, 2, 3]])


def box(center: Vec3 = (0.0, 0.0, 0.0), size: float | Vec3 = 1.0) -> Mesh:
    """An axis-aligned box: 8 shared corners and 12 triangles."""
    c, s = _vec3(center, "center"), _vec3(size, "size")
    if not (s > 0).all():
        raise ValueError(f"size must be positive, got {size!r}")
    # Corner k has x from bit 0, y from bit 1, z from bit 2.
    bits = np.array([[(k >> a) & 1 for a in range(3)] for k in range(8)], dtype=np.float64)
    positions = c + (bits - 0.5) * s
    faces = [
        (0, 4, 6, 2), (1, 3, 7, 5),  # -x, +x
        (0, 1, 5, 4), (2, 6, 7, 3),  # -y, +y
        (0, 2, 3, 1), (4, 5, 7, 6),  # -z, +z
    ]
    indices = [t for a, b, cc, d in faces for t in ((a, b, cc), (a, cc, d))]
    return _out(positions, indices)


def uv_sphere(center: Vec3 = (0.0, 0.0, 0.0), radius: float = 1.0, rings: int = 16, segments: int = 32) -> Mesh:
    """A latitude-longitude sphere with single-vertex poles (so no degenerate triangles):
    2 + (rings - 1) * segments vertices and 2 * segments * (rings - 1) triangles."""
    rings, segments = _count(rings, "rings", 2), _count(segments, "segments", 3)
    if not radius > 0:
        raise ValueError(f"radius must be positive, got {radius!r}")
    c = _vec3(center, "center")
    theta = np.pi * np.arange(1, rings) / rings  # polar angle of the inner rings
    phi = 2 * np.pi * np.arange(segments) / segments
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    ring = np.stack([st * np.cos(phi), np.broadcast_to(ct, (rings - 1, segments)), -st * np.sin(phi)], axis=-1)
    positions = np.concatenate([[[0.0, 1.0, 0.0]], ring.reshape(-1, 3), [[0.0, -1.0, 0.0]]]) * radius + c
    south = 1 + (rings - 1) * segments
    j = np.arange(segments)
    k = (j + 1) % segments
    tris = [np.stack([np.zeros(segments, int), 1 + j, 1 + k], axis=1)]
    for r in range(rings - 2):
        a, b = 1 + r * segments, 1 + (r + 1) * segments
        tris.append(np.stack([a + j, b + j, b + k], axis=1))
        tris.append(np.stack([a + j, b + k, a + k], axis=1))
    last = 1 + (rings - 2) * segments
    tris.append(np.stack([last + j, np.full(segments, south), last + k], axis=1))
    return _out(positions, np.concatenate(tris))


def torus(center: Vec3 = (0.0, 0.0, 0.0), major_radius: float = 1.0, minor_radius: float = 0.3,
          major_segments: int = 32, minor_segments: int = 16, axis: Vec3 = (0.0, 1.0, 0.0)) -> Mesh:
    """A ring around `axis` through `center`: major_segments * minor_segments vertices and
    twice as many triangles."""
    major_segments, minor_segments = _count(major_segments, "major_segments", 3), _count(minor_segments, "minor_segments", 3)
    if not 0 < minor_radius < major_radius:
        raise ValueError(f"need 0 < minor_radius < major_radius, got {minor_radius!r} and {major_radius!r}")
    c = _vec3(center, "center")
    a = _vec3(axis, "axis")
    helper = (1.0, 0.0, 0.0) if abs(a[0]) < 0.9 * np.linalg.norm(a) else (0.0, 1.0, 0.0)
    e1, e2, n = _frame(a, helper)
    u = 2 * np.pi * np.arange(major_segments)[:, None] / major_segments
    v = 2 * np.pi * np.arange(minor_segments)[None, :] / minor_segments
    radial = np.cos(u)[..., None] * e2 + np.sin(u)[..., None] * e1  # in the plane of the ring
    ring = major_radius + minor_radius * np.cos(v)
    positions = c + ring[..., None] * radial + (minor_radius * np.sin(v))[..., None] * n
    i = np.arange(major_segments)[:, None]
    j = np.arange(minor_segments)[None, :]
    idx = lambda p, q: (p % major_segments) * minor_segments + q % minor_segments  # noqa: E731
    a0, a1, b0, b1 = idx(i, j), idx(i, j + 1), idx(i + 1, j), idx(i + 1, j + 1)
    tris = np.concatenate([np.stack([a0, b1, b0], -1).reshape(-1, 3), np.stack([a0, a1, b1], -1).reshape(-1, 3)])
    return _out(positions.reshape(-1, 3), tris)


def blob(center: Vec3 = (0.0, 0.0, 0.0), size: float | Vec3 = 1.0, bumps: float = 0.3, rings: int = 24,
         segments: int = 48, seed: int = 0) -> Mesh:
    """A closed, non-convex lump: a uv_sphere whose radius is modulated by a few random
    low-frequency waves (amplitude `bumps`), then scaled by `size` per axis. It folds over
    itself enough that a ray crosses it four or more times in places, like a scanned figure."""
    s = _vec3(size, "size")
    if not (s > 0).all():
        raise ValueError(f"size must be positive, got {size!r}")
    if not 0 <= bumps < 0.5:
        raise ValueError(f"bumps must be in [0, 0.5) so that the radius stays positive, got {bumps!r}")
    positions, indices = uv_sphere(radius=1.0, rings=rings, segments=segments)
    rng = np.random.default_rng(seed)
    d = positions.astype(np.float64)
    waves = rng.normal(0.0, 2.5, (4, 3))
    phase = rng.uniform(0.0, 2 * np.pi, 4)
    # Four waves of amplitude bumps / 2 each: the radius stays in (1 - 2 bumps, 1 + 2 bumps) > 0.
    r = 1.0 + (bumps / 2) * np.sin(d @ waves.T + phase).sum(1)
    return _out(_vec3(center, "center") + d * r[:, None] * s, indices)


def decimate(positions: np.ndarray, indices: np.ndarray, max_triangles: int) -> Mesh:
    """At most `max_triangles` triangles by vertex clustering: vertices are merged per cell of
    a grid over the bounding box (each cluster at its mean), triangles that collapse or repeat
    are dropped; the grid coarsens until the count fits. Topology is not preserved, which is
    harmless for rendering a dense scan as a stand-in for itself."""
    max_triangles = _count(max_triangles, "max_triangles", 1)
    p = np.asarray(positions, dtype=np.float64)
    idx = np.asarray(indices, dtype=np.int64)
    if len(idx) <= max_triangles:
        return _out(p, idx)
    lo, extent = p.min(0), np.ptp(p, 0).max()
    # A closed surface of t triangles sampled at n cells per side keeps about t * (n / sqrt(t / 2))^2
    # triangles; start there and shrink the grid by 10% until the count fits.
    cells = max(2.0, np.sqrt(max_triangles / 2.0))
    while True:
        key = np.floor((p - lo) / extent * cells).astype(np.int64)
        _, cluster = np.unique(key, axis=0, return_inverse=True)
        cluster = cluster.reshape(-1)
        tris = cluster[idx]
        keep = (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 0] != tris[:, 2])
        tris = tris[keep]
        _, first = np.unique(np.sort(tris, axis=1), axis=0, return_index=True)
        tris = tris[np.sort(first)]
        if len(tris) <= max_triangles or cells <= 2.0:
            break
        cells = max(2.0, cells * 0.9)
    counts = np.bincount(cluster)
    centers = np.stack([np.bincount(cluster, weights=p[:, a]) for a in range(3)], 1) / counts[:, None]
    c = centers[tris]
    area2 = np.linalg.norm(np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]), axis=1)
    tris = tris[area2 > 1e-12 * extent ** 2]  # three distinct clusters can still lie on a line
    used, tris = np.unique(tris, return_inverse=True)
    return _out(centers[used], tris.reshape(-1, 3))


def vertex_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Unit normals per vertex: the area-weighted sum of the normals of its triangles."""
    p = np.asarray(positions, dtype=np.float64)
    idx = np.asarray(indices, dtype=np.int64)
    face = np.cross(p[idx[:, 1]] - p[idx[:, 0]], p[idx[:, 2]] - p[idx[:, 0]])  # length = 2 * area
    normals = np.zeros_like(p)
    for corner in range(3):
        np.add.at(normals, idx[:, corner], face)
    return normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
