"""A PyVista plotter rendered by oit: `render(plotter)` reads its visible actors, lights, camera
and background into an `oit.Scene` and renders it with an exact (or any) method, headless, with
no OpenGL context (oit renders on its own adapter). docs/loading.md, "From PyVista and trimesh".

What is read, and how it matches VTK's own render:

- values: VTK lights, blends and stores its colors as they are (8-bit RGBA, no sRGB anywhere),
  so they pass to oit unchanged and `frame.image` holds what VTK's framebuffer would hold;
  `screenshot` writes those values as they are, as PyVista's own screenshot does.
- meshes: each visible actor's mapper input (a non-PolyData dataset is reduced to its surface)
  placed by the actor's matrix. Polygons are fanned from their first point and strips
  alternated, as VTK's mapper does; line cells become strands and vertex cells particles.
  Representation "points" draws every point as a particle and "wireframe" every polygon's edges.
- colors: scalars mapped by the actor's own mapper (`MapScalars`: its lookup table, range,
  color mode, per point or per cell; cell colors split the vertices), else the property's color;
  alpha times the property's opacity. Scalars interpolated before mapping (PyVista's default)
  are mapped at the vertices and interpolated as colors, which differs from VTK's texture
  lookup inside triangles where the table is not linear.
- lighting: the renderer's lights (headlights and camera lights follow the camera; positional
  lights are taken as directional), diffuse times the color as base, ambient over diffuse as
  the scene's ambient term (the first lit actor's), specular and its power. Lighting off draws
  (ambient + diffuse) times the color. Flat interpolation, or Gouraud and Phong without point
  normals, is oit's "flat"; Gouraud and Phong with normals is "smooth". VTK turns a normal to
  the viewer by the triangle's facing, oit by the normal itself: on a smooth opaque closed
  surface (every visible triangle faces the viewer) oit's `two_sided=False` is VTK's rule;
  elsewhere the two differ only near silhouettes. Points and lines are drawn unlit.
- camera: VTK's composite projection (position, focal point, view up, view angle, clipping
  range, parallel projection, window center) at the frame's aspect, its z taken from OpenGL's
  [-w, w] to wgpu's [0, w]. The camera is first set as PyVista sets it before its first render.
- sizes: VTK's point size and line width are pixels; oit's radii and widths are world units,
  taken at the focal point's distance.
"""

from __future__ import annotations

import functools
import os
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ._api import Camera, Frame, Renderer, Scene
from .imageio import write_png

_VTK_FLAT, _VTK_POINTS, _VTK_WIREFRAME = 0, 0, 1


def pyvista_missing() -> str | None:
    """Why PyVista cannot be used here, or None when it can."""
    try:
        import pyvista  # noqa: F401
    except ImportError as e:
        return f"pyvista is not installed ({e}); `pip install 'oit[pyvista]'` adds it"
    return None


@functools.lru_cache(maxsize=2)
def _renderer(width: int, height: int) -> Renderer:
    return Renderer(width, height)


def _size(plotter: Any, size: Sequence[int] | None) -> tuple[int, int]:
    w, h = (plotter.window_size if size is None else size)
    return int(w), int(h)


def _ensure_camera(plotter: Any) -> None:
    """What PyVista does before its first render, without rendering: a camera not yet set is
    placed at the default position and reset to the visible bounds."""
    r = plotter.renderer
    if getattr(plotter, "_first_time", False) and not r.camera.is_set:
        r.camera_position = r.get_default_cam_pos()
        r.ResetCamera()


def camera(plotter: Any, size: Sequence[int] | None = None) -> Camera:
    """The oit.Camera of the plotter's active renderer at `size` (default: the window's)."""
    _ensure_camera(plotter)
    w, h = _size(plotter, size)
    ren = plotter.renderer
    vx0, vy0, vx1, vy1 = ren.GetViewport()
    aspect = (w * (vx1 - vx0)) / (h * (vy1 - vy0))
    vtk_cam = ren.GetActiveCamera()
    m = vtk_cam.GetCompositeProjectionTransformMatrix(aspect, -1.0, 1.0)
    gl = np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)], dtype=np.float64)
    gl[2] = 0.5 * (gl[2] + gl[3])  # z in [-w, w] (OpenGL) to [0, w] (wgpu)
    return Camera(gl)


def _pixel_size(plotter: Any, size: tuple[int, int]) -> float:
    """World units a pixel spans at the focal point."""
    cam = plotter.renderer.GetActiveCamera()
    h = size[1] * (plotter.renderer.GetViewport()[3] - plotter.renderer.GetViewport()[1])
    if cam.GetParallelProjection():
        return 2.0 * cam.GetParallelScale() / h
    return 2.0 * cam.GetDistance() * np.tan(np.radians(cam.GetViewAngle()) / 2.0) / h


