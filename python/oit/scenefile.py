"""The scene interchange file (`.oitscene`) that the viewer (crates/oit-viewer) reads.

`oit.Scene` keeps its arrays in Rust, so a file is written from the arrays themselves: a
`BuiltScene` from `oit.scenes` (which carries its meshes), or a list of `MeshArrays`. The
layout (docs/viewer.md; crates/oit-viewer/src/scenefile.rs reads it), all little-endian:

    b"OITSCENE", version u32 = 1, width u32, height u32 (0: no size),
    camera kind u32: 0 none | 1 view-projection, 16 f64 row-major | 2 look-at, 12 f64:
        eye xyz, target xyz, up xyz, fov_y (degrees), near, far
    mesh count u32, then per mesh: flags u32 (bit 0: opaque), name length u32, name UTF-8,
        vertices n u32, triangles m u32, positions n*3 f32, colors n*4 f32 (straight linear
        RGBA), indices m*3 u32
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

__all__ = ["LookAt", "save_scene", "load_scene", "scene_of", "MAGIC", "VERSION"]

MAGIC = b"OITSCENE"
VERSION = 1


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
               size: tuple[int, int] | None = None, names: Sequence[str] | None = None) -> None:
    """Writes `scene` (a BuiltScene or a list of MeshArrays) with `camera` (default: the
    BuiltScene's) and `size` (default: the BuiltScene's) to `path`."""
    if isinstance(scene, Scene):
        raise TypeError("an oit.Scene keeps its arrays in the engine: pass the BuiltScene from oit.scenes, "
                        "or the meshes as a list of oit.scenes.MeshArrays")
    if isinstance(scene, BuiltScene):
        camera = scene.camera if camera is None else camera
        size = scene.size if size is None else size
        meshes = list(scene.meshes)
    else:
        meshes = list(scene)
    out = [MAGIC, struct.pack("<3I", VERSION, *(size or (0, 0)))]
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
        name = (names[i] if names else f"mesh {i}").encode()
        out += [struct.pack("<2I", int(bool(m.opaque)), len(name)), name, struct.pack("<2I", len(pos), len(idx)),
                pos.tobytes(), col.tobytes(), idx.tobytes()]
    with open(path, "wb") as f:
        f.write(b"".join(out))


def load_scene(path: str | os.PathLike) -> tuple[list, Any, tuple[int, int] | None]:
    """Reads a scene file back: (meshes as MeshArrays, Camera or LookAt or None, size or None)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != MAGIC:
        raise ValueError(f"{path}: not an oit scene file")
    at = 8
    version, w, h, kind = struct.unpack_from("<4I", data, at)
    at += 16
    if version != VERSION:
        raise ValueError(f"{path}: scene file version {version}; this reads version {VERSION}")
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
        meshes.append(MeshArrays(pos, idx, col, bool(flags & 1)))
    return meshes, camera, ((w, h) if w and h else None)


def scene_of(meshes: Sequence[MeshArrays]) -> Scene:
    """An oit.Scene of the same meshes (for rendering a loaded file with the library)."""
    scene = Scene()
    for m in meshes:
        scene.add_mesh(m.positions, m.indices, m.colors, opaque=m.opaque)
    return scene
