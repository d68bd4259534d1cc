# The native module (crates/oit-py/src). It is private: python/oit/_scene.py and _render.py wrap
# it. Keep this file in step with the #[pyclass], #[pymethods] and #[pyfunction] items there;
# tests/test_stub.py checks that the names match.

from typing import Any, Literal, TypedDict, final

import numpy as np
import numpy.typing as npt

# A frame's stats: the TypedDict is written once, in the public API, and tests/test_contract.py
# holds it to the core's table (crates/oit-core/src/stats/).
from oit._api import Stats as _Stats

_ParamValue = int | float | str

class _AdapterInfo(TypedDict):
    name: str
    backend: str
    device_type: str
    driver: str
    driver_info: str
    timestamps: bool
    float32_blendable: bool
    int64_atomic_min_max: bool
    max_storage_binding_bytes: int
    loop_limit: int | None  # iterations one shader invocation may loop (the device profile's)
    features: list[str]
    methods: list[str]  # the methods this adapter's features allow

class _ParamInfo(TypedDict, total=False):
    name: str
    doc: str
    type: Literal["int", "float", "choice"]
    min: int | float  # int and float only
    max: int | float  # int and float only
    step: int  # int only: valid values are min, min + step, .., max
    choices: list[str]  # choice only
    default: _ParamValue

class _MemoryInfo(TypedDict):
    kind: Literal["frame", "scene", "slots"]
    formula: str

class _TilingInfo(TypedDict, total=False):
    kind: Literal["formula", "census"]
    per_pixel: int  # census only: bytes a pixel, a stored fragment, a transparent triangle
    per_fragment: int
    per_triangle: int

# The values passed as one argument (crates/oit-py/src/surface.rs), every key present.
class _Surface(TypedDict):
    normals: npt.NDArray[np.float32] | None
    uvs: npt.NDArray[np.float32] | None
    texture: npt.NDArray[np.float32] | None
    shading: str
    specular: float
    shininess: float
    opacity: float
    two_sided: bool
    cull_back_faces: bool

class _Look(TypedDict):
    shading: str
    specular: float
    shininess: float
    opacity: float

class _FrameOptions(TypedDict):
    background: tuple[float, float, float]
    antialias: int
    antialias_mode: str
    shading_cost: int
    census: bool

class _MethodInfo(TypedDict):
    name: str
    summary: str
    exact: bool
    bounded_memory: bool
    passes: list[str]
    params: list[_ParamInfo]
    features: list[str]
    order: Literal["bitwise", "bitwise_except_ties", "rounding", "submission"]
    order_independent: bool
    antialias_modes: list[Literal["frames", "coverage"]]
    memory: _MemoryInfo
    error_bound: Literal["exact", "per_pixel", "none"]
    tiling: _TilingInfo
    census: bool  # whether it plans from the fragment census (and so always runs it)
    main: str | None  # the int parameter its trade moves along (what `oit compare` sweeps)

