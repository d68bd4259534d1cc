"""The scene interchange file (`.oitscene`) that the viewer (crates/oit-viewer) reads.

`oit.Scene` keeps its arrays in Rust, so a file is written from the arrays themselves: a
`BuiltScene` from `oit.scenes` (which carries its meshes), or a list of `MeshArrays`. The
layout (docs/viewer.md; crates/oit-viewer/src/scenefile.rs reads it), all little-endian:

    b"OITSCENE", version u32 = 1, width u32, height u32 (0: no size),
    camera kind u32: 0 none | 1 view-projection, 16 f64 row-major | 2 look-at, 12 f64:
        eye xyz, target xyz, up xyz, fov_y (degrees), near, far
    mesh count u32, then per mesh: flags u32 (bit 0: opaque, bit 1: a surface follows),
        name length u32, name UTF-8, vertices n u32, triangles m u32, positions n*3 f32,
        colors n*4 f32 (straight linear RGBA), indices m*3 u32, and with bit 1 (version 2):
        shading u32 (0 unlit, 1 flat, 2 smooth), two-sided u32, specular, shininess, opacity
        f32, normals count u32 (0 or n) and n*3 f32, UV count u32 (0 or n) and n*2 f32,
        texture height h u32 and width w u32 (0 0: none) and h*w*4 f32 linear RGBA
    version 2 only, after the meshes: light count u32, per light direction xyz, color rgb,
        intensity (7 f32); ambient rgb (3 f32)
    version 3: as version 2, and a mesh's flags bit 2 says it is a strand or particle set
        (oit.Scene.add_strands, add_particles): its n vertices are the points, it has no
        triangles (m = 0), and after its indices come kind u32 (1 strands, 2 particles), then
        for strands the strand count s u32, the points per strand s*u32 and the widths n*f32,
        for particles the falloff u32 (1 hard, 2 linear, 3 gaussian) and the radii n*f32; its
        surface (bit 1) has no normals, UVs or texture, and shading 3 is "hair"

A file is written as version 1 when no mesh has a surface and there are no lights or
ambient term, so that older readers still read unlit scenes; as version 3 only when it holds
a strand or particle set or "hair" shading.
"""

from __future__ import annotations

import os
import struct
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Union

import numpy as np

from ._api import Camera, Scene
from .scenes import BuiltScene, MeshArrays

__all__ = ["LookAt", "save_scene", "load_scene", "load_lights", "scene_of", "MAGIC", "VERSION"]

MAGIC = b"OITSCENE"
VERSION = 3
SHADING_CODES = {"unlit": 0, "flat": 1, "smooth": 2, "hair": 3}
FALLOFF_CODES = {"hard": 1, "linear": 2, "gaussian": 3}


@dataclass(frozen=True)
class LookAt:
    """A perspective camera by its placement, which the viewer can re-aim and fit to any
    window shape (a matrix fixes the aspect ratio it was made for)."""

    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 1.0, 0.0)
    fov_y: float = 45.0
    near: float = 0.1
    far: float = 100.0

    def camera(self, aspect: float = 1.0) -> Camera:
        return Camera.look_at(self.eye, self.target, self.fov_y, self.near, self.far, up=self.up, aspect=aspect)


SceneLike = Union[BuiltScene, Sequence[MeshArrays]]


