"""`oit.pygfx.render(scene, camera)`: a pygfx scene graph rendered by oit, exactly where pygfx
has to pick an alpha mode by hand (`pip install 'oit[pygfx]'`, pygfx 0.17).

What is read, and how it maps (docs/loading.md has oit's side):

- meshes (gfx.Mesh): positions, indices, normals, texcoords and colors (1 to 4 channels, per
  vertex, or per face with color_mode "face"), under the object's world matrix. The color
  follows pygfx's mesh shader: material.color is sRGB (linearized), vertex colors are linear,
  the map is sRGB unless its texture's colorspace is "physical"; "auto" multiplies what is
  there, "uniform", "vertex"/"face" and "vertex_map"/"face_map" take one. `opacity` multiplies
  alpha. MeshBasicMaterial is drawn unlit; MeshPhongMaterial is lit ("smooth", or "flat" with
  flat_shading) with its specular color's mean as the weight and its shininess; other lit
  materials are lit without a highlight. side "front" culls back faces.
- alpha_mode: "solid" and "solid_premul" are opaque; every other blending or dithering mode
  ("auto", "blend", "dither", "bayer", "weighted_blend", ...) is what oit composites exactly;
  "add", "subtract" and "multiply" are not compositing and raise ValueError.
- points (gfx.Points) are particles, lines (gfx.Line; NaN breaks a line, LineSegmentMaterial
  pairs points) strands; sizes and thicknesses in screen pixels become world sizes at each
  point's depth, so they look as wide as pygfx draws them.
- lights: DirectionalLight (towards its target) and AmbientLight; a scene with lit meshes and
  no directional light gets none (pygfx has no headlight).
- camera: oit.Camera(camera.camera_matrix) after `set_view_size(size)`: pygfx's clip space is
  wgpu's (z in [0, 1], near at 0) as oit's is. The background is the scene's gfx.Background
  (its bottom-left color, sRGB) unless `background` (linear RGB) is given.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ._api import Camera, Frame, Renderer, Scene
from .imageio import linear_to_srgb, srgb_to_linear

NOT_COMPOSITING = ("add", "subtract", "multiply")
_renderers: dict[tuple[int, int], Renderer] = {}


def _data(buffer: Any) -> np.ndarray | None:
    return None if buffer is None else np.asarray(buffer.data)


def _srgb(color: Any) -> np.ndarray:
    """A gfx.Color (sRGB, straight alpha) as linear RGBA."""
    rgba = np.asarray(color.rgba, dtype=np.float64)
    return np.append(srgb_to_linear(rgba[:3]), rgba[3])


def _rgba(colors: np.ndarray) -> np.ndarray:
    """Geometry colors of 1 to 4 channels (linear) as (n, 4)."""
    c = np.asarray(colors, dtype=np.float64).reshape(len(colors), -1)
    if c.shape[1] == 1:
        return np.hstack([np.repeat(c, 3, 1), np.ones((len(c), 1))])
    if c.shape[1] == 2:
        return np.hstack([np.repeat(c[:, :1], 3, 1), c[:, 1:]])
    if c.shape[1] == 3:
        return np.hstack([c, np.ones((len(c), 1))])
    return c[:, :4]


def _texture(material: Any) -> np.ndarray | None:
    """The material's map as oit takes a texture: uint8 sRGB or float linear (h, w, 4)."""
    m = getattr(material, "map", None)
    if m is None:
        return None
    tex = getattr(m, "texture", m)
    data = np.asarray(tex.data)
    if data.ndim == 2:
        data = data[..., None]
    if data.ndim == 4:  # (1, h, w, c): a 2D texture stored with a depth of one
        data = data[0]
    c = data.shape[2]
    opaque = np.full((*data.shape[:2], 1), 255 if data.dtype == np.uint8 else 1.0, data.dtype)
    rgba = np.concatenate([np.repeat(data[..., :1], 3, 2) if c < 3 else data[..., :3],
                           data[..., -1:] if c in (2, 4) else opaque], axis=2)
    if data.dtype == np.uint8 and tex.colorspace == "srgb":
        return np.ascontiguousarray(rgba)
    f = rgba.astype(np.float64) / (255.0 if data.dtype == np.uint8 else 1.0)
    if tex.colorspace == "srgb":
        f[..., :3] = srgb_to_linear(f[..., :3])
    return np.ascontiguousarray(f, dtype=np.float32)