@final
class Scene:
    """Meshes in submission order (validated on the way in)."""

    def __init__(self) -> None: ...
    def add_mesh(
        self,
        positions: npt.NDArray[np.float32],
        indices: npt.NDArray[np.uint32],
        colors: npt.NDArray[np.float32],
        opaque: bool,
        surface: _Surface,
        transform: npt.NDArray[np.float64] | None = None,
    ) -> int:
        """positions (n, 3) float32, indices (m, 3) uint32, colors (n, 4) or (1, 4) float32; the
        surface a dict (surface.rs): normals (n, 3) and uvs (n, 2) float32 or None, texture (h, w,
        4) float32 linear RGBA or None, shading "unlit", "flat", "smooth" or "hair", specular,
        shininess, opacity, two_sided, cull_back_faces. `transform` (4, 4) float64 places it (else
        it is drawn where its vertices are)."""
    def add_strands(
        self,
        points: npt.NDArray[np.float32],
        counts: npt.NDArray[np.uint32],
        widths: npt.NDArray[np.float32],
        colors: npt.NDArray[np.float32],
        opaque: bool,
        look: _Look,
    ) -> int:
        """A strand set: points (n, 3), counts (strands,) uint32, widths (n,) or (1,), colors (n, 4)
        or (1, 4) float32; the look a dict of shading ("unlit" or "hair"), specular, shininess and
        opacity."""
    def add_particles(
        self,
        centers: npt.NDArray[np.float32],
        radii: npt.NDArray[np.float32],
        colors: npt.NDArray[np.float32],
        opaque: bool,
        falloff: str = "hard",
        opacity: float = 1.0,
    ) -> int:
        """A particle set: centers (n, 3), radii (n,) or (1,), colors (n, 4) or (1, 4) float32."""
    def add_gaussians(
        self,
        means: npt.NDArray[np.float32],
        scales: npt.NDArray[np.float32],
        rotations: npt.NDArray[np.float32],
        opacities: npt.NDArray[np.float32],
        colors: npt.NDArray[np.float32],
        look: tuple[tuple[npt.NDArray[np.float32], int] | None, str],
    ) -> int:
        """A splat set: means (n, 3), scales (n, 3), wxyz rotations (n, 4), opacities (n,), RGB
        colors (n, 3) float32, each with n rows or one; `look`: spherical harmonics ((n k, 3)
        coefficients, k = (degree + 1)², the DC first; degree) in place of the colors, or None,
        and the fragment depth ("center" or "ray")."""
    def to_triangles(
        self, mesh: int, view_proj: npt.NDArray[np.float64]
    ) -> tuple[
        npt.NDArray[np.float32],
        npt.NDArray[np.uint32],
        npt.NDArray[np.float32],
        npt.NDArray[np.float32] | None,
        npt.NDArray[np.float32] | None,
    ]:
        """Mesh `mesh` as the triangles it is drawn as under `view_proj`."""
    def mesh_primitives(self) -> list[str]:
        """"triangles", "strands" or "particles" per mesh."""
    def add_instances(
        self, mesh: int, transforms: npt.NDArray[np.float64], colors: npt.NDArray[np.float32] | None = None
    ) -> int:
        """Appends instances to mesh `mesh`: transforms (n, 4, 4) float64, colors (n, 4) float32
        factors or None; returns the first new instance's index."""
    def set_instances(
        self, mesh: int, transforms: npt.NDArray[np.float64], colors: npt.NDArray[np.float32] | None = None
    ) -> None:
        """Replaces the instances of mesh `mesh` (none: it stays uploaded but is not drawn)."""
    def instances(self, mesh: int) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float32]]:
        """Transforms (n, 4, 4) row-major and color factors (n, 4) of mesh `mesh`'s instances."""
    def add_light(self, direction: tuple[float, float, float], color: tuple[float, float, float], intensity: float) -> int:
        """A directional light travelling along `direction` (world space); returns its index."""
    def clear_lights(self) -> None: ...
    @property
    def lights(self) -> list[tuple[list[float], list[float], float]]:
        """(direction, color, intensity) per light."""
    @property
    def ambient(self) -> list[float]: ...
    def set_ambient(self, rgb: tuple[float, float, float]) -> None: ...
    def mesh_surfaces(self) -> list[tuple[str, bool]]:
        """(shading, textured) per mesh."""
    def set_mesh_alpha(self, mesh: int, alpha: float) -> None: ...
    @property
    def mesh_count(self) -> int: ...
    @property
    def triangle_count(self) -> int:
        """Triangles drawn, instances included."""
    @property
    def unique_triangle_count(self) -> int:
        """Triangles uploaded: each mesh's once."""
    @property
    def instance_count(self) -> int: ...
    def mesh_materials(self) -> list[dict[str, Any]]:
        """Per mesh: what its material and colors are (tests and `Scene.materials`)."""
    def bounds(self) -> tuple[list[float], list[float]] | None:
        """The smallest and largest corner of every drawn vertex's box (instances placed); None
        when nothing is drawn."""
    def mesh_summary(self) -> list[tuple[int, int, bool]]:
        """(triangles, vertices, opaque) per mesh."""

@final
class Renderer:
    def __init__(
        self,
        width: int,
        height: int,
        adapter: str | None = None,
        max_binding_bytes: int | None = None,
        memory_budget: int | None = None,
    ) -> None: ...
    @property
    def adapter_info(self) -> _AdapterInfo: ...
    @property
    def pipelines_built(self) -> int: ...
    def render(
        self,
        scene: Scene,
        view_proj: npt.NDArray[np.float64],
        method: str,
        params: dict[str, _ParamValue],
        options: _FrameOptions,
    ) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint32] | None, _Stats, npt.NDArray[np.float32] | None]:
        """Returns (image (h, w, 4) float32, depth complexity (h, w) uint32 or None without a
        census, stats dict, error bound (h, w) float32 or None); `options` a dict (surface.rs):
        background, antialias, antialias_mode, shading_cost, census."""