def save_scene(scene: SceneLike, path: str | os.PathLike, camera: Camera | LookAt | None = None,
               size: tuple[int, int] | None = None, names: Sequence[str] | None = None,
               lights: Sequence[tuple[Any, Any, float]] | None = None, ambient: Sequence[float] | None = None) -> None:
    """Writes `scene` (a BuiltScene or a list of MeshArrays) with `camera`, `size`, `lights`
    and `ambient` (default: the BuiltScene's) to `path`."""
    if isinstance(scene, Scene):
        raise TypeError("an oit.Scene keeps its arrays in the engine: pass the BuiltScene from oit.scenes, "
                        "or the meshes as a list of oit.scenes.MeshArrays")
    if isinstance(scene, BuiltScene):
        camera = scene.camera if camera is None else camera
        size = scene.size if size is None else size
        lights = scene.lights if lights is None else lights
        ambient = scene.ambient if ambient is None else ambient
        meshes = list(scene.meshes)
    else:
        meshes = list(scene)
    # The file has no instances: a mesh drawn more than once is written once per instance.
    names = [(names[i] if names else f"mesh {i}") + (f" #{j}" if m.transforms is not None and j else "")
             for i, m in enumerate(meshes) for j in range(len(m.placed()))]
    meshes = [p for m in meshes for p in m.placed()]
    lights = list(lights or [])
    ambient = tuple(float(a) for a in (ambient if ambient is not None else (0.0, 0.0, 0.0)))
    version = 2 if lights or any(ambient) or any(m.surface for m in meshes) else 1
    if any(m.primitive is not None or m.surface.get("shading") == "hair" for m in meshes):
        version = 3
    out = [MAGIC, struct.pack("<3I", version, *(size or (0, 0)))]
    if camera is None:
        out.append(struct.pack("<I", 0))
    elif isinstance(camera, LookAt):
        values = [*camera.eye, *camera.target, *camera.up, camera.fov_y, camera.near, camera.far]
        out.append(struct.pack("<I12d", 2, *map(float, values)))
    elif isinstance(camera, Camera):
        out.append(struct.pack("<I", 1) + np.ascontiguousarray(camera.view_proj, dtype="<f8").tobytes())
    else:
        raise TypeError(f"camera must be an oit.Camera or a scenefile.LookAt, got {type(camera).__name__}")
    out.append(struct.pack("<I", len(meshes)))
    for i, m in enumerate(meshes):
        pos = np.ascontiguousarray(m.positions, dtype="<f4").reshape(-1, 3)
        col = np.asarray(m.colors, dtype="<f4")
        col = np.ascontiguousarray(np.broadcast_to(col.reshape(-1, 4), (len(pos), 4)) if col.size == 4 else col.reshape(-1, 4))
        idx = np.ascontiguousarray(m.indices, dtype="<u4").reshape(-1, 3)
        if len(col) != len(pos):
            raise ValueError(f"mesh {i}: {len(col)} colors for {len(pos)} vertices")
        name = names[i].encode()
        flags = int(bool(m.opaque)) | (2 if m.surface else 0) | (4 if m.primitive is not None else 0)
        out += [struct.pack("<2I", flags, len(name)), name, struct.pack("<2I", len(pos), len(idx)),
                pos.tobytes(), col.tobytes(), idx.tobytes()]
        if m.primitive is not None:
            out.append(_primitive_bytes(m.primitive, len(pos)))
        if m.surface:
            out.append(_surface_bytes(m.surface, len(pos)))
    if version >= 2:
        out.append(struct.pack("<I", len(lights)))
        for d, c, intensity in lights:
            out.append(struct.pack("<7f", *map(float, d), *map(float, c), float(intensity)))
        out.append(struct.pack("<3f", *ambient))
    with open(path, "wb") as f:
        f.write(b"".join(out))


def load_scene(path: str | os.PathLike) -> tuple[list, Any, tuple[int, int] | None]:
    """Reads a scene file back: (meshes as MeshArrays, Camera or LookAt or None, size or None)."""
    return _load(path)[:3]


def load_lights(path: str | os.PathLike) -> tuple[list, tuple[float, float, float]]:
    """A scene file's lights ((direction, color, intensity) each) and ambient term."""
    return _load(path)[3:]


def _load(path: str | os.PathLike) -> tuple[list, Any, tuple[int, int] | None, list, tuple[float, float, float]]:
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != MAGIC:
        raise ValueError(f"{path}: not an oit scene file")
    at = 8
    version, w, h, kind = struct.unpack_from("<4I", data, at)
    at += 16
    if version not in (1, 2, VERSION):
        raise ValueError(f"{path}: scene file version {version}; this reads versions 1 to {VERSION}")
    camera: Any = None
    if kind == 1:
        camera = Camera(np.frombuffer(data, "<f8", 16, at).reshape(4, 4))
        at += 128
    elif kind == 2:
        v = struct.unpack_from("<12d", data, at)
        camera = LookAt(tuple(v[0:3]), tuple(v[3:6]), tuple(v[6:9]), v[9], v[10], v[11])
        at += 96
    (count,) = struct.unpack_from("<I", data, at)
    at += 4
    meshes = []
    for _ in range(count):
        flags, name_len = struct.unpack_from("<2I", data, at)
        at += 8 + name_len
        n, m = struct.unpack_from("<2I", data, at)
        at += 8
        pos = np.frombuffer(data, "<f4", n * 3, at).reshape(n, 3)
        at += n * 12
        col = np.frombuffer(data, "<f4", n * 4, at).reshape(n, 4)
        at += n * 16
        idx = np.frombuffer(data, "<u4", m * 3, at).reshape(m, 3)
        at += m * 12
        primitive = None
        if flags & 4:
            primitive, at = _read_primitive(data, at, n)
        surface: dict[str, Any] = {}
        if flags & 2:
            surface, at = _read_surface(data, at, n)
            if primitive is not None:
                surface = {k: surface[k] for k in ("shading", "specular", "shininess", "opacity")}
                if primitive["kind"] == "particles":
                    surface = {"opacity": surface["opacity"]}
        meshes.append(MeshArrays(pos, idx, col, bool(flags & 1), surface, primitive=primitive))
    lights: list = []
    ambient = (0.0, 0.0, 0.0)
    if version >= 2:
        (count,) = struct.unpack_from("<I", data, at)
        at += 4
        for _ in range(count):
            v = struct.unpack_from("<7f", data, at)
            lights.append((tuple(v[0:3]), tuple(v[3:6]), v[6]))
            at += 28
        ambient = struct.unpack_from("<3f", data, at)
    return meshes, camera, ((w, h) if w and h else None), lights, tuple(ambient)


