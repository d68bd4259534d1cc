"""Small mesh files written by the tests, for the loader (oit-core's, behind Scene.from_file,
the command line and the viewer): a GLB built by hand (JSON and binary chunks), OBJ with MTL,
PLY with RGBA vertex colors and binary STL."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np

from oit.imageio import encode_png

# A unit cube's corners and its 12 triangles, counter-clockwise seen from outside.
CUBE = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)], dtype=np.float32)
CUBE_FACES = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                       [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], dtype=np.uint32)
QUAD = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float32)
QUAD_FACES = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
QUAD_UVS = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], dtype=np.float32)


class Gltf:
    """A glTF document grown call by call; `glb()` packs it with its one binary buffer."""

    def __init__(self) -> None:
        self.bin = bytearray()
        self.doc: dict = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                          "materials": [], "accessors": [], "bufferViews": []}

    def _view(self, data: bytes) -> int:
        self.bin += b"\0" * (-len(self.bin) % 4)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)})
        self.bin += data
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, a: np.ndarray, kind: str, **extra) -> int:
        component = {"int8": 5120, "uint8": 5121, "int16": 5122, "uint16": 5123, "uint32": 5125}.get(a.dtype.name, 5126)
        a = a.astype(np.float32) if component == 5126 else a
        acc = {"bufferView": self._view(a.tobytes()), "componentType": component, "count": len(a), "type": kind, **extra}
        if kind == "VEC3" and component == 5126:
            acc["min"], acc["max"] = a.min(0).tolist(), a.max(0).tolist()
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def accessor(self, a, kind: str, **extra) -> int:
        """An accessor of `a` (its dtype gives the componentType; float64 is written float32)."""
        return self._accessor(np.asarray(a), kind, **extra)

    def material(self, **m) -> int:
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def texture(self, rgba8: np.ndarray, sampler: dict | None = None) -> int:
        """A PNG texture (sRGB color, linear alpha) of an (h, w, 4) uint8 image, with `sampler`."""
        view = self._view(encode_png(rgba8))
        self.doc.setdefault("images", []).append({"bufferView": view, "mimeType": "image/png"})
        texture = {"source": len(self.doc["images"]) - 1}
        if sampler is not None:
            self.doc.setdefault("samplers", []).append(sampler)
            texture["sampler"] = len(self.doc["samplers"]) - 1
        self.doc.setdefault("textures", []).append(texture)
        return len(self.doc["textures"]) - 1

    def mesh(self, positions, indices, material: int | None = None, uvs=None, name: str = "", mode: int | None = None,
             attributes: dict | None = None) -> int:
        """A mesh of one primitive; `indices` None draws the vertices in order, `mode` is glTF's
        (None: TRIANGLES), `attributes` more accessors by name (COLOR_0: accessor index)."""
        attributes = {"POSITION": self._accessor(np.asarray(positions, np.float32), "VEC3"), **(attributes or {})}
        if uvs is not None:
            attributes["TEXCOORD_0"] = self._accessor(np.asarray(uvs, np.float32), "VEC2")
        prim: dict = {"attributes": attributes}
        if indices is not None:
            prim["indices"] = self._accessor(np.asarray(indices, np.uint32).reshape(-1), "SCALAR")
        if mode is not None:
            prim["mode"] = mode
        if material is not None:
            prim["material"] = material
        self.doc["meshes"].append({"name": name, "primitives": [prim]})
        return len(self.doc["meshes"]) - 1

    def node(self, root: bool = True, **n) -> int:
        self.doc["nodes"].append(n)
        if root:
            self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)
        return len(self.doc["nodes"]) - 1

    def gltf(self, path: Path, bin_name: str | None = None) -> Path:
        """The document as .gltf at `path`, its buffer in the file `bin_name` next to it (None:
        a base64 data URI)."""
        import base64

        blob = bytes(self.bin)
        if bin_name is None:
            uri = "data:application/octet-stream;base64," + base64.b64encode(blob).decode()
        else:
            uri = bin_name
            (path.parent / bin_name).write_bytes(blob)
        path.write_text(json.dumps({**self.doc, "buffers": [{"byteLength": len(blob), "uri": uri}]}))
        return path

    def glb(self) -> bytes:
        doc = {**self.doc, "buffers": [{"byteLength": len(self.bin)}]}
        text = json.dumps(doc).encode()
        text += b" " * (-len(text) % 4)
        blob = bytes(self.bin) + b"\0" * (-len(self.bin) % 4)
        chunks = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(blob), b"BIN\0") + blob
        return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def box_and_panel_glb(path: Path, panel: bool = True) -> Path:
    """An OPAQUE red box (the material gives no alphaMode: OPAQUE is the spec's default) in front
    of a BLEND blue panel at alpha 0.5, seen from +z: the issue's example."""
    g = Gltf()
    red = g.material(name="red", pbrMetallicRoughness={"baseColorFactor": [1, 0, 0, 1]})
    g.node(mesh=g.mesh(CUBE, CUBE_FACES, red, name="box"), translation=[0, 0, 0.5])
    if panel:
        blue = g.material(name="blue", alphaMode="BLEND", doubleSided=True,
                          pbrMetallicRoughness={"baseColorFactor": [0, 0, 1, 0.5]})
        g.node(mesh=g.mesh(QUAD * [2, 2, 1], QUAD_FACES, blue, name="panel"), translation=[0, 0, -0.5])
    path.write_bytes(g.glb())
    return path


def textured_multi_node_glb(path: Path) -> Path:
    """A textured, double-sided quad under a parent node (translated, scaled) and a second
    instance of it on another node (rotated a half turn about y), with a camera on +z."""
    g = Gltf()
    texels = np.zeros((2, 2, 4), np.uint8)
    texels[..., 3] = 255
    texels[0, 0, :3], texels[0, 1, :3], texels[1, 0, :3], texels[1, 1, :3] = (255, 0, 0), (0, 255, 0), (0, 0, 255), (255, 255, 255)
    tex = g.material(name="checker", doubleSided=True, alphaMode="BLEND",
                     pbrMetallicRoughness={"baseColorFactor": [1, 1, 1, 0.6], "baseColorTexture": {"index": g.texture(texels)}})
    quad = g.mesh(QUAD, QUAD_FACES, tex, uvs=QUAD_UVS, name="quad")
    child = g.node(root=False, mesh=quad, scale=[0.5, 0.5, 0.5])
    g.node(children=[child], translation=[1, 0, 0])
    g.node(mesh=quad, translation=[-1, 0, 0], rotation=[0, 1, 0, 0])
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1, "zfar": 20, "aspectRatio": 1.0}}]
    g.node(camera=0, translation=[0, 0, 4])
    path.write_bytes(g.glb())
    return path