def _opaque(material: Any) -> bool:
    mode = str(material.alpha_mode)
    if mode in NOT_COMPOSITING:
        raise ValueError(f"alpha_mode '{mode}' is not compositing; oit draws 'solid' (opaque) or composites every "
                         "other mode exactly: set material.alpha_mode to 'solid' or 'blend'")
    return mode in ("solid", "solid_premul")


def _pixel_size(camera: Camera, projection: np.ndarray, points: np.ndarray, pixels: np.ndarray, height: int) -> np.ndarray:
    """World sizes of `pixels` screen pixels (logical = physical here) at each point's depth."""
    w = (camera.view_proj @ np.hstack([points, np.ones((len(points), 1))]).T)[3]
    return pixels * 2.0 / height * np.abs(w) / abs(projection[1, 1])


def _add_mesh(out: Scene, ob: Any) -> bool:
    import pygfx as gfx

    g, mat = ob.geometry, ob.material
    pos = _data(g.positions).astype(np.float64).reshape(-1, 3)
    idx = _data(getattr(g, "indices", None))
    idx = np.arange(len(pos)).reshape(-1, 3) if idx is None else np.asarray(idx).reshape(-1, 3).astype(np.int64)
    normals, uvs = _data(getattr(g, "normals", None)), _data(getattr(g, "texcoords", None))
    colors = _data(getattr(g, "colors", None))
    mode = str(mat.color_mode)
    if mode in ("face", "face_map"):  # one color a triangle: unshared vertices
        flat = idx.reshape(-1)
        pos, normals, uvs = pos[flat], None if normals is None else normals[flat], None if uvs is None else uvs[flat]
        colors = None if colors is None else np.repeat(_rgba(colors), 3, axis=0)
        idx = np.arange(len(flat)).reshape(-1, 3)
    elif colors is not None:
        colors = _rgba(colors)
    texture = _texture(mat) if mode in ("auto", "vertex_map", "face_map") and uvs is not None else None
    color = _srgb(mat.color)
    if mode == "uniform" or (mode == "auto" and colors is None):
        rgba = np.tile(color, (len(pos), 1))
    elif mode in ("vertex", "face"):
        rgba = colors if colors is not None else np.ones((len(pos), 4))
    elif mode in ("vertex_map", "face_map"):
        rgba = np.ones((len(pos), 4))
    else:  # auto with vertex colors
        rgba = colors * color
    if mode == "auto" and texture is not None and colors is None:
        rgba = np.tile(color, (len(pos), 1))
    lit = not isinstance(mat, gfx.MeshBasicMaterial)
    surface: dict[str, Any] = {"shading": "unlit"}
    if lit:
        flat_shading = bool(getattr(mat, "flat_shading", False))
        surface = {"shading": "flat" if flat_shading else "smooth",
                   "normals": None if flat_shading or normals is None else np.asarray(normals, np.float64).reshape(-1, 3)}
        if isinstance(mat, gfx.MeshPhongMaterial):
            surface["specular"] = float(srgb_to_linear(np.asarray(mat.specular.rgb, np.float64)).mean())
            surface["shininess"] = float(mat.shininess)
    side = str(getattr(mat, "side", "both"))
    if side == "back":
        idx = idx[:, ::-1]
    if uvs is not None and texture is not None:
        surface.update(uvs=np.asarray(uvs, np.float64).reshape(len(pos), -1)[:, :2], texture=texture)
    out.add_mesh(pos, idx, np.clip(rgba, 0.0, 1.0), opaque=_opaque(mat), opacity=float(mat.opacity),
                 cull_back_faces=side in ("front", "back"), transform=np.asarray(ob.world.matrix, np.float64), **surface)
    return lit


