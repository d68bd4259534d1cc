"""The scene interchange file (`.oitscene`) that the viewer (crates/oit-viewer) reads.

`oit.Scene` keeps its arrays in Rust, so a file is written from the arrays themselves: a
`BuiltScene` from `oit.scenes` (which carries its meshes), or a list of `MeshArrays`. The
layout is docs/viewer.md's; its one reader and writer is the core's
(crates/oit-core/src/scenefile/), which the viewer uses too. A file is written in the oldest
version that holds it (1 without surfaces, lights or ambient term, so that older readers still
read unlit scenes; 3 only with a strand or particle set or "hair" shading), and every version is
read.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Union

import numpy as np

from . import _oit
from ._api import Camera, Scene
from ._checks import SURFACE, _surface
from .scenes import BuiltScene, MeshArrays

__all__ = ["LookAt", "save_scene", "load_scene", "load_lights", "scene_of", "MAGIC", "VERSION"]

MAGIC, VERSION = _oit.scene_file_format()


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
    records = [_record(i, p, names[i]) for i, p in enumerate(p for m in meshes for p in m.placed())]
    if camera is None:
        spec = None
    elif isinstance(camera, LookAt):
        spec = (2, [float(v) for v in (*camera.eye, *camera.target, *camera.up, camera.fov_y, camera.near, camera.far)])
    elif isinstance(camera, Camera):
        spec = (1, np.asarray(camera.view_proj, dtype=np.float64).reshape(-1).tolist())
    else:
        raise TypeError(f"camera must be an oit.Camera or a scenefile.LookAt, got {type(camera).__name__}")
    lights = [(tuple(map(float, d)), tuple(map(float, c)), float(i)) for d, c, i in (lights or [])]
    ambient = tuple(float(a) for a in (ambient if ambient is not None else (0.0, 0.0, 0.0)))
    data = _oit.encode_scene(records, spec, tuple(size) if size else None, lights, ambient)
    with open(path, "wb") as f:
        f.write(data)


def _record(i: int, m: MeshArrays, name: str) -> dict[str, Any]:
    """A mesh as the core's codec takes it (crates/oit-py/src/scenefile.rs)."""
    pos = np.ascontiguousarray(m.positions, dtype=np.float32).reshape(-1, 3)
    col = np.asarray(m.colors, dtype=np.float32)
    col = np.ascontiguousarray(np.broadcast_to(col.reshape(-1, 4), (len(pos), 4)) if col.size == 4 else col.reshape(-1, 4))
    if len(col) != len(pos):
        raise ValueError(f"mesh {i}: {len(col)} colors for {len(pos)} vertices")
    primitive = None
    if m.primitive is not None:
        p, n = m.primitive, len(pos)
        if p["kind"] not in ("strands", "particles", "gaussians"):
            raise ValueError(f"primitive kind must be 'strands', 'particles' or 'gaussians', got {p['kind']!r}")
        if p["kind"] == "gaussians":
            primitive = _splat_record(p, n)
        else:
            size = p["widths"] if p["kind"] == "strands" else p["radii"]
            primitive = {"kind": p["kind"], "counts": None, "falloff": p.get("falloff"),
                         "sizes": np.ascontiguousarray(np.broadcast_to(np.asarray(size, np.float32).reshape(-1), (n,))),
                         "scales": None, "rotations": None, "sh": None, "degree": None}
        if p["kind"] == "strands":
            primitive["counts"] = np.ascontiguousarray(p["counts"], dtype=np.uint32).reshape(-1)
    surface = None
    if m.surface:
        s = m.surface
        surface = _surface(len(pos), *(s.get(k) for k in ("normals", "uvs", "texture", "shading")),
                           *(s.get(k, SURFACE[k]) for k in ("specular", "shininess", "opacity", "two_sided", "cull_back_faces")))
    return {"name": name, "opaque": bool(m.opaque), "positions": pos, "colors": col,
            "indices": np.ascontiguousarray(m.indices, dtype=np.uint32).reshape(-1, 3), "primitive": primitive,
            "surface": surface}


def _splat_record(p: dict[str, Any], n: int) -> dict[str, Any]:
    """A splat set's primitive record: scales (n, 3), rotations (n, 4), harmonics (n k, 3) or
    None and their degree (the opacity is the colors' alpha)."""
    rows = lambda a, k: np.ascontiguousarray(np.broadcast_to(np.asarray(a, np.float32).reshape(-1, k), (n, k)))  # noqa: E731
    sh = p.get("sh")
    if sh is not None:
        sh = np.ascontiguousarray(np.asarray(sh, np.float32).reshape(-1, 3))
    return {"kind": "gaussians", "counts": None, "falloff": None, "sizes": None, "scales": rows(p["scales"], 3),
            "rotations": rows(p["rotations"], 4), "sh": sh, "degree": int(p.get("degree", 0))}


def load_scene(path: str | os.PathLike) -> tuple[list, Any, tuple[int, int] | None]:
    """Reads a scene file back: (meshes as MeshArrays, Camera or LookAt or None, size or None)."""
    return _load(path)[:3]


def load_lights(path: str | os.PathLike) -> tuple[list, tuple[float, float, float]]:
    """A scene file's lights ((direction, color, intensity) each) and ambient term."""
    return _load(path)[3:]


def _load(path: str | os.PathLike) -> tuple[list, Any, tuple[int, int] | None, list, tuple[float, float, float]]:
    with open(path, "rb") as f:
        data = f.read()
    try:
        records, spec, size, lights, ambient = _oit.decode_scene(data)
    except ValueError as e:
        raise ValueError(f"{path}: {e}") from None
    camera: Any = None
    if spec is not None and spec[0] == 1:
        camera = Camera(np.array(spec[1], dtype=np.float64).reshape(4, 4))
    elif spec is not None:
        v = spec[1]
        camera = LookAt(tuple(v[0:3]), tuple(v[3:6]), tuple(v[6:9]), v[9], v[10], v[11])
    meshes = []
    for r in records:
        surface, primitive = r["surface"] or {}, r["primitive"]
        if surface and primitive is not None:
            # A set's surface: the words add_strands takes, or a particle set's opacity.
            keys = ("opacity",) if primitive["kind"] == "particles" else ("shading", "specular", "shininess", "opacity")
            surface = {k: surface[k] for k in keys}
        meshes.append(MeshArrays(r["positions"], r["indices"], r["colors"], r["opaque"], surface, primitive=primitive))
    return meshes, camera, size, [(tuple(d), tuple(c), i) for d, c, i in lights], tuple(ambient)


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