def scene_of(meshes: Sequence[MeshArrays], lights: Sequence[tuple[Any, Any, float]] = (),
             ambient: Sequence[float] = (0.0, 0.0, 0.0)) -> Scene:
    """An oit.Scene of the same meshes, surfaces and lights (for rendering a loaded file with
    the library)."""
    scene = Scene()
    for m in meshes:
        m.add_to(scene)
    for d, c, i in lights:
        scene.add_light(d, c, i)
    scene.ambient = tuple(ambient)
    return scene


def _primitive_bytes(p: dict[str, Any], n: int) -> bytes:
    """A strand or particle set's block (version 3): its kind and per-point sizes."""
    if p["kind"] == "strands":
        counts = np.ascontiguousarray(p["counts"], dtype="<u4").reshape(-1)
        sizes = np.broadcast_to(np.asarray(p["widths"], dtype="<f4").reshape(-1), (n,))
        head = struct.pack("<2I", 1, len(counts)) + counts.tobytes()
    elif p["kind"] == "particles":
        sizes = np.broadcast_to(np.asarray(p["radii"], dtype="<f4").reshape(-1), (n,))
        head = struct.pack("<2I", 2, FALLOFF_CODES[p["falloff"]])
    else:
        raise ValueError(f"primitive kind must be 'strands' or 'particles', got {p['kind']!r}")
    return head + np.ascontiguousarray(sizes).tobytes()


def _read_primitive(data: bytes, at: int, n: int) -> tuple[dict[str, Any], int]:
    kind, value = struct.unpack_from("<2I", data, at)
    at += 8
    if kind == 1:
        counts = np.frombuffer(data, "<u4", value, at)
        at += 4 * value
        widths = np.frombuffer(data, "<f4", n, at)
        return {"kind": "strands", "counts": counts, "widths": widths}, at + 4 * n
    if kind == 2:
        falloff = {v: k for k, v in FALLOFF_CODES.items()}[value]
        return {"kind": "particles", "radii": np.frombuffer(data, "<f4", n, at), "falloff": falloff}, at + 4 * n
    raise ValueError(f"unknown primitive kind {kind} (1: strands, 2: particles)")


def _surface_bytes(surface: dict[str, Any], n: int) -> bytes:
    from ._checks import SURFACE, _surface

    s = _surface(n, *(surface.get(k) for k in ("normals", "uvs", "texture", "shading")),
                 *(surface.get(k, SURFACE[k]) for k in ("specular", "shininess", "opacity", "two_sided", "cull_back_faces")))
    # The sidedness word: bit 0 two-sided lighting, bit 1 back faces culled (docs/viewer.md).
    sides = int(s["two_sided"]) | int(s["cull_back_faces"]) << 1
    out = [struct.pack("<2I3f", SHADING_CODES[s["shading"]], sides, s["specular"], s["shininess"], s["opacity"])]
    for key, width in (("normals", 3), ("uvs", 2)):
        a = s.get(key)
        out.append(struct.pack("<I", 0 if a is None else n))
        if a is not None:
            out.append(np.ascontiguousarray(a, dtype="<f4").reshape(n, width).tobytes())
    t = s.get("texture")
    out.append(struct.pack("<2I", *((0, 0) if t is None else t.shape[:2])))
    if t is not None:
        out.append(np.ascontiguousarray(t, dtype="<f4").tobytes())
    return b"".join(out)


def _read_surface(data: bytes, at: int, n: int) -> tuple[dict[str, Any], int]:
    code, sides, specular, shininess, opacity = struct.unpack_from("<2I3f", data, at)
    at += 20
    surface: dict[str, Any] = {"shading": {v: k for k, v in SHADING_CODES.items()}[code], "two_sided": bool(sides & 1),
                               "cull_back_faces": bool(sides & 2),
                               "specular": specular, "shininess": shininess, "opacity": opacity}
    for key, width in (("normals", 3), ("uvs", 2)):
        (count,) = struct.unpack_from("<I", data, at)
        at += 4
        if count:
            surface[key] = np.frombuffer(data, "<f4", count * width, at).reshape(count, width)
            at += count * width * 4
    h, w = struct.unpack_from("<2I", data, at)
    at += 8
    if h and w:
        surface["texture"] = np.frombuffer(data, "<f4", h * w * 4, at).reshape(h, w, 4)
        at += h * w * 16
    return surface, at
