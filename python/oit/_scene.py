"""`oit.Scene`: meshes, strands and particles from arrays, files and trimesh objects, converted
into what the native layer takes (dtypes, shapes, Python types) with errors that name the
argument; every check of their values happens once, in the core."""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from . import _oit
from ._camera import FileCamera
from ._checks import (
    _I64_MAX,
    _U32_MAX,
    SHADINGS,
    SURFACE,
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
from ._primitives import PrimitiveMethods
from ._trimesh import trimesh_arrays, trimesh_camera, trimesh_path, trimesh_points


class Scene(PrimitiveMethods):
    """Meshes, strands and particles in submission order, composited by the chosen method; opaque ones occlude."""

    def __init__(self) -> None:
        self._native = _oit.Scene()
        # What `from_file` read besides the meshes: their names and the file's cameras.
        self.mesh_names: list[str] = []
        self.cameras: list[FileCamera] = []

    def add_mesh(self, positions: Any, indices: Any, colors: Any, opaque: bool = False, *, normals: Any = None,
                 uvs: Any = None, texture: Any = None, shading: str | None = None,
                 specular: float = SURFACE["specular"], shininess: float = SURFACE["shininess"],
                 opacity: float = SURFACE["opacity"], two_sided: bool = SURFACE["two_sided"],
                 cull_back_faces: bool = SURFACE["cull_back_faces"], transform: Any = None) -> int:
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
        place = None
        if transform is not None:
            if np.shape(transform) != (4, 4):
                raise ValueError(f"transform must have shape (4, 4), got {np.shape(transform)}: "
                                 "add_instances places a mesh more than once")
            place = _transforms(transform, "transform")[0]
        return self._native.add_mesh(pos, idx, col, opaque, surface, place)

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
        set of hard discs of `point_radius`, by default 1/200 of its box's diagonal; one with 3D
        Gaussian splatting's properties is a splat set, `add_gaussians`), STL, or a
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
                     *, shading: str = "smooth", specular: float = SURFACE["specular"],
                     shininess: float = SURFACE["shininess"], two_sided: bool = SURFACE["two_sided"],
                     point_radius: float | None = None, line_width: float | None = None) -> Scene:
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
                    *, shading: str = "smooth", specular: float = SURFACE["specular"],
                    shininess: float = SURFACE["shininess"], two_sided: bool = SURFACE["two_sided"],
                    point_radius: float | None = None, line_width: float | None = None) -> None:
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
