"""A scene as arrays, so that another renderer (or a scene file) can draw the same input:
`MeshArrays` (one mesh as `Scene.add_mesh` takes it) and `BuiltScene` (an oit.Scene with its
camera, size, meshes and lights), with `from_meshes`, `is_lit` and `unlit`. `oit.scenes`
builds its scenes from these and exports them."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ._api import Camera, Scene

# The triangles of a particle's disc for peers (MeshArrays.peer_triangles).
PEER_FAN_SEGMENTS = 10


def _fan_indices(fans: int, segments: int) -> np.ndarray:
    """Triangles of `fans` fans of `segments` each, a fan's centre first, then its ring
    counter-clockwise: (fans * segments, 3)."""
    j = np.arange(segments)
    fan = np.stack([np.zeros(segments, int), 1 + j, 1 + (j + 1) % segments], 1)
    return (np.arange(fans)[:, None, None] * (segments + 1) + fan[None]).reshape(-1, 3)


def _highlight_normals(travel: np.ndarray, view: np.ndarray, tangent: np.ndarray) -> np.ndarray:
    """Kajiya-Kay's highlight baked into normals: the half vector between the light (travelling
    along `travel`) and `view` (unit, towards the eye), made perpendicular to the unit tangent."""
    half = -travel / np.linalg.norm(travel) + view
    half /= np.maximum(np.linalg.norm(half, axis=1, keepdims=True), 1e-30)
    normals = half - np.sum(half * tangent, 1, keepdims=True) * tangent
    return normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)


@dataclass
class MeshArrays:
    """One mesh as `Scene.add_mesh` takes it; colors are per vertex, straight linear RGBA."""

    positions: np.ndarray
    indices: np.ndarray
    colors: np.ndarray
    opaque: bool = False
    # The surface, as Scene.add_mesh's keywords (normals, shading, specular, ...); empty: unlit.
    surface: dict[str, Any] = field(default_factory=dict)
    # Instances (Scene.set_instances): (n, 4, 4) transforms and (n, 4) color factors, or None
    # for a mesh drawn once where its vertices are.
    transforms: np.ndarray | None = None
    instance_colors: np.ndarray | None = None
    # A strand or particle set instead of triangles (no indices; positions are its points):
    # {"kind": "strands", "counts": (strands,), "widths": (n,)} or {"kind": "particles",
    # "radii": (n,), "falloff": "hard" | "linear" | "gaussian"}; `surface` then holds
    # add_strands' shading, specular, shininess and opacity, or add_particles' opacity. Or a
    # splat set: {"kind": "gaussians", "scales": (n, 3), "rotations": (n, 4), "sh": (n, k, 3)
    # or None, "degree": int, "splat_depth": "center" (when absent) or "ray"}, the opacities the
    # colors' alpha (add_gaussians).
    primitive: dict[str, Any] | None = None

    def add_to(self, scene: Scene) -> int:
        """Adds this mesh or set to `scene` (without its instances); returns its index."""
        p = self.primitive
        if p is None:
            return scene.add_mesh(self.positions, self.indices, self.colors, opaque=self.opaque, **self.surface)
        if p["kind"] == "strands":
            return scene.add_strands(self.positions, p["counts"], p["widths"], self.colors, self.opaque, **self.surface)
        if p["kind"] == "gaussians":
            # The opacity is the colors' alpha; harmonics (n k, 3) replace their RGB where given.
            col = np.broadcast_to(np.asarray(self.colors, np.float32).reshape(-1, 4), (len(self.positions), 4))
            sh = p.get("sh")
            if sh is not None:
                sh = np.asarray(sh, np.float32).reshape(len(self.positions), -1, 3)
            return scene.add_gaussians(self.positions, p["scales"], p["rotations"], col[:, 3],
                                       None if sh is not None else col[:, :3], sh=sh,
                                       splat_depth=p.get("splat_depth", "center"))
        return scene.add_particles(self.positions, p["radii"], self.colors, self.opaque, falloff=p["falloff"], **self.surface)

    def triangles(self, camera: Camera) -> MeshArrays:
        """A strand or particle set as the triangles it is drawn as under `camera`
        (`Scene.to_triangles`: strands keep their "hair" shading with the tangents as normals);
        a triangle mesh as it is. For files that take only triangles."""
        if self.primitive is None:
            return self
        scene = Scene()
        self.add_to(scene)
        t = scene.to_triangles(0, camera)
        surface = dict(self.surface)
        if t["normals"] is not None:
            surface["normals"] = t["normals"]
        return MeshArrays(t["positions"], t["indices"], t["colors"], self.opaque, surface)

    def peer_triangles(self, camera: Camera, lights: Sequence[tuple[Any, Any, float]] = ()) -> MeshArrays:
        """What a peer that draws only Phong-lit or unlit triangles draws for this mesh or set
        under `camera`: `triangles`, but "hair" strands lit as the ribbons of `hair(primitive=
        "ribbons")` are (Kajiya-Kay's highlight baked into the normals for the first light, or
        the headlight, and this eye) and particles as fans of PEER_FAN_SEGMENTS triangles
        whose rim carries the falloff's value at the rim (exact for "hard", linear across the
        disc for "linear", for "gaussian" a linear fan to exp(-4.5)). An approximation for
        peers only: the engine draws the sets themselves."""
        if self.primitive is None:
            return self
        if self.primitive["kind"] == "particles":
            return self._peer_fans(camera)
        t = self.triangles(camera)
        if t.surface.get("shading") != "hair":
            return t
        # Towards the eye: the homogeneous eye is inv(view_proj) (0, 0, 1, 0); an orthographic
        # camera's is at infinity, against the view direction.
        eye = np.linalg.inv(np.asarray(camera.view_proj, np.float64)) @ np.array([0.0, 0.0, 1.0, 0.0])
        p = t.positions.astype(np.float64)
        view = eye[:3] / eye[3] - p if abs(eye[3]) > 1e-12 else np.broadcast_to(-camera.view_direction, p.shape)
        view = view / np.maximum(np.linalg.norm(view, axis=1, keepdims=True), 1e-30)
        travel = np.asarray(lights[0][0], np.float64) if lights else camera.view_direction
        normals = _highlight_normals(travel, view, np.asarray(t.surface["normals"], np.float64))
        surface = {k: v for k, v in t.surface.items() if k != "shading"}
        surface["normals"] = normals.astype(np.float32)
        return replace(t, surface=surface)

    def _peer_fans(self, camera: Camera) -> MeshArrays:
        # Six corners a particle (primitive::CORNERS): (-1, -1), (1, -1), (-1, 1) first.
        quads = self.triangles(camera).positions.astype(np.float64).reshape(-1, 6, 3)
        right, up = (quads[:, 1] - quads[:, 0]) / 2, (quads[:, 2] - quads[:, 0]) / 2
        center = quads[:, 0] + right + up
        angle = 2 * np.pi * np.arange(PEER_FAN_SEGMENTS) / PEER_FAN_SEGMENTS
        ring = center[:, None] + np.cos(angle)[None, :, None] * right[:, None] + np.sin(angle)[None, :, None] * up[:, None]
        verts = np.concatenate([center[:, None], ring], 1)
        rim = {"hard": 1.0, "linear": 0.0, "gaussian": float(np.exp(-4.5))}[self.primitive["falloff"]]
        colors = np.repeat(np.asarray(self.colors, np.float32)[:, None], PEER_FAN_SEGMENTS + 1, axis=1)
        colors[:, 1:, 3] *= rim
        tris = _fan_indices(len(verts), PEER_FAN_SEGMENTS)
        return MeshArrays(verts.reshape(-1, 3).astype(np.float32), tris.astype(np.uint32), colors.reshape(-1, 4),
                          self.opaque, dict(self.surface))

    def placed(self) -> list[MeshArrays]:
        """The mesh as drawn: one copy per instance, positions and normals carried by its
        transform (normals by the inverse transpose) and colors times its factor, in float64
        then float32; itself when it has no instances. For peers and files that take plain arrays."""
        if self.transforms is None:
            return [self]
        factors = np.ones((len(self.transforms), 4)) if self.instance_colors is None else self.instance_colors
        out = []
        for t, f in zip(self.transforms, factors):
            linear = t[:3, :3]
            surface = dict(self.surface)
            if surface.get("normals") is not None:
                n = np.asarray(surface["normals"], dtype=np.float64) @ np.linalg.inv(linear)
                surface["normals"] = (n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)).astype(np.float32)
            pos = (self.positions.astype(np.float64) @ linear.T + t[:3, 3]).astype(np.float32)
            idx = self.indices if np.linalg.det(linear) > 0 else np.ascontiguousarray(self.indices[:, ::-1])
            out.append(MeshArrays(pos, idx, (self.colors * np.float32(f)).astype(np.float32), self.opaque, surface,
                                  primitive=self.primitive))
        return out


@dataclass
class BuiltScene:
    scene: Scene
    camera: Camera
    size: tuple[int, int] = (512, 512)
    meta: dict[str, Any] = field(default_factory=dict)
    meshes: list[MeshArrays] = field(default_factory=list)
    # (direction, color, intensity) of each light (none: the headlight), and the ambient term.
    lights: list[tuple[tuple[float, float, float], tuple[float, float, float], float]] = field(default_factory=list)
    ambient: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __iter__(self) -> Iterator[Any]:
        yield self.scene
        yield self.camera

    def drawn_meshes(self) -> list[MeshArrays]:
        """Every mesh as a peer draws it, each instance a copy (`MeshArrays.placed`), strand and
        particle sets as triangles under the scene's camera and lights
        (`MeshArrays.peer_triangles`)."""
        return [p.peer_triangles(self.camera, self.lights) for m in self.meshes for p in m.placed()]


def from_meshes(meshes: Sequence[MeshArrays], camera: Camera, size: tuple[int, int] = (512, 512),
                meta: dict[str, Any] | None = None, lights: Sequence[tuple[Any, Any, float]] = (),
                ambient: Sequence[float] = (0.0, 0.0, 0.0)) -> BuiltScene:
    """A BuiltScene of the given meshes, added in order, with `lights` ((direction, color,
    intensity) each; none: the headlight) and `ambient`."""
    scene = Scene()
    for m in meshes:
        index = m.add_to(scene)
        if m.transforms is not None:
            scene.set_instances(index, m.transforms, m.instance_colors)
    lights = [(tuple(map(float, d)), tuple(map(float, c)), float(i)) for d, c, i in lights]
    for d, c, i in lights:
        scene.add_light(d, c, i)
    ambient = (float(ambient[0]), float(ambient[1]), float(ambient[2]))
    scene.ambient = ambient
    meta = {**(meta or {}), "triangles": scene.triangle_count}
    return BuiltScene(scene, camera, size, meta, list(meshes), lights, ambient)


def is_lit(built: BuiltScene) -> bool:
    """Whether any mesh of `built` has a surface or the scene has lights or ambient light."""
    return any(m.surface for m in built.meshes) or bool(built.lights) or any(built.ambient)


def unlit(built: BuiltScene) -> BuiltScene:
    """The same meshes with their vertex colors only, no lights: what the peers (pygfx, VTK)
    draw, and an input whose colors do not vary inside a pixel beyond the vertex colors'.
    Instances stay, and strand and particle sets stay sets (unlit; a particle's falloff, part
    of its coverage, stays too)."""
    meshes = [MeshArrays(m.positions, m.indices, m.colors, m.opaque, transforms=m.transforms,
                         instance_colors=m.instance_colors, primitive=m.primitive) for m in built.meshes]
    return from_meshes(meshes, built.camera, built.size, dict(built.meta))


def _mesh(positions: np.ndarray, indices: Any, rgba: np.ndarray, opaque: bool = False, **surface: Any) -> MeshArrays:
    """MeshArrays with float32/uint32 arrays; one RGBA is repeated for every vertex; `surface`:
    Scene.add_mesh's keywords."""
    rgba = np.asarray(rgba, dtype=np.float32)
    colors = np.tile(rgba, (len(positions), 1)) if rgba.shape == (4,) else rgba
    return MeshArrays(np.ascontiguousarray(positions, dtype=np.float32), np.ascontiguousarray(indices, dtype=np.uint32),
                      np.ascontiguousarray(colors), opaque, surface)