def _world(ob: Any, points: np.ndarray) -> np.ndarray:
    m = np.asarray(ob.world.matrix, np.float64)
    return points @ m[:3, :3].T + m[:3, 3]


def _point_colors(ob: Any, n: int) -> np.ndarray:
    mat, colors = ob.material, _data(getattr(ob.geometry, "colors", None))
    mode = str(mat.color_mode)
    if colors is not None and mode in ("auto", "vertex"):
        return np.clip(_rgba(colors) * (_srgb(mat.color) if mode == "auto" else 1.0), 0, 1)
    return np.tile(np.clip(_srgb(mat.color), 0, 1), (n, 1))


def _sizes(ob: Any, name: str, camera: Camera, projection: np.ndarray, points: np.ndarray, height: int) -> np.ndarray:
    """The material's size (points) or thickness (lines), per point from the geometry where the
    material says so, as world sizes."""
    mat = ob.material
    base = float(getattr(mat, name))
    per = _data(getattr(ob.geometry, "sizes", None)) if name == "size" and str(getattr(mat, "size_mode", "")) == "vertex" else None
    px = np.full(len(points), base) if per is None else np.asarray(per, np.float64).reshape(-1)
    space = str(getattr(mat, "size_space" if name == "size" else "thickness_space", "screen"))
    if space == "screen":
        return _pixel_size(camera, projection, points, px, height)
    if space == "model":  # scaled as the object is
        return px * float(np.cbrt(abs(np.linalg.det(np.asarray(ob.world.matrix, np.float64)[:3, :3]))))
    return px


def _add_points(out: Scene, ob: Any, camera: Camera, projection: np.ndarray, height: int) -> None:
    centers = _world(ob, _data(ob.geometry.positions).astype(np.float64).reshape(-1, 3))
    keep = np.isfinite(centers).all(1)
    diameter = _sizes(ob, "size", camera, projection, centers, height)
    out.add_particles(centers[keep], diameter[keep] / 2.0, _point_colors(ob, len(centers))[keep],
                      opaque=_opaque(ob.material), opacity=float(ob.material.opacity))


def _add_line(out: Scene, ob: Any, camera: Camera, projection: np.ndarray, height: int) -> None:
    import pygfx as gfx

    pts = _world(ob, _data(ob.geometry.positions).astype(np.float64).reshape(-1, 3))
    colors, width = _point_colors(ob, len(pts)), _sizes(ob, "thickness", camera, projection, pts, height)
    if isinstance(ob.material, gfx.LineSegmentMaterial):
        runs = [(i, i + 2) for i in range(0, len(pts) - 1, 2)]
    else:  # NaN points break a line into runs
        ok = np.isfinite(pts).all(1)
        edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(np.int8), [0]])))
        runs = list(zip(edges[::2], edges[1::2]))
    runs = [(a, b) for a, b in runs if b - a >= 2 and np.isfinite(pts[a:b]).all()]
    if not runs:
        return
    take = np.concatenate([np.arange(a, b) for a, b in runs])
    out.add_strands(pts[take], [b - a for a, b in runs], width[take], colors[take], opaque=_opaque(ob.material),
                    opacity=float(ob.material.opacity))