def methods() -> list[_MethodInfo]:
    """Every method: name, summary, exact, bounded memory, passes, parameters."""

def memory_bytes(method: str, width: int, height: int, params: dict[str, _ParamValue], slots: int | None = None) -> int | None:
    """GPU bytes `method` allocates at `width` x `height` with `params` (its memory formula), or
    None when that grows with the scene; `slots` is auto's k-TAB slots in all."""

def extra_merge_rules() -> list[tuple[str, str]]:
    """Every extra number a method reports and how tiles and samples merge it: sum, max or mean."""

def stats_schema() -> list[tuple[str, str, str]]:
    """The keys of a frame's stats: (name, Python type, meaning), in order (crates/oit-core/src/stats/)."""

class _SurfaceDefaults(TypedDict):
    shading: str
    specular: float
    shininess: float
    opacity: float
    two_sided: bool
    cull_back_faces: bool

def surface_defaults() -> _SurfaceDefaults:
    """The surface a mesh has unless told otherwise (the core's `Material::default()`)."""

def constants() -> dict[str, Any]:
    """The numbers shared by the core, its shaders and Python (crates/oit-core/src/consts.rs)."""

def view_direction(view_proj: npt.NDArray[np.float64]) -> tuple[float, float, float]:
    """The unit world-space direction the camera looks along at the picture's center."""

def reference(
    scene: Scene,
    view_proj: npt.NDArray[np.float64],
    width: int,
    height: int,
    background: tuple[float, float, float],
    antialias: int = 1,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_], npt.NDArray[np.uint32]]:
    """CPU float64 reference: (image (h, w, 4) float64, ambiguous (h, w) bool, depth complexity),
    the mean over the standard pattern's positions when `antialias` > 1."""
def load_file(
    path: str,
    shading: str = "smooth",
    specular: float = 0.25,
    alpha: float | None = None,
    viewing: bool = False,
    point_radius: float | None = None,
) -> tuple[Scene, list[str], list[dict[str, Any]], str | None, list[str]]:
    """Reads `path`; `shading` and `specular` style every surface (`load::Surface`). `alpha`
    makes every mesh transparent at it; `viewing` adds the command line's convenience (every
    mesh at VIEWING_ALPHA when nothing blends) and returns its note; `point_radius` sizes a point
    cloud's particles (None: 1/200 of its box's diagonal). Returns the scene, its mesh names, the
    file's cameras, the note and the loader's warnings (one sentence a feature not drawn). A
    panic while reading is a RuntimeError naming the file."""

# A scene file's records (crates/oit-py/src/scenefile.rs): a camera is (1, 16 row-major
# view-projection values) or (2, eye, target, up, fov_y, near, far); a light (direction, color,
# intensity).
_CameraRecord = tuple[int, list[float]]
_LightRecord = tuple[tuple[float, float, float], tuple[float, float, float], float]

def encode_scene(
    meshes: list[dict[str, Any]],
    camera: _CameraRecord | None,
    size: tuple[int, int] | None,
    lights: list[_LightRecord],
    ambient: tuple[float, float, float],
) -> bytes:
    """A scene file's bytes from mesh records (dicts: name, opaque, positions, colors, indices,
    primitive, surface), a camera record, the size, lights and the ambient term."""

def decode_scene(
    data: bytes,
) -> tuple[list[dict[str, Any]], _CameraRecord | None, tuple[int, int] | None, list[_LightRecord], list[float]]:
    """A scene file's records from its bytes: mesh dicts (a surface has only the arrays the file
    has), the camera record, the size, the lights and the ambient term."""

def scene_file_format() -> tuple[bytes, int]:
    """The file's magic bytes and its newest version."""

# Every entry above runs under the binding's panic guard (crates/oit-py/src/guard.rs): a panic is
# a RuntimeError that says it is a bug. `_GUARDED` names the guarded entries ("Scene.add_mesh",
# "methods", ...) and `_panic_for_test` panics on purpose (tests/test_load_entry_points.py).
_GUARDED: list[str]

def _panic_for_test() -> None: ...