def _cells(cell_array: Any) -> tuple[np.ndarray, np.ndarray]:
    """(offsets, connectivity) of a vtkCellArray."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    if cell_array is None or cell_array.GetNumberOfCells() == 0:
        return np.zeros(1, np.int64), np.zeros(0, np.int64)
    return (vtk_to_numpy(cell_array.GetOffsetsArray()).astype(np.int64),
            vtk_to_numpy(cell_array.GetConnectivityArray()).astype(np.int64))


def _fan(offsets: np.ndarray, conn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of polygons fanned from their first point, and the polygon of each."""
    counts = np.diff(offsets)
    tris = np.maximum(counts - 2, 0)
    cell = np.repeat(np.arange(len(counts)), tris)
    k = np.arange(len(cell)) - np.repeat(np.cumsum(tris) - tris, tris)  # triangle number in its polygon
    start = offsets[:-1][cell]
    return np.stack([conn[start], conn[start + k + 1], conn[start + k + 2]], axis=1), cell


def _strips(offsets: np.ndarray, conn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of triangle strips (every other one reversed to keep the winding)."""
    counts = np.diff(offsets)
    tris = np.maximum(counts - 2, 0)
    cell = np.repeat(np.arange(len(counts)), tris)
    k = np.arange(len(cell)) - np.repeat(np.cumsum(tris) - tris, tris)
    start = offsets[:-1][cell] + k
    a, b, c = conn[start], conn[start + 1], conn[start + 2]
    odd = (k % 2) == 1
    return np.stack([a, np.where(odd, c, b), np.where(odd, b, c)], axis=1), cell


def _polydata(actor: Any) -> Any:
    """The actor's input as PolyData (other datasets reduced to their surface)."""
    import pyvista as pv

    data = actor.GetMapper().GetInputDataObject(0, 0)
    if data is None:
        return None
    data = pv.wrap(data)
    if isinstance(data, pv.MultiBlock):
        data = data.combine()
    if not isinstance(data, pv.PolyData):
        data = data.extract_surface()
    return data


def _mapped_colors(actor: Any, poly: Any) -> tuple[np.ndarray | None, bool]:
    """The mapper's RGBA in [0, 1] per point (False) or per cell (True), or None for the
    property's color."""
    import vtkmodules.vtkCommonCore as core
    from vtkmodules.util.numpy_support import vtk_to_numpy

    mapper = actor.GetMapper()
    if not mapper.GetScalarVisibility():
        return None, False
    before = mapper.GetInterpolateScalarsBeforeMapping()
    mapper.SetInterpolateScalarsBeforeMapping(False)
    try:
        flag = core.reference(0)
        colors = mapper.MapScalars(poly, 1.0, flag)
        if colors is None:
            return None, False
        rgba = vtk_to_numpy(colors).astype(np.float64) / 255.0
    finally:
        mapper.SetInterpolateScalarsBeforeMapping(before)
    if rgba.ndim == 1:
        rgba = rgba[:, None]
    if rgba.shape[1] < 4:  # luminance (+ alpha) or RGB
        rgba = np.concatenate([np.repeat(rgba[:, :1], 3, 1) if rgba.shape[1] < 3 else rgba[:, :3],
                               rgba[:, 1:2] if rgba.shape[1] == 2 else np.ones((len(rgba), 1))], 1)
    per_cell = int(flag) == 1
    expected = poly.n_cells if per_cell else poly.n_points
    if int(flag) not in (0, 1) or len(rgba) != expected:
        return None, False  # field data colors: the property's color instead
    return rgba, per_cell


class _Lighting:
    """The scene-wide lighting terms, set from the first lit actor."""

    def __init__(self) -> None:
        self.ambient: float | None = None
        self.mixed = False

    def base_scale(self, prop: Any) -> float:
        """The factor on an actor's color: diffuse when lit (the ambient term goes to the scene)."""
        if not prop.GetLighting():
            return prop.GetAmbient() + prop.GetDiffuse()
        diffuse = prop.GetDiffuse()
        ambient = prop.GetAmbient() / diffuse if diffuse > 0 else 0.0
        if self.ambient is None:
            self.ambient = ambient
        elif abs(self.ambient - ambient) > 1e-9:
            self.mixed = True
        return diffuse


def _lights(plotter: Any) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """(direction, color, intensity) of each light that is on, in world space."""
    ren = plotter.renderer
    cam = ren.GetActiveCamera()
    view = cam.GetViewTransformMatrix()
    rot = np.array([[view.GetElement(i, j) for j in range(3)] for i in range(3)], dtype=np.float64)
    forward = np.subtract(cam.GetFocalPoint(), cam.GetPosition())
    out = []
    lights = ren.GetLights()
    for i in range(lights.GetNumberOfItems()):
        light = lights.GetItemAsObject(i)
        if not light.GetSwitch() or light.GetIntensity() <= 0:
            continue
        d = np.subtract(light.GetFocalPoint(), light.GetPosition())
        if light.LightTypeIsHeadlight():
            d = forward
        elif light.LightTypeIsCameraLight():
            d = rot.T @ d  # the light's coordinates are the camera's
        if np.linalg.norm(d) == 0:
            continue
        out.append((d / np.linalg.norm(d), np.asarray(light.GetDiffuseColor(), dtype=np.float64), float(light.GetIntensity())))
    return out


def _add_actor(scene: Scene, actor: Any, lighting: _Lighting, pixel: float) -> None:
    poly = _polydata(actor)
    if poly is None or poly.n_points == 0:
        return
    prop = actor.GetProperty()
    matrix = np.array([[actor.GetMatrix().GetElement(i, j) for j in range(4)] for i in range(4)], dtype=np.float64)
    points = np.asarray(poly.points, dtype=np.float64) @ matrix[:3, :3].T + matrix[:3, 3]
    rgba, per_cell = _mapped_colors(actor, poly)
    if rgba is None:
        rgba, per_cell = np.tile(np.append(prop.GetDiffuseColor(), 1.0), (poly.n_points, 1)), False
    rgba = rgba.copy()
    scale = lighting.base_scale(prop) if prop.GetLighting() else prop.GetAmbient() + prop.GetDiffuse()
    rgba[:, 3] *= prop.GetOpacity()
    lit_rgba = rgba.copy()
    lit_rgba[:, :3] = np.clip(lit_rgba[:, :3] * scale, 0.0, 1.0)
    unlit_rgba = rgba.copy()
    unlit_rgba[:, :3] = np.clip(unlit_rgba[:, :3] * (prop.GetAmbient() + prop.GetDiffuse()), 0.0, 1.0)
    if actor.GetForceOpaque():
        opaque = True
    elif actor.GetForceTranslucent():
        opaque = False
    else:
        opaque = bool((rgba[:, 3] >= 1.0).all())
    # Cell offsets into one running numbering (VTK numbers verts, lines, polys, strips in turn).
    verts, lines, polys, strips = (_cells(c) for c in (poly.GetVerts(), poly.GetLines(), poly.GetPolys(), poly.GetStrips()))
    first = np.cumsum([0] + [len(c[0]) - 1 for c in (verts, lines, polys, strips)])
    representation = prop.GetRepresentation()

    def cell_rows(local: np.ndarray, kind: int) -> np.ndarray:
        return local + first[kind]

    def point_colors(colors: np.ndarray, point_ids: np.ndarray, cell_ids: np.ndarray) -> np.ndarray:
        return colors[cell_ids] if per_cell else colors[point_ids]

    radius = 0.5 * prop.GetPointSize() * pixel
    width = prop.GetLineWidth() * pixel
    if representation == _VTK_POINTS:
        ids = np.arange(poly.n_points)
        if per_cell:  # a point takes the color of the last cell that holds it, as VTK draws it
            cols = np.tile(unlit_rgba[:1], (poly.n_points, 1))
            for kind, (off, conn) in enumerate((verts, lines, polys, strips)):
                cell = np.repeat(np.arange(len(off) - 1), np.diff(off))
                cols[conn] = unlit_rgba[cell_rows(cell, kind)]
        else:
            cols = unlit_rgba
        scene.add_particles(points[ids], radius, cols, opaque=opaque)
        return
    # Vertex cells: particles.
    off, conn = verts
    if len(conn):
        cell = np.repeat(np.arange(len(off) - 1), np.diff(off))
        scene.add_particles(points[conn], radius, point_colors(unlit_rgba, conn, cell_rows(cell, 0)), opaque=opaque)
    # Line cells, and polygon edges in wireframe: strands.
    strand_sets = [(lines, 1, False)]
    if representation == _VTK_WIREFRAME:
        strand_sets += [(polys, 2, True)]
    for (off, conn), kind, closed in strand_sets:
        counts = np.diff(off)
        keep = counts >= 2
        if not keep.any():
            continue
        ids, cells, lengths = [], [], []
        for c in np.nonzero(keep)[0]:
            p = conn[off[c]:off[c + 1]]
            if closed:
                p = np.append(p, p[0])
            ids.append(p)
            cells.append(np.full(len(p), c))
            lengths.append(len(p))
        pid, cid = np.concatenate(ids), np.concatenate(cells)
        scene.add_strands(points[pid], np.asarray(lengths, np.int64), width,
                          point_colors(unlit_rgba, pid, cell_rows(cid, kind)), opaque=opaque)
    if representation == _VTK_WIREFRAME:
        return
    # Polygons and strips: triangles.
    tri_p, cell_p = _fan(*polys)
    tri_s, cell_s = _strips(*strips)
    tris = np.concatenate([tri_p, tri_s]).astype(np.int64)
    if not len(tris):
        return
    cells = np.concatenate([cell_rows(cell_p, 2), cell_rows(cell_s, 3)])
    lit = bool(prop.GetLighting())
    colors = lit_rgba if lit else unlit_rgba
    normals = poly.point_data.active_normals if lit else None
    smooth = lit and prop.GetInterpolation() != _VTK_FLAT and normals is not None
    if smooth:
        normals = np.asarray(normals, dtype=np.float64) @ np.linalg.inv(matrix[:3, :3])  # inverse transpose, row vectors
    if per_cell:  # one color a cell: a vertex per corner
        corner = tris.reshape(-1)
        positions, colors = points[corner], np.repeat(colors[cells], 3, axis=0)
        normals = normals[corner] if smooth else None
        tris = np.arange(len(corner)).reshape(-1, 3)
    else:
        positions = points
    shading = ("smooth" if smooth else "flat") if lit else "unlit"
    scene.add_mesh(positions, tris, colors, opaque=opaque, normals=normals if smooth else None, shading=shading,
                   specular=float(prop.GetSpecular()) if lit else 0.0,
                   shininess=max(float(prop.GetSpecularPower()), 1e-3),
                   two_sided=not (smooth and opaque and poly.n_open_edges == 0))


def scene(plotter: Any, size: Sequence[int] | None = None) -> tuple[Scene, Camera, tuple[float, float, float]]:
    """The plotter's active renderer as (oit.Scene, oit.Camera, background): its visible actors
    in the order they were added, its lights, its camera at `size` (default: the window's) and
    its background (see the module's docstring for what is read and how)."""
    from vtkmodules.vtkRenderingCore import vtkActor

    cam = camera(plotter, size)
    pixel = _pixel_size(plotter, _size(plotter, size))
    oit_scene = Scene()
    lighting = _Lighting()
    actors = plotter.renderer.GetActors()
    for i in range(actors.GetNumberOfItems()):
        actor = actors.GetItemAsObject(i)
        if not isinstance(actor, vtkActor) or not actor.GetVisibility() or actor.GetMapper() is None:
            continue
        _add_actor(oit_scene, actor, lighting, pixel)
    if lighting.mixed:
        warnings.warn("oit.pyvista: lit actors with different ambient/diffuse ratios; oit's ambient term is one "
                      "for the scene, the first actor's is used", stacklevel=3)
    for direction, color, intensity in _lights(plotter)[:8]:
        oit_scene.add_light(direction, color, intensity)
    if lighting.ambient:
        oit_scene.ambient = (lighting.ambient,) * 3
    bg = tuple(float(c) for c in plotter.renderer.GetBackground())
    return oit_scene, cam, (bg[0], bg[1], bg[2])


def render(plotter: Any, method: str = "abuffer", size: Sequence[int] | None = None,
           background: Sequence[float] | None = None, **params: Any) -> Frame:
    """Renders a PyVista plotter's active renderer with oit's `method` (parameters as keywords,
    as `oit.Renderer.render` takes them) at `size` (width, height; default: the window's) on
    `background` (default: the renderer's). The frame holds VTK's color values as VTK's
    framebuffer would (no sRGB conversion: VTK has none), composited exactly by the exact methods."""
    w, h = _size(plotter, size)
    oit_scene, cam, bg = scene(plotter, (w, h))
    return _renderer(w, h).render(oit_scene, cam, method, background=bg if background is None else background, **params)


def to_uint8(frame: Frame) -> np.ndarray:
    """(h, w, 3) uint8 of a frame from `render`, as PyVista's `screenshot()` returns it."""
    return np.rint(np.clip(frame.image[..., :3], 0.0, 1.0) * 255.0).astype(np.uint8)


def screenshot(plotter: Any, path: str | os.PathLike | None = None, method: str = "abuffer",
               size: Sequence[int] | None = None, background: Sequence[float] | None = None, **params: Any) -> np.ndarray:
    """`render`, then the image as PyVista's `screenshot()` gives it ((h, w, 3) uint8, VTK's
    values unencoded), written as PNG to `path` when one is given."""
    image = to_uint8(render(plotter, method, size, background, **params))
    if path is not None:
        write_png(Path(path), image)
    return image