def to_oit(scene: Any, camera: Any, size: tuple[int, int] = (640, 480)) -> tuple[Scene, Camera, tuple[float, float, float] | None]:
    """The oit.Scene and oit.Camera of a pygfx scene and camera at `size` (w, h), and the
    scene's background (linear RGB, None without a gfx.Background). See the module docstring."""
    import pygfx as gfx

    w, h = int(size[0]), int(size[1])
    camera.set_view_size(w, h)  # as pygfx's renderer does before each frame: the aspect follows the size
    projection = np.asarray(camera.projection_matrix, np.float64)
    cam = Camera(np.asarray(camera.camera_matrix, np.float64))
    out, lit, lights, background = Scene(), False, 0, None
    ambient = np.zeros(3)
    for ob in scene.iter(skip_invisible=True):
        if isinstance(ob, gfx.Background) and background is None:
            background = tuple(float(c) for c in srgb_to_linear(np.asarray(ob.material.color_bottom_left.rgb, np.float64)))
        elif isinstance(ob, gfx.Mesh):
            lit |= _add_mesh(out, ob)
        elif isinstance(ob, gfx.Points):
            _add_points(out, ob, cam, projection, h)
        elif isinstance(ob, gfx.Line):
            _add_line(out, ob, cam, projection, h)
        elif isinstance(ob, gfx.DirectionalLight):
            target = ob.target.world.position if ob.target is not None else np.zeros(3)
            color = srgb_to_linear(np.asarray(ob.color.rgb, np.float64))
            out.add_light(np.asarray(target, np.float64) - np.asarray(ob.world.position, np.float64), tuple(color),
                          float(ob.intensity))
            lights += 1
        elif isinstance(ob, gfx.AmbientLight):
            ambient += srgb_to_linear(np.asarray(ob.color.rgb, np.float64)) * float(ob.intensity)
    if lit and lights == 0:
        out.add_light((0.0, 0.0, -1.0), (0.0, 0.0, 0.0))  # no headlight: pygfx lights only with lights
    out.ambient = tuple(float(a) for a in np.clip(ambient, 0.0, None))
    return out, cam, background


def render(scene: Any, camera: Any, method: str = "abuffer", size: tuple[int, int] = (640, 480),
           background: Sequence[float] | None = None, **params: Any) -> Frame:
    """Renders a pygfx scene (a gfx.Scene or any WorldObject) seen by a pygfx camera with oit's
    `method` at `size` (w, h); `params` go to oit.Renderer.render (antialias, method parameters).
    The background is `background` (linear RGB), else the scene's gfx.Background, else black
    (pygfx's clear color). One oit.Renderer is kept per size."""
    oscene, cam, bg = to_oit(scene, camera, size)
    key = (int(size[0]), int(size[1]))
    if key not in _renderers:
        _renderers[key] = Renderer(*key)
    bg = tuple(background) if background is not None else (bg or (0.0, 0.0, 0.0))
    return _renderers[key].render(oscene, cam, method, background=bg, **params)


def show(frame: Frame, canvas: Any = None) -> Any:
    """Shows `frame` in a pygfx canvas (a new rendercanvas window when `canvas` is None; pass
    an offscreen one to draw without a display) and returns the canvas: the image is an sRGB
    texture drawn pixel for pixel by an orthographic camera."""
    import pygfx as gfx

    h, w = frame.image.shape[:2]
    if canvas is None:
        from rendercanvas.auto import RenderCanvas

        canvas = RenderCanvas(size=(w, h), title="oit")
    rgba = np.empty((h, w, 4), np.uint8)
    rgba[..., :3] = np.rint(np.clip(linear_to_srgb(np.clip(frame.image[..., :3], 0, 1)), 0, 1) * 255)
    rgba[..., 3] = 255
    # gfx.Image puts row 0 at y = 0 (the bottom): flip so the frame's top row is at the top.
    image = gfx.Image(gfx.Geometry(grid=gfx.Texture(np.ascontiguousarray(rgba[::-1]), dim=2, colorspace="srgb")),
                      gfx.ImageBasicMaterial(clim=(0, 255), interpolation="nearest"))
    view = gfx.Scene()
    view.add(image)
    camera = gfx.OrthographicCamera(w, h, maintain_aspect=False)
    camera.local.position = (w / 2 - 0.5, h / 2 - 0.5, 0)
    renderer = gfx.WgpuRenderer(canvas, pixel_scale=1, ppaa="none")
    canvas.request_draw(lambda: renderer.render(view, camera))
    return canvas
