"""Peers for the benchmark: the same scene and camera rendered by another library.

pygfx (optional, `pip install pygfx`) is what a Python user would pick instead of oit; its
`blend`, `weighted_blend` and `dither` alpha modes are measured beside our methods. The
inputs are matched as follows (docs/results.md says how the match was checked):

- colors: pygfx takes vertex colors as linear ("physical") RGBA, as oit does, so they pass
  unchanged; its background material takes sRGB, so our linear background is encoded.
- camera: pygfx draws with projection @ inverse(camera world matrix). We give it our
  view-projection matrix as the view (with z negated) and the z negation as the projection,
  so the product is exactly ours; both use wgpu's clip space (z in [0, 1], y up). The
  negation makes pygfx's view-space z (which it sorts objects by, looking down -z) increase
  toward the camera, as it expects.
- objects: one gfx.Mesh per mesh, placed at its vertex centroid, since pygfx sorts
  transparent objects by their position; opaque meshes use alpha mode `solid`.
- lit meshes (those with normals in their surface, `oit.bench.floor`'s lit rows): a
  MeshPhongMaterial with the same normals, specular and shininess, the scene's directional
  lights and its ambient term. pygfx's Phong is not our shading model, so only the times of
  these rows compare, not the images.
- output: pygfx blends into an rgba8unorm-srgb target; `snapshot()` reads that target before
  the output pass (with `ppaa="none"` and `pixel_scale=1` nothing filters it) and we decode it
  to linear. Its 8-bit sRGB storage is part of what pygfx computes, so it stays in the error.

VTK (optional, `pip install vtk`, 9.5 or later: 9.3's wheels ignore the window variable below
and 9.4 has no `SetUseOIT`) is what PyVista and ParaView draw with; its dual depth peeling
(exact up to its peel limit) and its plain alpha blending are measured. VTK needs an
OpenGL context: offscreen without a display it gets one from EGL, so `VtkRenderer` sets
`VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow` before importing vtk when the variable is unset
(with Mesa that is llvmpipe; without EGL VTK falls back to OSMesa or X, and crashes where
neither exists, which is why `vtk_missing` probes in a child process). The match:

- camera: VTK draws with projection @ view @ model. The view is the identity (eye at the
  origin looking down -z, y up) and the projection is explicit: our view-projection with
  its z row remapped from our clip range [0, w] to OpenGL's [-w, w] (z' = 2z - w), so x, y,
  w, the clipping and the depth order are ours. vtkMatrix4x4 is row-major with column
  vectors, as numpy's `view_proj @ p` is.
- colors: per-vertex RGBA as direct scalars, lighting off (ambient 1, diffuse 0), Gouraud
  interpolation (flat would take one vertex's color per triangle). VTK's mappers hand the GPU
  8-bit colors, so we round them to 8 bits ourselves (up to 1/510 a channel). Opaque meshes
  get alpha 1 and `ForceOpaque`. No multisampling, no FXAA; the framebuffer is linear RGBA8,
  so the background passes unchanged and no sRGB conversion happens anywhere.
- modes: `depth_peeling` is VTK's depth peeling (dual depth peeling on this OpenGL) with the
  occlusion ratio 0 (peel until no pixel changes) and VTK_MAX_PEELS passes at most; a render
  on which VTK reports it did not peel raises instead of returning another mode's image.
  `blend` is plain alpha blending in actor order (`SetUseOIT(0)`: without peeling VTK would
  otherwise use its weighted-average OIT pass).
- output: read back with vtkWindowToImageFilter as 8-bit RGB (what VTK gives), flipped to
  rows from the top. VTK's peels accumulate in RGBA8 textures, so its rounding grows with
  the peels; that stays in the error.
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from .imageio import linear_to_srgb, srgb_to_linear
from .scenes import BuiltScene

PYGFX_MODES = ("blend", "weighted_blend", "dither")


def pygfx_missing() -> str | None:
    """Why pygfx cannot be used here, or None when it can."""
    try:
        import pygfx  # noqa: F401
    except ImportError as e:
        return f"pygfx is not installed ({e}); `pip install pygfx` adds it"
    return None


def _matrix_camera(view_proj: np.ndarray) -> Any:
    import pygfx as gfx

    flip_z = np.diag([1.0, 1.0, -1.0, 1.0])
    flip_z.flags.writeable = False

    class MatrixCamera(gfx.Camera):
        """A camera whose projection @ view is a given view-projection matrix."""

        def _update_projection_matrix(self) -> np.ndarray:
            return flip_z

    camera = MatrixCamera()
    camera.local.state_basis = "matrix"  # keep the (projective) matrix as given, undecomposed
    camera.local.matrix = np.linalg.inv(flip_z @ np.asarray(view_proj, dtype=np.float64))
    return camera


class PygfxRenderer:
    """Renders BuiltScenes with pygfx at one size, offscreen, into linear RGBA like oit."""

    def __init__(self, width: int, height: int) -> None:
        import pygfx as gfx

        self.width, self.height = width, height
        # The target only receives pygfx's output pass; we read its internal color buffer.
        target = gfx.Texture(dim=2, size=(width, height, 1), format="rgba8unorm")
        self._renderer = gfx.WgpuRenderer(target, pixel_scale=1, ppaa="none")
        # pygfx scenes of the BuiltScene last rendered, by (mode, background); the reference to
        # it keeps its id from being reused by another scene while cached.
        self._built: BuiltScene | None = None
        self._scenes: dict[tuple[str, tuple[float, ...]], Any] = {}

    @property
    def adapter(self) -> str:
        from pygfx.renderers.wgpu import get_shared

        return f"pygfx on {get_shared().adapter.info['device']}"

    def _scene(self, built: BuiltScene, mode: str, background: Sequence[float]) -> Any:
        import pygfx as gfx

        if built is not self._built:
            self._built, self._scenes = built, {}  # drop the old scenes' GPU buffers
        key = (mode, tuple(background))
        if key not in self._scenes:
            scene = gfx.Scene()
            srgb = linear_to_srgb(np.asarray(background, dtype=np.float64))
            scene.add(gfx.Background.from_color(gfx.Color(*srgb)))
            for m in built.drawn_meshes():
                center = m.positions.astype(np.float64).mean(0)
                alpha_mode = "solid" if m.opaque else mode
                normals = m.surface.get("normals")
                if normals is None:
                    geometry = gfx.Geometry(positions=(m.positions - center).astype(np.float32),
                                            indices=m.indices, colors=m.colors)
                    material = gfx.MeshBasicMaterial(color_mode="vertex", alpha_mode=alpha_mode)
                else:
                    # A lit mesh: Phong with the same normals, specular and shininess.
                    geometry = gfx.Geometry(positions=(m.positions - center).astype(np.float32), indices=m.indices,
                                            colors=m.colors, normals=np.asarray(normals, dtype=np.float32))
                    spec = float(m.surface.get("specular", 0.0))
                    material = gfx.MeshPhongMaterial(color_mode="vertex", alpha_mode=alpha_mode, specular=(spec, spec, spec),
                                                     shininess=float(m.surface.get("shininess", 32.0)))
                mesh = gfx.Mesh(geometry, material)
                mesh.local.position = center
                scene.add(mesh)
            if any(m.surface.get("normals") is not None for m in built.drawn_meshes()):
                for direction, color, intensity in built.lights:
                    light = gfx.DirectionalLight(color=gfx.Color(*color), intensity=intensity)
                    light.local.position = -np.asarray(direction, dtype=np.float64)  # shines towards the origin
                    scene.add(light)
                scene.add(gfx.AmbientLight(color=gfx.Color(*built.ambient), intensity=1.0))
            self._scenes[key] = scene
        return self._scenes[key]

    def render(self, built: BuiltScene, mode: str, background: Sequence[float] = (1.0, 1.0, 1.0)) -> tuple[np.ndarray, float]:
        """(h, w, 4) float32 linear RGBA (A = 1: the background is opaque) and the wall time in
        milliseconds of the render and the readback."""
        if mode not in (*PYGFX_MODES, "solid"):
            raise ValueError(f"unknown pygfx alpha mode '{mode}'; choose one of {', '.join(PYGFX_MODES)}")
        scene = self._scene(built, mode, background)
        camera = _matrix_camera(built.camera.view_proj)
        t0 = time.perf_counter()
        self._renderer.render(scene, camera)
        snap = self._renderer.snapshot()
        wall = (time.perf_counter() - t0) * 1e3
        image = np.empty(snap.shape, dtype=np.float32)
        image[..., :3] = srgb_to_linear(snap[..., :3] / 255.0)
        image[..., 3] = snap[..., 3] / 255.0
        return image, wall


@functools.lru_cache(maxsize=2)
def pygfx_renderer(width: int, height: int) -> PygfxRenderer:
    """A PygfxRenderer per size, kept: pygfx compiles its shaders once per renderer."""
    return PygfxRenderer(width, height)


# ---- VTK

VTK_MODES = ("depth_peeling", "blend")
# Dual depth peeling takes two layers a pass; 4096 passes cover 8192 layers, past any scene
# here (hair's worst pixel has 388). VTK documents 0 as "no limit", but its dual depth peeling
# then stops before the first peel and blends every layer unsorted.
VTK_MAX_PEELS = 4096
_EGL_WINDOW = "vtkEGLRenderWindow"
_VTK_PROBE = """
import os
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
from vtkmodules.vtkRenderingCore import vtkRenderWindow, vtkRenderer
import vtkmodules.vtkRenderingOpenGL2
w = vtkRenderWindow()
w.SetOffScreenRendering(1)
w.SetSize(1, 1)
w.AddRenderer(vtkRenderer())
w.Render()
print(w.GetClassName(), w.ReportCapabilities().count("OpenGL renderer string"))
"""


@functools.lru_cache(maxsize=1)
def vtk_missing() -> str | None:
    """Why VTK cannot render here, or None when it can. Opening the context is tried in a child
    process: where neither EGL, OSMesa nor X works, VTK crashes rather than raising."""
    try:
        import vtkmodules  # noqa: F401
    except ImportError as e:
        return f"vtk is not installed ({e}); `pip install vtk` adds it"
    env = {**os.environ, "VTK_DEFAULT_OPENGL_WINDOW": os.environ.get("VTK_DEFAULT_OPENGL_WINDOW", _EGL_WINDOW)}
    try:
        p = subprocess.run([sys.executable, "-c", _VTK_PROBE], env=env, capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        return "vtk could not open an OpenGL context (the probe timed out)"
    words = p.stdout.split()
    if p.returncode != 0 or len(words) != 2 or words[1] == "0":
        why = f"exit status {p.returncode}" + (f", window {words[0]}" if words else "")
        return (f"vtk could not open an OpenGL context ({why}); offscreen it needs EGL (Mesa's libEGL_mesa gives "
                f"llvmpipe) with VTK_DEFAULT_OPENGL_WINDOW={_EGL_WINDOW}, or OSMesa, or a display")
    return None


def _vtk_polydata(mesh: Any, rgba8: np.ndarray) -> Any:
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import VTK_ID_TYPE, vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData

    poly = vtkPolyData()
    points = vtkPoints()
    points.SetData(numpy_to_vtk(np.ascontiguousarray(mesh.positions, dtype=np.float32), deep=True))
    poly.SetPoints(points)
    connectivity = np.ascontiguousarray(mesh.indices, dtype=np.int64).reshape(-1)
    offsets = np.arange(0, len(connectivity) + 1, 3, dtype=np.int64)
    cells = vtkCellArray()
    cells.SetData(numpy_to_vtk(offsets, deep=True, array_type=VTK_ID_TYPE),
                  numpy_to_vtk(connectivity, deep=True, array_type=VTK_ID_TYPE))
    poly.SetPolys(cells)
    colors = numpy_to_vtk(rgba8, deep=True)
    colors.SetName("rgba")
    poly.GetPointData().SetScalars(colors)
    return poly


def vtk_colors(mesh: Any) -> np.ndarray:
    """A mesh's vertex colors as VTK receives them: straight linear RGBA rounded to 8 bits,
    alpha 255 on opaque meshes."""
    rgba8 = np.rint(np.clip(np.asarray(mesh.colors, dtype=np.float64), 0.0, 1.0) * 255.0).astype(np.uint8)
    if mesh.opaque:
        rgba8[:, 3] = 255
    return np.ascontiguousarray(rgba8)


class VtkRenderer:
    """Renders BuiltScenes with VTK at one size, offscreen, into linear RGBA like oit (see the
    module docstring for how the inputs are matched)."""

    def __init__(self, width: int, height: int) -> None:
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", _EGL_WINDOW)
        import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 - registers the OpenGL classes
        from vtkmodules.vtkRenderingCore import vtkCamera, vtkRenderWindow, vtkWindowToImageFilter

        self.width, self.height = width, height
        self._window = vtkRenderWindow()
        self._window.SetOffScreenRendering(1)
        self._window.SetSize(width, height)
        self._window.SetMultiSamples(0)
        self._window.SetAlphaBitPlanes(1)
        self._camera = vtkCamera()
        self._camera.SetPosition(0.0, 0.0, 0.0)  # the view transform is the identity
        self._camera.SetFocalPoint(0.0, 0.0, -1.0)
        self._camera.SetViewUp(0.0, 1.0, 0.0)
        self._camera.SetUseExplicitProjectionTransformMatrix(True)
        # One vtkRenderer per mode, new for each scene: VTK sets its "used depth peeling" flag only
        # on renders that draw translucent geometry and leaves it as it was on the plain blending
        # path, so a renderer that only ever drew this scene in this mode is what makes it true.
        self._renderers: dict[str, Any] = {}
        self._mode: str | None = None
        self._grab = vtkWindowToImageFilter()
        self._grab.SetInput(self._window)
        self._grab.SetInputBufferTypeToRGB()
        self._grab.ReadFrontBufferOff()
        self._grab.ShouldRerenderOff()  # we render (and time) it ourselves
        self._built: BuiltScene | None = None
        self._translucent = False

    @property
    def adapter(self) -> str:
        from vtkmodules.vtkCommonCore import vtkVersion

        caps = self._window.ReportCapabilities() if self._built is not None else ""
        gl = next((line.split(":", 1)[1].strip() for line in caps.splitlines() if line.startswith("OpenGL renderer string")),
                  "an OpenGL context not yet opened")
        return f"VTK {vtkVersion.GetVTKVersion()} on {gl}"

    def _load(self, built: BuiltScene) -> None:
        from vtkmodules.vtkCommonMath import vtkMatrix4x4
        from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper, vtkRenderer

        if built is self._built:
            return
        if self._mode is not None:
            self._window.RemoveRenderer(self._renderers[self._mode])
        self._renderers, self._mode, self._translucent = {}, None, False
        for mode in VTK_MODES:
            renderer = vtkRenderer()
            renderer.SetActiveCamera(self._camera)
            renderer.SetUseFXAA(False)
            renderer.SetUseOIT(False)
            renderer.SetUseDepthPeeling(mode == "depth_peeling")
            renderer.SetMaximumNumberOfPeels(VTK_MAX_PEELS)
            renderer.SetOcclusionRatio(0.0)
            self._renderers[mode] = renderer
        for mesh in built.drawn_meshes():
            rgba8 = vtk_colors(mesh)
            self._translucent |= bool((rgba8[:, 3] < 255).any())
            mapper = vtkPolyDataMapper()
            mapper.SetInputData(_vtk_polydata(mesh, rgba8))
            mapper.SetScalarModeToUsePointData()
            mapper.SetColorModeToDirectScalars()
            mapper.ScalarVisibilityOn()
            actor = vtkActor()
            actor.SetMapper(mapper)
            prop = actor.GetProperty()
            prop.LightingOff()
            prop.SetAmbient(1.0)
            prop.SetDiffuse(0.0)
            prop.SetSpecular(0.0)
            prop.SetInterpolationToGouraud()
            actor.SetForceOpaque(mesh.opaque)
            for renderer in self._renderers.values():
                renderer.AddActor(actor)
        to_gl = np.eye(4)
        to_gl[2] = (0.0, 0.0, 2.0, -1.0)  # z' = 2z - w: our clip z in [0, w] to OpenGL's [-w, w]
        matrix = vtkMatrix4x4()
        matrix.DeepCopy((to_gl @ np.asarray(built.camera.view_proj, dtype=np.float64)).reshape(-1).tolist())
        self._camera.SetExplicitProjectionTransformMatrix(matrix)
        self._built = built

    def peeled(self) -> bool:
        """Whether VTK says it peeled the scene last rendered with `depth_peeling`."""
        renderer = self._renderers.get("depth_peeling")
        return bool(renderer is not None and renderer.GetLastRenderingUsedDepthPeeling())

    def render(self, built: BuiltScene, mode: str, background: Sequence[float] = (1.0, 1.0, 1.0)) -> tuple[np.ndarray, float]:
        """(h, w, 4) float32 linear RGBA (A = 1: the background is opaque) and the wall time in
        milliseconds of the render and the readback. Raises RuntimeError when `depth_peeling`
        was asked for, the scene has translucent geometry and VTK reports it did not peel."""
        from vtkmodules.util.numpy_support import vtk_to_numpy

        if mode not in VTK_MODES:
            raise ValueError(f"unknown VTK mode '{mode}'; choose one of {', '.join(VTK_MODES)}")
        self._load(built)
        if mode != self._mode:
            if self._mode is not None:
                self._window.RemoveRenderer(self._renderers[self._mode])
            self._window.AddRenderer(self._renderers[mode])
            self._mode = mode
        self._renderers[mode].SetBackground(*(float(c) for c in background[:3]))
        t0 = time.perf_counter()
        self._window.Render()
        self._grab.Modified()
        self._grab.Update()
        rgb = vtk_to_numpy(self._grab.GetOutput().GetPointData().GetScalars()).copy()
        wall = (time.perf_counter() - t0) * 1e3
        if mode == "depth_peeling" and self._translucent and not self.peeled():
            raise RuntimeError("VTK did not use depth peeling (GetLastRenderingUsedDepthPeeling() is 0 on a scene "
                               "with translucent geometry); no other mode is put in its place")
        image = np.ones((self.height, self.width, 4), dtype=np.float32)
        image[..., :3] = rgb.reshape(self.height, self.width, 3)[::-1] / 255.0  # VTK's rows run bottom to top
        return image, wall


@functools.lru_cache(maxsize=2)
def vtk_renderer(width: int, height: int) -> VtkRenderer:
    """A VtkRenderer per size, kept: its window, context and shaders are made once."""
    return VtkRenderer(width, height)


# ---- the peers as the bench sees them: library -> (modes, why it is missing, renderer per size)

PEERS = {
    "pygfx": (PYGFX_MODES, pygfx_missing, pygfx_renderer),
    "vtk": (VTK_MODES, vtk_missing, vtk_renderer),
}
