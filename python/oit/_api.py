"""The public API. Arguments are converted here into what the native layer takes (dtypes,
shapes, Python types), with errors that name the argument; every check of their values
(ranges, finiteness, index bounds, counts) happens once, in the core, whose errors say what to
do."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, TypedDict

import numpy as np

from . import _oit
from ._checks import (
    _I64_MAX,
    _U32_MAX,
    SHADINGS,
    _bool,
    _colors,
    _float_array,
    _instance_colors,
    _int,
    _number,
    _rows,
    _surface,
    _transforms,
    _vector,
)
from ._load import read, warn
from ._memory import available_memory
from ._primitives import PrimitiveMethods
from ._trimesh import trimesh_arrays, trimesh_camera, trimesh_path, trimesh_points
from .imageio import encode_png


class Scene(PrimitiveMethods):
    """Meshes, strands and particles in submission order, composited by the chosen method; opaque ones occlude."""

    def __init__(self) -> None:
        self._native = _oit.Scene()
        # What `from_file` read besides the meshes: their names and the file's cameras.
        self.mesh_names: list[str] = []
        self.cameras: list[FileCamera] = []

    def add_mesh(self, positions: Any, indices: Any, colors: Any, opaque: bool = False, *, normals: Any = None,
                 uvs: Any = None, texture: Any = None, shading: str | None = None, specular: float = 0.0,
                 shininess: float = 32.0, opacity: float = 1.0, two_sided: bool = True,
                 cull_back_faces: bool = False, transform: Any = None) -> int:
        """Adds a triangle mesh and returns its index.

        `transform` (4, 4), affine, places it (world = transform @ [x, y, z, 1]; normals by its
        inverse transpose); without one it is drawn where its vertices are. `add_instances`
        and `set_instances` draw the same vertices again under other transforms.

        positions: (n, 3) float; indices: (m, 3) non-negative integers below n (converted to
        uint32); colors: (n, 4) per vertex or (4,) or (1, 4) for the whole mesh, straight (not
        premultiplied) linear RGBA in [0, 1].

        The surface (docs/shading.md): `normals` (n, 3) per vertex, `uvs` (n, 2) per vertex,
        `texture` (h, w, 4) straight RGBA -- float in [0, 1] taken as linear, or uint8 taken as
        sRGB color with linear alpha -- sampled bilinearly with repeat wrap, row 0 at v = 0.
        `shading`: "unlit" (the vertex color), "flat" (the triangle's normal), "smooth"
        (interpolated vertex normals, angle-weighted when `normals` is None) or "hair" (Kajiya-Kay,
        `normals` read as strand tangents); by default "smooth" with `normals`, else "unlit".
        `specular` >= 0 and `shininess` > 0 weigh the highlight; `opacity` in [0, 1] multiplies alpha;
        `two_sided` turns the normal towards the viewer (else the back is lit as the front's
        reverse side, and stays drawn); `cull_back_faces` drops the triangles seen from behind
        (clockwise on screen), as glTF's `doubleSided: false` asks.
        """
        pos = _rows(_float_array(positions, "positions"), 3, "positions")
        idx = np.asarray(indices)
        if idx.size == 0:
            idx = idx.reshape(0, 3).astype(np.int64) if idx.ndim <= 2 else idx
        if idx.dtype == bool or not np.issubdtype(idx.dtype, np.integer):
            raise TypeError(f"indices must be an integer array (uint32 preferred), got dtype {idx.dtype}")
        idx = _rows(idx, 3, "indices")
        if idx.size:
            # uint32 cannot hold these: the conversion would wrap them into range.
            lo, hi = int(idx.min()), int(idx.max())
            if lo < 0 or hi > _U32_MAX:
                bad = lo if lo < 0 else hi
                raise ValueError(f"indices has an entry {bad}; indices must be in [0, {len(pos)})")
        idx = np.ascontiguousarray(idx, dtype=np.uint32)
        col, opaque = _colors(colors, len(pos), "vertex"), _bool(opaque, "opaque")
        surface = _surface(len(pos), normals, uvs, texture, shading, specular, shininess, opacity, two_sided,
                           cull_back_faces)
        if transform is not None:
            if np.shape(transform) != (4, 4):
                raise ValueError(f"transform must have shape (4, 4), got {np.shape(transform)}: "
                                 "add_instances places a mesh more than once")
            surface["transform"] = _transforms(transform, "transform")[0]
        return self._native.add_mesh(pos, idx, col, opaque, **surface)

    def add_instances(self, mesh: int, transforms: Any, colors: Any = None) -> int:
        """Draws mesh `mesh` (the index add_mesh returned) once more under each of `transforms`
        ((n, 4, 4) or (4, 4), affine), from the same uploaded vertices; `colors` ((n, 4) or (4,),
        in [0, 1]) multiplies each instance's vertex RGBA. Returns the first new instance's index.
        A mirroring transform (negative determinant) keeps the mesh's outside outside: its front
        faces are clockwise, as glTF has it. Submission order: a mesh's instances in order, each
        with all its triangles."""
        index = self._mesh_index(mesh)
        t = _transforms(transforms, "transforms")
        return self._native.add_instances(index, t, _instance_colors(colors, len(t)))

    def set_instances(self, mesh: int, transforms: Any, colors: Any = None) -> None:
        """Replaces the instances of mesh `mesh` (its add_mesh placement included) with
        `transforms` and `colors`, as `add_instances` takes them; with none (shape (0, 4, 4))
        the mesh stays in the scene but is not drawn."""
        index, t = self._mesh_index(mesh), _transforms(transforms, "transforms")
        self._native.set_instances(index, t, _instance_colors(colors, len(t)))

    def instances(self, mesh: int) -> tuple[np.ndarray, np.ndarray]:
        """(transforms (n, 4, 4), colors (n, 4)) of mesh `mesh`'s instances."""
        return self._native.instances(self._mesh_index(mesh))

    def _mesh_index(self, mesh: Any) -> int:
        """The index as the native layer takes it (an i64); the core checks its range."""
        index = _int(mesh, "mesh", "an int (the index add_mesh returned)")
        return max(min(index, _I64_MAX), -_I64_MAX)

    def add_light(self, direction: Sequence[float], color: Sequence[float] = (1.0, 1.0, 1.0), intensity: float = 1.0) -> int:
        """Adds a directional light travelling along `direction` (world space: L is
        -normalize(direction)) with linear RGB `color` times `intensity`; returns its index. With
        no light added, one white headlight travels along the camera's view direction."""
        d, c = _vector(direction, 3, "direction"), _vector(color, 3, "color")
        return self._native.add_light(tuple(d), tuple(c), _number(intensity, "intensity"))

    def clear_lights(self) -> None:
        """Removes every light added (the headlight shines again)."""
        self._native.clear_lights()

    @property
    def lights(self) -> list[tuple[tuple[float, ...], tuple[float, ...], float]]:
        """(direction, color, intensity) of each light added."""
        return [(tuple(d), tuple(c), i) for d, c, i in self._native.lights]

    @property
    def ambient(self) -> tuple[float, float, float]:
        """The ambient light, linear RGB added to every lit fragment's diffuse term (default 0)."""
        a = self._native.ambient
        return (a[0], a[1], a[2])

    @ambient.setter
    def ambient(self, rgb: Sequence[float]) -> None:
        self._native.set_ambient(tuple(_vector(rgb, 3, "ambient")))

    def set_mesh_alpha(self, mesh: int, alpha: float) -> None:
        """Sets every vertex alpha of one mesh."""
        self._native.set_mesh_alpha(self._mesh_index(mesh), _number(alpha, "alpha"))

    @property
    def mesh_count(self) -> int:
        return self._native.mesh_count

    @property
    def triangle_count(self) -> int:
        """Triangles drawn: each mesh's times its instances."""
        return self._native.triangle_count

    @property
    def unique_triangle_count(self) -> int:
        """Triangles uploaded: each mesh's once, however many instances draw it."""
        return self._native.unique_triangle_count

    @property
    def instance_count(self) -> int:
        """Instances drawn over every mesh (a mesh added once counts one)."""
        return self._native.instance_count

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The (lo, hi) corners of the box around every drawn vertex (instances placed); None
        when nothing is drawn."""
        b = self._native.bounds()
        return None if b is None else (np.array(b[0], dtype=np.float64), np.array(b[1], dtype=np.float64))

    @property
    def materials(self) -> list[dict[str, Any]]:
        """Per mesh: opaque, shading, textured, two_sided, cull_back_faces, has_normals, has_uvs,
        the vertex alphas' range (alpha_min, alpha_max), the mean vertex RGBA (color_mean), the
        emissive RGB, the alpha cutoff (None unless alpha-tested, as glTF's MASK), and the base
        color texture's size, sampler and UV transform where there is one (texture: a dict)."""
        return self._native.mesh_materials()

    @classmethod
    def from_file(cls, path: str | os.PathLike, alpha: float | None = None, *, shading: str = "smooth",
                  specular: float = 0.25, point_radius: float | None = None) -> Scene:
        """A scene from a mesh file, as the file has it (docs/loading.md): OBJ with its MTL
        (Kd, d or Tr, map_Kd, map_d), glTF/GLB (a mesh shared by nodes drawn as instances, every
        primitive, baseColorFactor and baseColorTexture, alphaMode and alphaCutoff, doubleSided:
        false culls back faces), PLY (vertex colors with alpha; a PLY of points only is a particle
        set of hard discs of `point_radius`, by default 1/200 of its box's diagonal), STL, or a
        `.hair` strand model (oit.hairfile; shaded "hair", its thickness as the width). `alpha` makes every mesh
        transparent at it; `shading` ("smooth" with the file's normals, "flat" or "unlit") and
        `specular` style every surface. `scene.mesh_names` names the meshes, and
        `scene.cameras` lists the file's cameras (`FileCamera.camera(aspect)` gives an oit.Camera).
        The same loader (oit-core's) reads files for the viewer and `python -m oit render`.
        What the file has that oit does not draw (animations, skins...) is said once a feature
        as an `oit.OitLoadWarning`; a refused file raises ValueError naming the file, the object
        and the rule, and a missing file it refers to (a .bin, an image) FileNotFoundError."""
        return load_file(path, alpha, shading=shading, specular=specular, point_radius=point_radius)[0]

    @classmethod
    def from_trimesh(cls, obj: Any, alpha: float | None = None, color: Sequence[float] | None = None, opaque: bool = False,
                     *, shading: str = "smooth", specular: float = 0.0, shininess: float = 32.0,
                     two_sided: bool = True, point_radius: float | None = None, line_width: float | None = None) -> Scene:
        """A scene from a trimesh Trimesh or Scene, lit (docs/shading.md). Colors come from
        vertex colors, face colors or the material (sRGB 8-bit colors are linearized; a PBR
        baseColorFactor is linear, as glTF has it); texture visuals bring their UVs and image
        (PBR baseColorTexture or the material image). glTF alphaMode is honoured: OPAQUE gives
        an opaque mesh, MASK keeps what passes alphaCutoff (alpha 0 or 1, per texel), BLEND
        and meshes without one are transparent. A Scene's geometry shared by nodes is uploaded once
        and drawn as instances under the nodes' transforms. `color` (RGB or RGBA) and `alpha` override
        the colors; `shading` ("smooth" with the mesh's vertex normals by default, "flat" or
        "unlit"), `specular`, `shininess` and `two_sided` apply to every mesh. A PointCloud is a
        particle set (hard discs of `point_radius`) and a Path3D a strand set (each entity a strand,
        `line_width` wide), both by default 1/200 of their box's diagonal, unlit, in their colors. A
        Scene's camera, where it has one, is `scene.cameras[0]` (a perspective FileCamera)."""
        scene = cls()
        scene.add_trimesh(obj, alpha=alpha, color=color, opaque=opaque, shading=shading, specular=specular,
                          shininess=shininess, two_sided=two_sided, point_radius=point_radius, line_width=line_width)
        import trimesh

        if isinstance(obj, trimesh.Scene) and obj.has_camera:
            scene.cameras.append(FileCamera(*trimesh_camera(obj)))
        return scene

    def add_trimesh(self, obj: Any, alpha: float | None = None, color: Sequence[float] | None = None, opaque: bool = False,
                    *, shading: str = "smooth", specular: float = 0.0, shininess: float = 32.0,
                    two_sided: bool = True, point_radius: float | None = None, line_width: float | None = None) -> None:
        import trimesh

        if shading not in SHADINGS:
            raise ValueError(f"shading must be one of {SHADINGS}, got {shading!r}")
        # A trimesh Scene's geometry is added once and drawn under each node's transform.
        placements: dict[str, list[np.ndarray]] = {}
        if isinstance(obj, trimesh.Scene):
            for node in obj.graph.nodes_geometry:
                transform, name = obj.graph[node]
                placements.setdefault(name, []).append(np.asarray(transform, dtype=np.float64))
            meshes = [(obj.geometry[name], np.stack(ts)) for name, ts in placements.items()]
        else:
            meshes = [(obj, None)]
        def styled(colors: np.ndarray) -> np.ndarray:
            if color is not None:
                c = np.asarray(color, dtype=np.float64)
                if c.shape not in ((3,), (4,)):
                    raise ValueError(f"color must be RGB or RGBA, got shape {c.shape}")
                colors = np.tile(np.append(c, colors[:, 3:4].mean() if c.shape == (3,) else c[3])[:4], (len(colors), 1))
            if alpha is not None:
                if not 0.0 <= float(alpha) <= 1.0:
                    raise ValueError(f"alpha must be in [0, 1], got {alpha}")
                colors[:, 3] = float(alpha)
            return colors

        for m, transforms in meshes:
            if isinstance(m, (trimesh.PointCloud, trimesh.path.Path3D)):
                # Points and polylines are placed on the CPU, once per node.
                for t in [np.eye(4)] if transforms is None else transforms:
                    if isinstance(m, trimesh.PointCloud):
                        p = trimesh_points(m, t)
                        size = point_radius if point_radius is not None else p.default_size
                        self.add_particles(p.positions, size, styled(p.colors), opaque=opaque)
                    else:
                        p = trimesh_path(m, t)
                        if len(p.counts):
                            size = line_width if line_width is not None else p.default_size
                            self.add_strands(p.positions, p.counts, size, styled(p.colors), opaque=opaque)
                continue
            if not isinstance(m, trimesh.Trimesh):
                continue
            t = trimesh_arrays(m)
            colors = styled(t.colors)
            index = self.add_mesh(t.positions, t.faces, colors, opaque=opaque or t.opaque,
                                  normals=t.normals if shading == "smooth" else None, uvs=t.uvs, texture=t.texture,
                                  shading=shading, specular=specular, shininess=shininess, two_sided=two_sided)
            if transforms is not None:
                self.set_instances(index, transforms)  # one identity instance leaves the scene uninstanced


class Camera:
    """A 4x4 view-projection matrix, column-vector convention (clip = M @ [x, y, z, 1]),
    wgpu clip space: x, y in [-1, 1] with y up, z in [0, 1] (smaller is nearer)."""

    def __init__(self, view_proj: Any) -> None:
        if np.iscomplexobj(view_proj):
            raise TypeError("view_proj must be a 4 x 4 array of real numbers, got complex values")
        try:
            m = np.asarray(view_proj, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise TypeError(f"view_proj must be a 4 x 4 array of numbers, got {view_proj!r:.60}") from e
        if m.shape != (4, 4):
            raise ValueError(f"view_proj must be a 4 x 4 matrix, got shape {m.shape}")
        if not np.isfinite(m).all():
            raise ValueError("view_proj has NaN or Inf entries")
        if abs(np.linalg.det(m)) < 1e-300:
            raise ValueError("view_proj is singular: build it with Camera.look_at or Camera.orthographic")
        # The GPU gets the matrix in float32: entries past its range become Inf, and tiny ones
        # flush to 0 (a matrix regular in float64 can be singular there).
        big = float(np.abs(m).max())
        if big > float(np.finfo(np.float32).max):
            raise ValueError(f"view_proj has an entry of magnitude {big:.3g}, past float32 (the GPU's precision): "
                             "rescale it")
        if abs(np.linalg.det(m.astype(np.float32).astype(np.float64))) < 1e-300:
            raise ValueError("view_proj is singular in float32 (the GPU's precision): build it with Camera.look_at "
                             "or Camera.orthographic")
        self.view_proj = np.ascontiguousarray(m)

    def __repr__(self) -> str:
        return f"Camera(view_proj={self.view_proj.tolist()})"

    @property
    def view_direction(self) -> np.ndarray:
        """The unit world-space direction the camera looks along at the center of the picture
        (from the near plane to the far one): the way the headlight travels."""
        return np.array(_oit.view_direction(self.view_proj), np.float64)

    @staticmethod
    def _view(eye: Sequence[float], target: Sequence[float], up: Sequence[float]) -> np.ndarray:
        eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
        f = target - eye
        if np.linalg.norm(f) == 0:
            raise ValueError("eye and target must differ")
        f /= np.linalg.norm(f)
        s = np.cross(f, up)
        if np.linalg.norm(s) < 1e-12:
            raise ValueError("up must not be parallel to the viewing direction")
        s /= np.linalg.norm(s)
        u = np.cross(s, f)
        view = np.eye(4)
        view[0, :3], view[1, :3], view[2, :3] = s, u, -f
        view[:3, 3] = -view[:3, :3] @ eye
        return view

    @classmethod
    def look_at(cls, eye: Sequence[float], target: Sequence[float], fov_y: float = 45.0, near: float = 0.1,
                far: float = 100.0, up: Sequence[float] = (0.0, 1.0, 0.0), aspect: float = 1.0) -> Camera:
        """Right-handed perspective camera; fov_y in degrees; depth 0 at `near`, 1 at `far`."""
        if not (0.0 < fov_y < 180.0):
            raise ValueError(f"fov_y must be in (0, 180) degrees, got {fov_y}")
        if not (0.0 < near < far) or not np.isfinite(far):
            raise ValueError(f"need 0 < near < far (finite), got near={near}, far={far}")
        if not aspect > 0:
            raise ValueError(f"aspect must be positive, got {aspect}")
        f = 1.0 / np.tan(np.radians(fov_y) / 2.0)
        proj = np.zeros((4, 4))
        proj[0, 0], proj[1, 1] = f / aspect, f
        proj[2, 2], proj[2, 3] = far / (near - far), near * far / (near - far)
        proj[3, 2] = -1.0
        return cls(proj @ cls._view(eye, target, up))

    @classmethod
    def orthographic(cls, left: float, right: float, bottom: float, top: float, near: float, far: float,
                     eye: Sequence[float] | None = None, target: Sequence[float] | None = None,
                     up: Sequence[float] = (0.0, 1.0, 0.0)) -> Camera:
        """Orthographic projection of the view volume (right-handed: looking down -z),
        optionally placed with eye/target."""
        if right == left or top == bottom or far == near:
            raise ValueError("orthographic volume must have non-zero extent on every axis")
        proj = np.eye(4)
        proj[0, 0], proj[0, 3] = 2.0 / (right - left), -(right + left) / (right - left)
        proj[1, 1], proj[1, 3] = 2.0 / (top - bottom), -(top + bottom) / (top - bottom)
        proj[2, 2], proj[2, 3] = 1.0 / (near - far), near / (near - far)
        view = cls._view(eye, target, up) if eye is not None and target is not None else np.eye(4)
        return cls(proj @ view)

    @classmethod
    def fit(cls, positions: np.ndarray, direction: Sequence[float] = (0.3, 0.35, 1.0), fov_y: float = 40.0,
            aspect: float = 1.0) -> Camera:
        """A perspective camera that frames the given points' bounding sphere."""
        p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        center = (p.min(0) + p.max(0)) / 2 if len(p) else np.zeros(3)
        radius = max(float(np.linalg.norm(p - center, axis=1).max()) if len(p) else 1.0, 1e-6)
        d = np.asarray(direction, dtype=np.float64)
        d /= np.linalg.norm(d)
        dist = radius / np.sin(np.radians(fov_y) / 2) * 1.05
        near, far = max(dist - radius * 1.5, dist * 1e-3), dist + radius * 1.5
        return cls.look_at(center + d * dist, center, fov_y, near=near, far=far, aspect=aspect)


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


def load_file(path: str | os.PathLike, alpha: float | None = None, *, shading: str = "smooth", specular: float = 0.25,
              viewing: bool = False, point_radius: float | None = None) -> tuple[Scene, str | None]:
    """`Scene.from_file`, and with `viewing` the command line's convenience: when nothing in
    the file is transparent every mesh is drawn at alpha 0.4, and the second value says so.
    What the file has that oit does not draw is said once each, as an `oit.OitLoadWarning`."""
    native, names, cameras, note, warnings = read(path, alpha, shading, specular, viewing, point_radius)
    warn(path, warnings, stacklevel=3)
    scene = Scene()
    scene._native, scene.mesh_names = native, names
    scene.cameras = [FileCamera(c["name"], np.array(c["view"], dtype=np.float64),
                                {k: v for k, v in c.items() if k not in ("name", "view")}) for c in cameras]
    return scene, note


class Stats(TypedDict, total=False):
    """`frame.stats`: what every frame reports; method-specific figures are under `extra`. The
    keys, their types and meanings are the core's (`oit._oit.stats_schema()`,
    crates/oit-core/src/stats.rs); tests/test_contract.py holds this class to them."""

    method: str  # the method's name
    params: dict[str, Any]  # every parameter, defaults filled in
    census: bool  # whether the fragment census ran (render(census=True), or a method that plans from it)
    fragments: int | None  # transparent fragments in front of the opaque depth (summed over samples); None without a census
    max_depth_complexity: int | None  # the most transparent fragments of a pixel; None without a census
    memory_bytes: int  # what the method allocated (oit.memory_bytes gives its formula)
    target_bytes: int  # the frame's targets and readbacks as allocated (tile-sized under a small budget)
    scene_bytes: int  # the scene's GPU buffers (one copy of each mesh, the instance table), apart from the frame's
    expanded_bytes: int  # the part of scene_bytes that strands and particles build on the GPU each frame, not uploaded
    texture_bytes: int  # the part of scene_bytes that textures take (each image once, with its mips, 4 bytes a texel)
    scene_bytes_by_primitive: dict[str, float]  # scene_bytes as 'triangles' (meshes, materials, instances), 'strands' and 'particles'
    gpu_time_ms: float | None  # the passes' GPU time; None where the adapter has no timestamp queries
    pass_times_ms: dict[str, float]  # GPU time per pass; a pass run more than once adds up
    overflow_fragments: int  # fragments a bounded structure could not hold
    wall_time_ms: float  # the render's wall time, readback included
    antialias: int  # samples a pixel (1: no antialiasing)
    antialias_mode: str  # 'frames' or 'coverage'
    tiles: int  # screen tiles the frame was rendered in (1: untiled), summed over antialiasing samples
    geometry_chunks: int  # chunks the transparent geometry was uploaded in (1 unless it passes a binding)
    instances: int  # instances drawn, over every mesh (a mesh added once counts one)
    peak_memory_bytes: int  # memory_bytes + target_bytes: all the frame allocated at once, within memory_budget
    adapter: str  # the adapter's name
    extra: dict[str, float]  # method-specific figures, each declared with its merge rule (oit._oit.extra_merge_rules())
    error_bound_max: float  # the largest of frame.error_bound, where the method derives one


@dataclass
class Frame:
    """One rendered frame. `image`: (h, w, 4) float32, linear; RGB is the final color and A
    the coverage of the background. `depth_complexity`: transparent fragments per pixel, where
    the census ran (`stats["census"]`), else None.
    `error_bound`: (h, w, 3) float32, a bound of |image RGB - the exact composite| at every
    pixel and channel, for the methods that derive one (hybrid, hybrid64, ktab, auto);
    otherwise None, and `error_bound_reason` says why."""

    image: np.ndarray
    stats: Stats
    depth_complexity: np.ndarray | None = field(repr=False)
    error_bound: np.ndarray | None = field(default=None, repr=False)
    error_bound_reason: str = ""

    def _repr_png_(self) -> bytes:
        """The image as PNG (sRGB), so that a frame shows inline in Jupyter."""
        return encode_png(self.image[..., :3])


class Renderer:
    """Renders scenes at one size. `adapter` (or the OIT_ADAPTER variable) picks an adapter by
    a substring of its name; otherwise a hardware adapter is preferred over a software one.
    `memory_budget` (bytes) bounds everything a frame allocates (the method's storage, the
    frame's targets and readbacks: `stats["peak_memory_bytes"]`): where that would pass the
    budget, or the storage a binding, the frame is rendered in screen tiles
    (`frame.stats["tiles"]`), with the same image, or within float32 rounding of it where the
    targets themselves are tiled (docs/methods.md, "Tiles")."""

    def __init__(self, width: int, height: int, adapter: str | None = None, max_binding_bytes: int | None = None,
                 memory_budget: int | None = None) -> None:
        for name, v in (("width", width), ("height", height)):
            if _int(v, name) <= 0:
                raise ValueError(f"{name} must be positive, got {v}")
        if adapter is not None and not isinstance(adapter, str):
            raise TypeError(f"adapter must be a string (part of an adapter's name) or None, "
                            f"got {type(adapter).__name__}")
        # Byte counts as the native layer takes them (i64; the core caps a binding limit at the
        # adapter's and checks both).
        if max_binding_bytes is not None:
            max_binding_bytes = max(min(_int(max_binding_bytes, "max_binding_bytes", "an int (bytes) or None"), _I64_MAX), -_I64_MAX)
        if memory_budget is not None:
            memory_budget = max(min(_int(memory_budget, "memory_budget", "an int (bytes) or None"), _I64_MAX), -_I64_MAX)
        self.width, self.height = int(width), int(height)
        # Sizes past u32 are past every adapter's largest texture: let the core say which
        # size is the largest, about the size asked for.
        w, h = min(self.width, _U32_MAX), min(self.height, _U32_MAX)
        try:
            self._native = _oit.Renderer(w, h, adapter, max_binding_bytes, memory_budget)
        except MemoryError as e:
            if (w, h) == (self.width, self.height):
                raise
            raise MemoryError(str(e).replace(f"{w} x {h}", f"{self.width} x {self.height}", 1)) from None
        if (w, h) != (self.width, self.height):  # no adapter has 2^32-pixel textures
            raise MemoryError(f"{self.width} x {self.height} is past the adapter's largest texture")

    @property
    def adapter_info(self) -> dict:
        return self._native.adapter_info

    @property
    def pipelines_built(self) -> int:
        """Pipelines this adapter's device has compiled so far (renderers on one adapter share
        them): a frame whose configuration was rendered before compiles none."""
        return self._native.pipelines_built

    def render(self, scene: Scene, camera: Camera, method: str = "abuffer",
               background: Sequence[float] = (1.0, 1.0, 1.0), antialias: int = 1, antialias_mode: str = "frames",
               shading_cost: int = 0, census: bool = False, **params: Any) -> Frame:
        """Renders `scene` with `method` (see `oit.methods()`); parameters go as keywords.
        `antialias` S in (1, 2, 4, 8, 16): S samples a pixel on the standard pattern. With
        antialias_mode "frames" each sample is a frame of its own with the method's buffers
        reused, averaged (any method; memory as at one sample, time about S times); with
        "coverage" (abuffer, S = 4) the transparent geometry is rasterized once, multisampled,
        and each stored fragment keeps its sample mask (docs/methods.md, "Antialiasing").
        `shading_cost` N: every shaded fragment evaluates N extra lights whose result is
        discarded, so the image is unchanged and shading costs more (docs/shading.md).
        `census=True` counts every pixel's transparent fragments (`stats["fragments"]`,
        `stats["max_depth_complexity"]`, `frame.depth_complexity`) with one more geometry pass;
        methods that plan their storage from the counts (the A-buffers, peeling, adaptive_lists, mlab_lists,
        auto) and hybrid with tail="compact" (its tail count) always do, the others by default do not, and
        report None there."""
        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be an oit.Scene, got {type(scene).__name__}")
        if not isinstance(camera, Camera):
            raise TypeError(f"camera must be an oit.Camera, got {type(camera).__name__}")
        if not isinstance(method, str):
            raise TypeError(f"method must be a string, got {type(method).__name__}")
        bg = _background(background)
        if not isinstance(antialias_mode, str):
            raise TypeError(f"antialias_mode must be 'frames' or 'coverage', got {antialias_mode!r}")
        cost = _int(shading_cost, "shading_cost", "an int (extra light evaluations per fragment)")
        if not 0 <= cost <= 65536:
            raise ValueError(f"shading_cost must be in [0, 65536], got {cost}")
        if not isinstance(census, bool):
            raise TypeError(f"census must be True or False, got {census!r}")
        image, dc, stats, bound = self._native.render(scene._native, camera.view_proj, method, bg, params,
                                                      _antialias(antialias), antialias_mode, cost, census)
        if bound is not None:
            return Frame(image=image, stats=stats, depth_complexity=dc, error_bound=np.repeat(bound[..., None], 3, axis=2))
        exact = any(m["name"] == method and m["error_bound"] == "exact" for m in methods())
        reason = ("exact method: the error is float32 compositing, at most about (n + 2) * 2**-23 for n layers"
                  if exact else f"no per-pixel bound is derived for '{method}' (docs/methods.md)")
        return Frame(image=image, stats=stats, depth_complexity=dc, error_bound_reason=reason)


ANTIALIAS = tuple(_oit.constants()["ANTIALIAS_SAMPLES"])  # the core's standard patterns


def _antialias(antialias: Any) -> int:
    samples = _int(antialias, "antialias", f"an int, one of {ANTIALIAS} samples a pixel")
    if samples not in ANTIALIAS:
        raise ValueError(f"antialias must be one of {ANTIALIAS} samples a pixel (the standard patterns), got {samples}")
    return samples


def _background(background: Sequence[float]) -> tuple[float, float, float]:
    try:
        bg = np.asarray(background, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"background must be three linear RGB values in [0, 1], got {background!r}") from None
    if bg.shape != (3,) or not np.isfinite(bg).all() or bg.min() < 0 or bg.max() > 1:
        raise ValueError(f"background must be three linear RGB values in [0, 1], got {background!r}")
    return (float(bg[0]), float(bg[1]), float(bg[2]))


def methods() -> list[dict]:
    """Every method and what the core knows of it: name, summary, `exact`, `bounded_memory`,
    `passes`, `params` (defaults and ranges), the adapter `features` it needs, `order` (how
    its image depends on submission order: "bitwise", "bitwise_except_ties", "rounding" or
    "submission") and `order_independent`, `antialias_modes`, `memory` (its "kind" -- "frame",
    "scene" or "slots" -- and "formula") and `error_bound` ("exact", "per_pixel" or "none")."""
    return _oit.methods()


def memory_bytes(method: str, width: int, height: int, slots: int | None = None, **params: Any) -> int | None:
    """GPU bytes `method` allocates for a width x height frame with `params`, from the core's
    formula (what `frame.stats["memory_bytes"]` reports); None when that grows with the scene
    (the storing methods). `auto` chooses its slots per frame: pass `slots` =
    frame.stats["extra"]["auto_slots"] for the bytes of the hybrid it rendered."""
    if not isinstance(method, str):
        raise TypeError(f"method must be a string, got {type(method).__name__}")
    w, h = _int(width, "width"), _int(height, "height")
    if slots is not None:
        slots = _int(slots, "slots")
    return _oit.memory_bytes(method, w, h, params, slots)


def constants() -> dict:
    """The numbers the core, its shaders and these models share (crates/oit-core/src/consts.rs):
    accumulator words, fixed-point scales, the 8-bit alpha's bias and error, the depth maximum
    of packed keys, rounding terms, the antialiasing sample counts."""
    return dict(_CONSTANTS)


_CONSTANTS = _oit.constants()


def reference(scene: Scene, camera: Camera, width: int, height: int, background: Sequence[float] = (1.0, 1.0, 1.0),
              return_mask: bool = False, antialias: int = 1):
    """The CPU float64 reference image (h, w, 4). With return_mask=True, also a boolean
    (h, w) mask of ambiguous pixels: a pixel center on a triangle edge or on two nearly
    equal depths, where a rasterizer may legitimately differ (docs/methods.md). With
    `antialias` S, the mean over the S standard sample positions of each pixel, as
    Renderer.render(..., antialias=S) renders it (ambiguous where any sample is)."""
    if not isinstance(scene, Scene) or not isinstance(camera, Camera):
        raise TypeError("reference(scene, camera, width, height): scene must be an oit.Scene and camera an oit.Camera")
    w, h = _int(width, "width"), _int(height, "height")
    if not (1 <= w <= 65536 and 1 <= h <= 65536):
        raise ValueError(f"width and height must be in [1, 65536], got {w} x {h}")
    # float64 RGBA, the ambiguity mask and the depth complexity: a failed allocation in the
    # core would abort the process, so refuse what this machine cannot hold.
    need = w * h * (4 * 8 + 1 + 4)
    avail = available_memory()
    if w * h > _U32_MAX or (avail is not None and need > avail):
        raise MemoryError(f"reference at {w} x {h} needs {need / 2**30:.1f} GiB"
                          + (f" but {avail / 2**30:.1f} GiB are available" if avail is not None else "")
                          + ": use a smaller size (it costs 37 bytes a pixel)")
    samples = _antialias(antialias)
    image, ambiguous, _ = _oit.reference(scene._native, camera.view_proj, w, h, _background(background), samples)
    return (image, ambiguous) if return_mask else image