def obj_with_dissolve(path: Path) -> Path:
    """Two quads: 'glass' with d 0.25 (Kd red) and 'wall' with Tr 0.5 (Kd blue, sRGB 0.5)."""
    path.with_suffix(".mtl").write_text("newmtl glass\nKd 1 0 0\nd 0.25\nnewmtl wall\nKd 0 0 0.5\nTr 0.5\n")
    v = "".join(f"v {x} {y} {z}\n" for x, y, z in QUAD.tolist()) + "".join(f"v {x} {y} -1\n" for x, y, _ in QUAD.tolist())
    path.write_text(f"mtllib {path.with_suffix('.mtl').name}\n{v}o glass\nusemtl glass\nf 1 2 3 4\n"
                    "o wall\nusemtl wall\nf 5 6 7\nf 5 7 8\n")
    return path


def ply_rgba(path: Path) -> Path:
    """A quad (one polygon, fanned) with 8-bit RGBA vertex colors, alpha 128/255."""
    head = ("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n")
    rows = "".join(f"{x} {y} {z} 0 255 0 128\n" for x, y, z in QUAD.tolist())
    path.write_text(head + rows + "4 0 1 2 3\n")
    return path


def stl_cube(path: Path) -> Path:
    """The cube as binary STL (12 facets)."""
    data = bytearray(80) + struct.pack("<I", len(CUBE_FACES))
    for f in CUBE_FACES:
        data += struct.pack("<3f", 0, 0, 0) + CUBE[f].astype("<f4").tobytes() + b"\0\0"
    path.write_bytes(bytes(data))
    return path


def ply_points(path: Path) -> Path:
    """A point cloud: three points with 8-bit RGBA colors and no faces."""
    head = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\nend_header\n")
    path.write_text(head + "-0.5 0 0 255 0 0 128\n0.5 0 0 0 255 0 128\n0 0.5 0.2 0 0 255 255\n")
    return path


