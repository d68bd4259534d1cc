"""Built-in scenes, seeded and self-contained (no files needed). Each function returns a
`BuiltScene`: unpack it as `scene, camera = oit.scenes.hair()`; it also carries the size it
is meant for, the meshes as arrays (so that another renderer can draw the same input), their
lights and what was generated (`meta`). `SCENES` maps names to the functions the benchmark
runs. `hair`, `dragons` and `glass` are lit (docs/shading.md); `smoke`, `foliage` and the
synthetic `stacks` keep their vertex colors."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from . import geometry
from ._api import Camera
from ._meshes import (
    PEER_FAN_SEGMENTS,
    BuiltScene,
    MeshArrays,
    _fan_indices,
    _highlight_normals,
    _mesh,
    from_meshes,
    is_lit,
    unlit,
)

__all__ = ["BuiltScene", "MeshArrays", "from_meshes", "is_lit", "unlit", "hair", "smoke", "foliage",
           "dragons", "glass", "stacks", "splats", "ALPHA_KINDS", "DRAGON_ALPHAS", "DRAGON_FILE", "shared_data_dir",
           "default_dragon_path", "splat_cloud", "SCENES", "SHOWCASE", "PEER_FAN_SEGMENTS"]


ALPHA_KINDS = ("random", "increasing", "worst", "constant")


def stack_alphas(kind: str, n: int, rng: np.random.Generator) -> np.ndarray:
    """Alphas front to back, as in the hybrid paper's Figure 7: random; uniformly increasing
    along depth; its worst case (the front half at 0.05, the back half at 0.9); constant 0.25."""
    if kind == "random":
        return rng.uniform(0.0, 1.0, n)
    if kind == "increasing":
        return np.linspace(0.05, 0.95, n)
    if kind == "worst":
        return np.r_[np.full(n // 2, 0.05), np.full(n - n // 2, 0.9)]
    if kind == "constant":
        return np.full(n, 0.25)
    raise ValueError(f"unknown alpha distribution '{kind}'; choose one of {', '.join(ALPHA_KINDS)}")


def stacks(layers: int = 20, alphas: str = "random", size: tuple[int, int] = (10, 10), seed: int = 0) -> BuiltScene:
    """Synthetic per-pixel fragment stacks: every pixel gets `layers` tiny quads (one per
    layer, covering only that pixel's center) at distinct random depths, with random colors
    and the chosen alpha distribution along depth, submitted in a shuffled order. The camera
    is the identity. `meta` holds each pixel's stack in submission order: z (P, n), rgb
    (P, n, 3), alpha (P, n), with P = width * height in row-major order."""
    w, h = size
    rng = np.random.default_rng(seed)
    pixels = w * h
    z = np.sort(rng.uniform(0.05, 0.95, (pixels, layers)), axis=1)
    alpha = np.stack([stack_alphas(alphas, layers, rng) for _ in range(pixels)])
    rgb = rng.uniform(0.0, 1.0, (pixels, layers, 3))
    # Submission order: a global shuffle of all quads.
    order = rng.permutation(pixels * layers)
    pix, lay = np.divmod(order, layers)
    row, col = np.divmod(pix, w)
    cx = (col + 0.5) * 2.0 / w - 1.0
    cy = 1.0 - (row + 0.5) * 2.0 / h
    hx, hy = 0.3 * 2.0 / w, 0.3 * 2.0 / h
    zz = z[pix, lay]
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], np.float64)
    pos = np.empty((len(order), 4, 3))
    pos[:, :, 0] = cx[:, None] + corners[None, :, 0] * hx
    pos[:, :, 1] = cy[:, None] + corners[None, :, 1] * hy
    pos[:, :, 2] = zz[:, None]
    colors = np.concatenate([rgb[pix, lay], alpha[pix, lay][:, None]], axis=1)
    quad = np.array([[0, 1, 2], [0, 2, 3]])
    idx = (np.arange(len(order))[:, None, None] * 4 + quad[None]).reshape(-1, 3)
    mesh = _mesh(pos.reshape(-1, 3), idx, np.repeat(colors, 4, axis=0))
    # Each pixel's stack in submission order.
    rank = np.empty((pixels, layers), np.int64)
    rank[pix, lay] = np.arange(len(order))
    per_pixel = np.argsort(rank, axis=1)
    take = lambda a: np.take_along_axis(a, per_pixel if a.ndim == 2 else per_pixel[..., None], axis=1)  # noqa: E731
    meta = {"z": take(z), "rgb": take(rgb), "alpha": take(alpha), "layers": layers, "alphas": alphas}
    return from_meshes([mesh], Camera(np.eye(4)), (w, h), meta)


HAIR_PRIMITIVES = ("ribbons", "strands")


def hair(strands: int = 6000, segments: int = 16, seed: int = 0, width: float = 0.01,
         alpha: tuple[float, float] = (0.1, 0.4), primitive: str = "strands") -> BuiltScene:
    """Procedural hair: strands grown from a scalp, falling under gravity and converging into
    a tail, alpha in `alpha`. The defaults give several hundred layers at the worst pixel at
    512 x 512; the papers' model has 15,000 strands. Strands vary in hue and darken at the root.

    `primitive="ribbons"`: triangle ribbons facing the camera (+z), built here, lit with a hair
    highlight baked into the normals: each vertex's normal is the key light's half vector with
    the strand tangent T taken out, so Blinn-Phong's N.H is Kajiya-Kay's sin(T, H).
    `primitive="strands"` (the default): the same polylines as one strand set
    (`Scene.add_strands`), its ribbons built on the GPU facing the eye and shaded "hair"
    (Kajiya-Kay from the tangent, for any eye); `drawn_meshes()` gives its triangles under the
    camera lit as the ribbons are, for peers."""
    if primitive not in HAIR_PRIMITIVES:
        raise ValueError(f"primitive must be one of {HAIR_PRIMITIVES}, got {primitive!r}")
    rng = np.random.default_rng(seed)
    theta = rng.uniform(0.15 * np.pi, 0.85 * np.pi, strands)  # around the top of the head
    phi = rng.uniform(-0.6, 0.6, strands)
    root = np.stack([0.5 * np.cos(theta) * np.cos(phi), 0.45 + 0.5 * np.sin(theta) * 0.6, 0.5 * np.sin(phi)], 1)
    tip = np.stack([rng.normal(0.0, 0.035, strands), np.full(strands, -0.9) + rng.normal(0, 0.04, strands),
                    rng.normal(-0.1, 0.05, strands)], 1)
    t = np.linspace(0.0, 1.0, segments + 1)[None, :, None]
    bulge = np.stack([root[:, 0] * 1.2, np.zeros(strands), root[:, 2] * 0.8], 1)[:, None, :]
    pts = (1 - t) ** 2 * root[:, None] + 2 * t * (1 - t) * (root[:, None] + bulge) + t ** 2 * tip[:, None]
    pts += rng.normal(0, 0.01, pts.shape) * t  # frizz toward the tips
    # Ribbon: offset perpendicular to the strand in the image plane (camera looks down -z).
    d = np.gradient(pts, axis=1)
    side = np.stack([-d[..., 1], d[..., 0], np.zeros_like(d[..., 0])], -1)
    side /= np.linalg.norm(side, axis=-1, keepdims=True) + 1e-12
    half = (width * (1 - 0.3 * t[..., 0]))[..., None] / 2
    left, right = pts - side * half, pts + side * half
    verts = np.stack([left, right], 2).reshape(strands, -1, 3)  # (strands, 2 * (segments + 1), 3)
    base = np.arange(strands)[:, None] * verts.shape[1] + 2 * np.arange(segments)[None, :]
    tris = np.stack([np.stack([base, base + 1, base + 3], -1), np.stack([base, base + 3, base + 2], -1)], 2).reshape(-1, 3)
    hue = rng.uniform(0, 1, strands)
    rgb = np.stack([0.15 + 0.7 * hue, 0.08 + 0.45 * hue, 0.03 + 0.2 * hue], 1)  # dark brown to blond
    a = rng.uniform(alpha[0], alpha[1], strands)
    colors = np.repeat(np.concatenate([rgb, a[:, None]], 1), verts.shape[1], axis=0)
    colors[:, :3] *= np.tile(np.repeat(0.6 + 0.4 * t[0, :, 0], 2), strands)[:, None]  # darker at the root
    eye = np.array([0.0, 0.0, 2.6])
    key = np.array([-0.3, -0.6, -1.0])  # where the key light travels
    camera = Camera.look_at(eye=tuple(eye), target=(0.0, -0.1, 0.0), fov_y=45.0, near=1.0, far=4.0)
    meta = {"strands": strands, "primitive": primitive}
    lights, ambient = [(tuple(key), (1.0, 0.95, 0.9), 0.8)], (0.35, 0.35, 0.35)
    if primitive == "strands":
        # The ribbons' left corners carry each point's color; the width tapers as theirs.
        point_colors = colors.reshape(strands, -1, 2, 4)[:, :, 0].reshape(-1, 4).astype(np.float32)
        widths = np.broadcast_to(width * (1 - 0.3 * t[..., 0]), (strands, segments + 1)).reshape(-1).astype(np.float32)
        set_ = MeshArrays(pts.reshape(-1, 3).astype(np.float32), np.zeros((0, 3), np.uint32), point_colors,
                          surface={"shading": "hair", "specular": 0.3, "shininess": 48.0},
                          primitive={"kind": "strands", "counts": np.full(strands, segments + 1), "widths": widths})
        return from_meshes([set_], camera, (512, 512), meta, lights, ambient)
    tangent = np.repeat(d / (np.linalg.norm(d, axis=-1, keepdims=True) + 1e-12), 2, axis=1).reshape(-1, 3)
    p = verts.reshape(-1, 3)
    normals = _highlight_normals(key, (eye - p) / np.linalg.norm(eye - p, axis=1, keepdims=True), tangent)
    mesh = _mesh(p, tris, colors.astype(np.float32), normals=normals.astype(np.float32), specular=0.3, shininess=48.0)
    return from_meshes([mesh], camera, (512, 512), meta, lights, ambient)


def smoke(particles: int = 600, seed: int = 0, alpha: tuple[float, float] = (0.05, 0.25), segments: int = 10,
          primitive: str = "particles") -> BuiltScene:
    """A smoke plume of soft particle billboards: each particle is a disc facing the camera,
    with its alpha in `alpha` at the center falling linearly to 0 at the rim. Particles rise
    from an emitter, widen and drift with height, glow orange near the source and turn gray
    above; they are submitted in random (spawn) order.

    `primitive="fans"`: each disc a fan of `segments` triangles facing +z, built here (its
    alpha linear across each triangle). `primitive="particles"` (the default): one particle set
    (`Scene.add_particles`, falloff "linear"), true discs facing the eye built on the GPU;
    `drawn_meshes()` gives fans of those discs under the camera, for peers."""
    if primitive not in ("fans", "particles"):
        raise ValueError(f"primitive must be 'fans' or 'particles', got {primitive!r}")
    rng = np.random.default_rng(seed)
    h = rng.uniform(0.0, 1.0, particles) ** 0.8  # height along the plume, denser near the source
    spread = 0.06 + 0.3 * h
    center = np.stack([0.3 * h ** 2 + rng.normal(0.0, 1.0, particles) * spread, -0.85 + 1.7 * h,
                       rng.normal(0.0, 1.0, particles) * spread], 1)
    radius = (0.1 + 0.3 * h) * rng.uniform(0.7, 1.3, particles)
    angle = 2 * np.pi * np.arange(segments) / segments + rng.uniform(0, 2 * np.pi, (particles, 1))
    ring = np.stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)], -1) * radius[:, None, None]
    verts = np.concatenate([center[:, None], center[:, None] + ring], 1)  # (particles, 1 + segments, 3)
    tris = _fan_indices(particles, segments)  # counter-clockwise seen from +z
    t = np.clip(h * 1.6, 0.0, 1.0)[:, None]
    rgb = ((1 - t) * np.array([1.0, 0.42, 0.08]) + t * np.array([0.3, 0.3, 0.33])) * rng.uniform(0.75, 1.1, (particles, 1))
    a = rng.uniform(alpha[0], alpha[1], particles)
    colors = np.zeros((particles, segments + 1, 4))
    colors[:, :, :3] = np.clip(rgb, 0.0, 1.0)[:, None]
    colors[:, 0, 3] = a  # the rim keeps alpha 0: soft edges
    camera = Camera.look_at(eye=(0.0, 0.0, 3.0), target=(0.1, 0.0, 0.0), fov_y=45.0, near=1.0, far=5.0)
    meta = {"particles": particles, "primitive": primitive}
    if primitive == "particles":
        set_ = MeshArrays(center.astype(np.float32), np.zeros((0, 3), np.uint32), colors[:, 0].astype(np.float32),
                          primitive={"kind": "particles", "radii": radius.astype(np.float32), "falloff": "linear"})
        return from_meshes([set_], camera, (512, 512), meta)
    return from_meshes([_mesh(verts.reshape(-1, 3), tris, colors.reshape(-1, 4))], camera, (512, 512), meta)


def foliage(leaves: int = 5000, seed: int = 0) -> BuiltScene:
    """A tree crown of leaf quads (kites) in random orientations around an opaque trunk, with
    mixed alphas: most leaves 0.3-0.7, a quarter nearly opaque (0.85-1), the rest faint
    (0.05-0.2). The defaults give about 45 layers at the worst pixel."""
    rng = np.random.default_rng(seed)
    # Leaves fill an ellipsoidal crown, denser toward its surface.
    d = rng.normal(size=(leaves, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    center = d * rng.uniform(0.0, 1.0, (leaves, 1)) ** 0.4 * np.array([0.75, 0.55, 0.75]) + np.array([0.0, 0.25, 0.0])
    normal = rng.normal(size=(leaves, 3))
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    up = np.cross(normal, rng.normal(size=(leaves, 3)))
    up /= np.linalg.norm(up, axis=1, keepdims=True)
    right = np.cross(up, normal)
    length = rng.uniform(0.1, 0.2, (leaves, 1))
    # Kite: stem, left, tip, right (counter-clockwise seen from `normal`).
    shape = [(0.0, -0.5), (-0.3, 0.0), (0.0, 0.5), (0.3, 0.0)]
    verts = np.stack([center + length * (x * right + y * up) for x, y in shape], 1)
    tris = (np.arange(leaves)[:, None, None] * 4 + np.array([[0, 1, 2], [0, 2, 3]])[None]).reshape(-1, 3)
    green = np.array([0.08, 0.35, 0.05]) + rng.uniform(0.0, 1.0, (leaves, 1)) * np.array([0.35, 0.3, 0.0])
    kind = rng.uniform(0.0, 1.0, leaves)
    a = np.where(kind < 0.6, rng.uniform(0.3, 0.7, leaves),
                 np.where(kind < 0.85, rng.uniform(0.85, 1.0, leaves), rng.uniform(0.05, 0.2, leaves)))
    colors = np.repeat(np.concatenate([green, a[:, None]], 1), 4, axis=0)
    colors[2::4, :3] = np.clip(colors[2::4, :3] * 1.3, 0.0, 1.0)  # lighter tips
    trunk = geometry.box((0.0, -0.55, 0.0), (0.16, 0.9, 0.16))
    meshes = [_mesh(*trunk, (0.25, 0.14, 0.06, 1.0), opaque=True), _mesh(verts.reshape(-1, 3), tris, colors)]
    camera = Camera.look_at(eye=(0.4, 0.3, 2.9), target=(0.0, 0.0, 0.0), fov_y=45.0, near=1.0, far=5.0)
    return from_meshes(meshes, camera, (512, 512), {"leaves": leaves})


def glass(detail: int = 32) -> BuiltScene:
    """CAD-like nested glass around an opaque part: an opaque torus inside a glass sphere,
    inside a glass box that the sphere pokes through, crossed by a glass ring that cuts
    through both; high alphas (0.45-0.7), few layers. All shells share one center, so sorting
    whole meshes by depth cannot order their intersecting surfaces: `sorted` is visibly wrong
    here. Lit by a key and a fill light with specular highlights; the box is flat-shaded."""
    core = geometry.torus((0.0, 0.0, 0.0), 0.28, 0.1, detail, detail // 2, axis=(1.0, 1.0, 0.0))
    sphere = geometry.uv_sphere((0.0, 0.0, 0.0), 0.62, rings=detail, segments=2 * detail)
    box = geometry.box((0.0, 0.0, 0.0), 1.0)
    ring = geometry.torus((0.0, 0.0, 0.0), 0.75, 0.1, 2 * detail, detail // 2, axis=(1.0, 0.4, 0.3))
    # Submitted outermost first: the worst order for blending in submission order.
    shiny = dict(shading="smooth", specular=0.5, shininess=64.0)
    meshes = [
        _mesh(*ring, (0.95, 0.55, 0.1, 0.7), **shiny),
        _mesh(*box, (0.6, 0.85, 0.95, 0.45), shading="flat", specular=0.4, shininess=64.0),
        _mesh(*sphere, (0.1, 0.3, 0.9, 0.55), normals=sphere[0] / 0.62, **shiny),
        _mesh(*core, (0.8, 0.1, 0.1, 1.0), opaque=True, shading="smooth", specular=0.3, shininess=32.0),
    ]
    camera = Camera.look_at(eye=(1.2, 0.9, 1.8), target=(0.0, 0.0, 0.0), fov_y=45.0, near=1.0, far=5.0)
    lights = [((-0.5, -0.7, -0.6), (1.0, 0.97, 0.92), 0.75), ((0.8, -0.2, -0.3), (0.6, 0.7, 1.0), 0.3)]
    return from_meshes(meshes, camera, (512, 512), {}, lights=lights, ambient=(0.35, 0.35, 0.35))


def _quaternions_to(normals: np.ndarray) -> np.ndarray:
    """wxyz quaternions turning +z onto each unit normal (a half-turn about x for -z)."""
    w = 1.0 + normals[:, 2]
    q = np.stack([w, -normals[:, 1], normals[:, 0], np.zeros(len(normals))], 1)
    q[w < 1e-6] = (0.0, 1.0, 0.0, 0.0)
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def splats(count: int = 20000, kind: str = "surface", seed: int = 0, splat_depth: str = "center") -> BuiltScene:
    """Gaussian splats (`Scene.add_gaussians`), as 3D Gaussian splatting fits them, in one set.

    `kind="surface"`: flat Gaussians fitted to a bumpy blob's surface, each lying in the tangent
    plane at a point drawn by area (in-plane spread about half the point spacing, a tenth of
    that across), colored by their normal, mostly opaque (0.6-0.95): overlapping discs, a few
    deep where the surface folds or turns edge-on. `kind="cloud"`: anisotropic Gaussians in random orientations
    filling an ellipsoid, faint (0.03-0.25) and deep, as a volume of smoke is fitted. Any count
    from thousands to millions. `splat_depth`: the set's fragment depth, "center" or "ray"
    (`Scene.add_gaussians`)."""
    if kind not in ("surface", "cloud"):
        raise ValueError(f"kind must be 'surface' or 'cloud', got {kind!r}")
    if splat_depth not in ("center", "ray"):
        raise ValueError(f"splat_depth must be 'center' or 'ray', got {splat_depth!r}")
    if count < 1:
        raise ValueError(f"count must be at least 1, got {count}")
    rng = np.random.default_rng(seed)
    if kind == "surface":
        positions, indices = geometry.blob((0.0, 0.0, 0.0), 1.1, bumps=0.25)
        tri = positions[indices]
        cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        area = 0.5 * np.linalg.norm(cross, axis=1)
        which = rng.choice(len(indices), count, p=area / area.sum())
        u, v = rng.uniform(0.0, 1.0, (2, count))
        flip = u + v > 1.0
        u[flip], v[flip] = 1.0 - u[flip], 1.0 - v[flip]
        t = tri[which]
        means = t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + v[:, None] * (t[:, 2] - t[:, 0])
        normals = cross[which] / np.linalg.norm(cross[which], axis=1, keepdims=True)
        spacing = np.sqrt(area.sum() / count)
        spread = 0.5 * spacing * rng.uniform(0.6, 1.0, (count, 1))
        scales = np.concatenate([spread, spread * rng.uniform(0.6, 1.0, (count, 1)), 0.1 * spread], 1)
        rotations = _quaternions_to(normals)
        rgb = np.clip(0.25 + 0.6 * (0.5 + 0.5 * normals) * np.array([1.0, 0.8, 0.6]), 0.0, 1.0)
        opacity = rng.uniform(0.6, 0.95, count)
    else:
        d = rng.normal(size=(count, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        means = d * rng.uniform(0.0, 1.0, (count, 1)) ** (1 / 3) * np.array([0.9, 0.6, 0.6])
        base = 0.6 * count ** (-1 / 3)
        scales = base * rng.uniform(0.3, 1.0, (count, 3))
        rotations = rng.normal(size=(count, 4))
        rotations /= np.linalg.norm(rotations, axis=1, keepdims=True)
        height = (means[:, 1] + 0.6) / 1.2
        rgb = np.clip(np.array([0.55, 0.6, 0.7]) + 0.35 * height[:, None] * np.array([0.6, 0.5, 0.3]), 0.0, 1.0)
        opacity = rng.uniform(0.03, 0.25, count)
    colors = np.concatenate([rgb, opacity[:, None]], 1).astype(np.float32)
    primitive = {"kind": "gaussians", "scales": scales.astype(np.float32), "rotations": rotations.astype(np.float32),
                 "sh": None, "degree": 0, "splat_depth": splat_depth}
    set_ = MeshArrays(means.astype(np.float32), np.zeros((0, 3), np.uint32), colors, primitive=primitive)
    camera = Camera.look_at(eye=(0.6, 0.5, 2.8), target=(0.0, 0.0, 0.0), fov_y=45.0, near=1.0, far=5.0)
    return from_meshes([set_], camera, (512, 512), {"splats": count, "kind": kind, "splat_depth": splat_depth})


# The opacities of the hybrid paper's 22 dragons (Maule et al. 2013), front to back.
DRAGON_ALPHAS = (0.05, 0.1, 0.05, 0.1, 0.2, 0.9, 0.2, 0.1, 0.05, 0.1, 0.05) * 2
DRAGON_FILE = "dragon-100k.obj"


def shared_data_dir() -> Path | None:
    """The optional mesh folder: $OIT_DATA when set, else the first `shared/data` found beside
    the working directory or the package (walking up from each), else None. An installed wheel
    lives in site-packages, far from the checkout, so the working directory is searched too."""
    env = os.environ.get("OIT_DATA")
    if env:
        return Path(env) if Path(env).is_dir() else None
    for start in (Path.cwd(), Path(__file__).resolve().parent):
        for folder in (start, *start.parents):
            candidate = folder / "shared" / "data"
            if candidate.is_dir():
                return candidate
    return None


def default_dragon_path() -> Path | None:
    """shared_data_dir()/dragon-100k.obj when it exists, else None (the stand-in is used)."""
    folder = shared_data_dir()
    return folder / DRAGON_FILE if folder is not None and (folder / DRAGON_FILE).is_file() else None


def _dragon_mesh(path: str | os.PathLike | None, max_triangles: int) -> tuple[np.ndarray, np.ndarray, str]:
    """The dragon (or the stand-in blob) centered, longest side 1, decimated to max_triangles."""
    if path is not None:
        import trimesh

        if not Path(path).is_file():
            raise ValueError(f"no such mesh file: {path}")
        mesh = trimesh.load(path, force="mesh")
        positions, indices, source = np.asarray(mesh.vertices), np.asarray(mesh.faces), Path(path).name
    else:
        positions, indices = geometry.blob(size=(1.0, 0.55, 0.4), bumps=0.3, rings=48, segments=96, seed=3)
        source = "stand-in blob"
    positions, indices = geometry.decimate(positions, indices, max_triangles)
    p = positions.astype(np.float64)
    p = (p - (p.min(0) + p.max(0)) / 2) / np.ptp(p, 0).max()
    return p, indices, source


def dragons(path: str | os.PathLike | None = "default", max_triangles: int = 8000) -> BuiltScene:
    """The hybrid paper's 22 aligned dragons with its opacities (DRAGON_ALPHAS), one after
    another along the view, each lit by one light (two-sided, with a specular highlight). `path`:
    the mesh (anything trimesh loads); "default" uses dragon-100k.obj from shared_data_dir()
    when present, and None or its absence gives a built-in non-convex stand-in. One dragon is
    uploaded, decimated to at most `max_triangles` (22 full 100k-triangle dragons are slow on a
    software rasterizer), and drawn as 22 instances, each with its hue and alpha as a color
    factor (`built.drawn_meshes()` gives the copies). `meta["mesh"]` says which mesh was used."""
    if isinstance(path, str) and path == "default":
        path = default_dragon_path()
    p, idx, source = _dragon_mesh(path, max_triangles)
    normals = geometry.vertex_normals(p, idx).astype(np.float32)
    # One dragon, drawn 22 times: each instance offset along the view, with its hue and alpha.
    n = len(DRAGON_ALPHAS)
    transforms = np.tile(np.eye(4), (n, 1, 1))
    factors = np.ones((n, 4), dtype=np.float32)
    for i, a in enumerate(DRAGON_ALPHAS):
        hue = i / n
        base = 0.5 + 0.4 * np.cos(2 * np.pi * (hue + np.array([0.0, 1 / 3, 2 / 3])))
        factors[i] = (*np.clip(base, 0.0, 1.0), a)
        transforms[i, :3, 3] = (0.06 * np.sin(i * 1.3), 0.03 * np.cos(i * 0.7), -0.3 * i)
    dragon = _mesh(p, idx, np.ones(4), normals=normals, specular=0.35, shininess=24.0)
    dragon.transforms, dragon.instance_colors = transforms, factors
    meshes = [dragon]
    camera = Camera.look_at(eye=(0.6, 0.5, 2.2), target=(-0.45, -0.3, -2.5), fov_y=36.0, near=1.2, far=10.0)
    return from_meshes(meshes, camera, (512, 512), {"mesh": source, "instances": len(DRAGON_ALPHAS)},
                       lights=[((-0.4, -0.8, -0.45), (1.0, 1.0, 1.0), 0.65)], ambient=(0.35, 0.35, 0.35))


def splat_cloud(count: int = 20000, seed: int = 0, splat_depth: str = "center") -> BuiltScene:
    """`splats(count, kind="cloud")`: faint anisotropic Gaussians filling an ellipsoid."""
    return splats(count, "cloud", seed, splat_depth)


# Every builder by name; SHOWCASE is what the benchmark runs by default (stacks is the Figure 7
# experiment's synthetic input, sized to the frame; the splat scenes are chosen by name, and
# `python -m oit bench --splats` measures them).
SCENES = {"hair": hair, "smoke": smoke, "foliage": foliage, "dragons": dragons, "glass": glass, "stacks": stacks,
          "splats": splats, "splat_cloud": splat_cloud}
SHOWCASE = ("hair", "smoke", "foliage", "dragons", "glass")