# OBJ/MTL, PLY and STL as exporters write them (tests/test_load_formats.py).

def obj_lines_points_empty_usemtl(path: Path) -> Path:
    """A red triangle, then after an empty `usemtl` a polyline (`l`, 3 points) and two points
    (`p`) in the default gray; the vertices' box is 3 by 4 (diagonal 5)."""
    path.with_suffix(".mtl").write_text("newmtl red\nKd 1 0 0\n")
    path.write_text(f"mtllib {path.with_suffix('.mtl').name}\nv 0 0 0\nv 3 0 0\nv 3 4 0\nv 0 4 0\n"
                    "o tri\nusemtl red\nf 1 2 3\no wire\nusemtl\nl 1 2 3\no dots\np 1 4\n")
    return path


def obj_meshlab_tr(path: Path, tr: str = "1.000000") -> Path:
    """A quad whose material MeshLab wrote: `Tr 1.000000` and no `d`."""
    path.with_suffix(".mtl").write_text(f"#\n# Wavefront material file\n# Converted by Meshlab Group\n#\n\n"
                                        f"newmtl material_0\nKa 0.2 0.2 0.2\nKd 0.5 0.5 1\nKs 1 1 1\nTr {tr}\nillum 2\nNs 0\n")
    v = "".join(f"v {x} {y} {z}\n" for x, y, z in QUAD.tolist())
    path.write_text(f"mtllib {path.with_suffix('.mtl').name}\n{v}usemtl material_0\nf 1 2 3 4\n")
    return path


def stl_ascii_solids(path: Path, names: list[str], facets: int = 1) -> Path:
    """An ASCII STL of one `solid` block a name (an empty name is a bare `solid` header), each
    of `facets` triangles."""
    text = ""
    for name in names:
        text += f"solid {name}\n" if name else "solid\n"
        for k in range(facets):
            text += (f" facet normal 0 0 1\n  outer loop\n   vertex 0 0 {k}\n   vertex 1 0 {k}\n   vertex 0 1 {k}\n"
                     "  endloop\n endfacet\n")
        text += f"endsolid {name}\n"
    path.write_text(text)
    return path


def ply_face_colors(path: Path, binary: bool = False) -> Path:
    """A quad as two triangles sharing an edge: face 0 red (opaque), face 1 blue at alpha
    128/255, 8-bit per-face colors (the shared vertices are split)."""
    head = ("ply\nformat {} 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 2\nproperty list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\n"
            "property uchar blue\nproperty uchar alpha\nend_header\n")
    faces = [([0, 1, 2], (255, 0, 0, 255)), ([0, 2, 3], (0, 0, 255, 128))]
    if binary:
        data = head.format("binary_big_endian").encode() + QUAD.astype(">f4").tobytes()
        for idx, rgba in faces:
            data += struct.pack(">B3i4B", 3, *idx, *rgba)
        path.write_bytes(data)
    else:
        rows = "".join(f"{x} {y} {z}\n" for x, y, z in QUAD.tolist())
        rows += "".join(f"3 {' '.join(map(str, idx))} {' '.join(map(str, rgba))}\n" for idx, rgba in faces)
        path.write_text(head.format("ascii") + rows)
    return path


def ply_gaussians(path: Path, count: int = 1500) -> Path:
    """A 3DGS PLY (binary little endian) of oit.scenes.splats(count): f_dc the color's degree-0
    harmonic, the opacity as a logit, the scales as logs, the wxyz quaternion."""
    import oit

    m = oit.scenes.splats(count).meshes[0]
    rgb, alpha = m.colors[:, :3].astype(np.float64), m.colors[:, 3].astype(np.float64)
    columns = [m.positions, (rgb - 0.5) / 0.28209479177387814, np.log(alpha / (1 - alpha))[:, None],
               np.log(m.primitive["scales"]), m.primitive["rotations"]]
    names = ["x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2",
             "rot_0", "rot_1", "rot_2", "rot_3"]
    header = f"ply\nformat binary_little_endian 1.0\nelement vertex {count}\n"
    header += "".join(f"property float {n}\n" for n in names) + "end_header\n"
    path.write_bytes(header.encode() + np.concatenate(columns, 1).astype("<f4").tobytes())
    return path
