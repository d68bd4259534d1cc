"""Loading files: speed and memory (`python -m oit bench --load`) and a fuzz run of the loader
(`python -m oit bench --fuzz-load`, and in short in tests/test_load_fuzz.py).

--load writes one ~1.3 M-triangle mesh as OBJ, GLB, binary PLY and binary STL into a temporary
directory and loads each with `Scene.from_file` in a fresh interpreter, which reports the load's
time and the process's peak resident memory (ru_maxrss): triangles a second against the
target of 2 M, and the peak against the file's size.

--fuzz-load mutates small files of every format (truncation, bit flips, numbers made huge,
negative or not numbers, glTF JSON fields deleted or of another type, huge counts, nodes that
form cycles or share a child, references to files that are not there) from a fixed seed and
loads each: the only outcomes allowed are a scene, ValueError or OSError. Anything else (a
PanicException, another exception, a load past the time limit, peak memory past the bound) is
a failure, kept in --out with the bytes that caused it.
"""

from __future__ import annotations

import base64
import copy
import faulthandler
import json
import os
import random
import resource
import struct
import subprocess
import sys
import tempfile
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .harness import Result

TARGET_TRIANGLES_PER_S = 2e6
LOAD_TRIANGLES = 1_300_000
LOAD_FORMATS = ("obj", "glb", "ply", "stl")
LOAD_COLUMNS = [("format", "{}"), ("file_mb", "{:.1f}"), ("triangles", "{:,}"), ("seconds", "{:.3f}"),
                ("mtri_per_s", "{:.2f}"), ("meets", "{}"), ("peak_rss_mb", "{:.0f}"), ("load_rss_mb", "{:.0f}"),
                ("rss_per_file", "{:.1f}")]
# A fuzz case slower than this is a hang; peak memory past the start by more than this a runaway.
FUZZ_CASE_SECONDS = 10.0
FUZZ_RSS_GROWTH_MB = 512


# ---- writers: a mesh (positions (n, 3) float32, faces (m, 3) uint32) as each format's bytes


def grid(triangles: int) -> tuple[np.ndarray, np.ndarray]:
    """A wavy square grid of about `triangles` triangles (two a cell)."""
    n = max(2, round((triangles / 2) ** 0.5) + 1)
    u = np.linspace(-1.0, 1.0, n, dtype=np.float32)
    x, y = np.meshgrid(u, u)
    z = 0.1 * np.sin(6 * x) * np.cos(5 * y)
    positions = np.stack([x, y, z], -1).reshape(-1, 3).astype(np.float32)
    i = np.arange(n - 1)
    a = (i[:, None] * n + i[None, :]).reshape(-1).astype(np.uint32)
    faces = np.concatenate([np.stack([a, a + 1, a + n + 1], -1), np.stack([a, a + n + 1, a + n], -1)])
    return positions, faces.astype(np.uint32)


def obj_bytes(positions: np.ndarray, faces: np.ndarray, material: str | None = None) -> bytes:
    head = f"mtllib {material}.mtl\nusemtl {material}\n" if material else ""
    v = "".join(f"v {x:.6g} {y:.6g} {z:.6g}\n" for x, y, z in positions.tolist())
    f = "".join(f"f {a} {b} {c}\n" for a, b, c in (faces.astype(np.int64) + 1).tolist())
    return (head + v + f).encode()


def gltf_doc(positions: np.ndarray, faces: np.ndarray) -> tuple[dict, bytes]:
    """A glTF document of the mesh on a node under a parent, with a material, and its buffer."""
    pos, idx = positions.astype("<f4").tobytes(), faces.astype("<u4").tobytes()
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"children": [1], "translation": [0, 0, 0.5]}, {"mesh": 0, "scale": [1, 1, 1]}],
           "meshes": [{"name": "grid", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
           "materials": [{"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0, 0.5]}}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
                          "min": positions.min(0).tolist(), "max": positions.max(0).tolist()},
                         {"bufferView": 1, "componentType": 5125, "count": faces.size, "type": "SCALAR"}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
                           {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx)}],
           "buffers": [{"byteLength": len(pos) + len(idx)}]}
    return doc, pos + idx


def glb_pack(doc: dict, blob: bytes) -> bytes:
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    blob = blob + b"\0" * (-len(blob) % 4)
    chunks = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(blob), b"BIN\0") + blob
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def glb_bytes(positions: np.ndarray, faces: np.ndarray) -> bytes:
    return glb_pack(*gltf_doc(positions, faces))


def ply_bytes(positions: np.ndarray, faces: np.ndarray, binary: bool = True) -> bytes:
    head = (f"ply\nformat {'binary_little_endian' if binary else 'ascii'} 1.0\nelement vertex {len(positions)}\n"
            "property float x\nproperty float y\nproperty float z\n"
            f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n").encode()
    if not binary:
        v = "".join(f"{x:.6g} {y:.6g} {z:.6g}\n" for x, y, z in positions.tolist())
        return head + (v + "".join(f"3 {a} {b} {c}\n" for a, b, c in faces.tolist())).encode()
    rows = np.empty(len(faces), np.dtype([("n", "u1"), ("i", "<i4", (3,))]))
    rows["n"], rows["i"] = 3, faces
    return head + positions.astype("<f4").tobytes() + rows.tobytes()


def stl_bytes(positions: np.ndarray, faces: np.ndarray, binary: bool = True) -> bytes:
    tri = positions[faces]
    if not binary:
        facets = "".join("facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {x:.6g} {y:.6g} {z:.6g}\n" for x, y, z in t)
                         + "endloop\nendfacet\n" for t in tri.tolist())
        return f"solid grid\n{facets}endsolid grid\n".encode()
    rows = np.zeros(len(faces), np.dtype([("normal", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")]))
    rows["v"] = tri
    return b"oit bench".ljust(80, b"\0") + struct.pack("<I", len(faces)) + rows.tobytes()


def write_format(directory: Path, fmt: str, positions: np.ndarray, faces: np.ndarray) -> Path:
    """The mesh as `directory`/mesh.<fmt> (OBJ, GLB, binary PLY, binary STL)."""
    data = {"obj": obj_bytes, "glb": glb_bytes, "ply": ply_bytes, "stl": stl_bytes}[fmt](positions, faces)
    path = directory / f"mesh.{fmt}"
    path.write_bytes(data)
    return path


# ---- --load

# Peak resident memory from VmHWM, which starts afresh at exec (ru_maxrss of a child starts at
# its parent's peak, here the bench's own arrays).
_PROBE = """
import json, sys, time, warnings
import oit
def hwm():
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmHWM:"))
warnings.simplefilter("ignore")
base = hwm()
t = time.perf_counter()
scene = oit.Scene.from_file(sys.argv[1])
dt = time.perf_counter() - t
print(json.dumps({"seconds": dt, "triangles": scene.triangle_count, "base_kb": base, "peak_kb": hwm()}))
"""


def measure_load(path: Path) -> dict:
    """Loads `path` with Scene.from_file in a fresh interpreter: seconds, triangles, and peak
    resident memory (KiB) before and after (so the peak is this file's, not an earlier one's)."""
    done = subprocess.run([sys.executable, "-c", _PROBE, str(path)], capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        raise RuntimeError(f"loading {path} failed: {done.stderr.strip().splitlines()[-1] if done.stderr else done.returncode}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def load_speed(triangles: int = LOAD_TRIANGLES, formats: tuple[str, ...] = LOAD_FORMATS) -> Result:
    """One row a format: the file's size, the load's time, triangles a second and peak memory."""
    positions, faces = grid(triangles)
    rows = []
    with tempfile.TemporaryDirectory(prefix="oit-bench-load-") as tmp:
        for fmt in formats:
            path = write_format(Path(tmp), fmt, positions, faces)
            row: dict[str, Any] = {"format": fmt, "file_mb": path.stat().st_size / 2**20, "adapter": "none (CPU loader)",
                                   "status": "ok", "message": ""}
            try:
                m = measure_load(path)
            except (RuntimeError, subprocess.TimeoutExpired) as e:
                rows.append({**row, "triangles": len(faces), "status": "failed", "message": str(e)})
                continue
            rate = m["triangles"] / m["seconds"]
            peak, load = m["peak_kb"] / 1024, (m["peak_kb"] - m["base_kb"]) / 1024
            rows.append({**row, "triangles": m["triangles"], "seconds": m["seconds"], "mtri_per_s": rate / 1e6,
                         "meets": "yes" if rate >= TARGET_TRIANGLES_PER_S else "no", "peak_rss_mb": peak,
                         "load_rss_mb": load, "rss_per_file": load / row["file_mb"]})
            os.remove(path)
    notes = [f"{len(faces):,} triangles ({len(positions):,} vertices) a file, loaded by Scene.from_file in a fresh "
             f"interpreter; target {TARGET_TRIANGLES_PER_S / 1e6:.0f} M triangles/s; peak_rss_mb is the process's peak "
             "resident memory, load_rss_mb its growth during the load (after `import oit`), rss_per_file that over the "
             "file's size"]
    return Result(rows=rows, notes=notes)


# ---- --fuzz-load: seeds


def _small() -> tuple[np.ndarray, np.ndarray]:
    return grid(8)


def seed_files(directory: Path) -> list[Path]:
    """Small valid files of every format, each of its own kind: GLB; glTF with a data URI and
    with an external .bin and .png; OBJ with an MTL (and a texture); ASCII and binary PLY and STL."""
    from ..imageio import encode_png

    directory.mkdir(parents=True, exist_ok=True)
    positions, faces = _small()
    out = []

    def put(name: str, data: bytes) -> Path:
        p = directory / name
        p.write_bytes(data)
        out.append(p)
        return p

    put("seed.glb", glb_bytes(positions, faces))
    doc, blob = gltf_doc(positions, faces)
    inline = copy.deepcopy(doc)
    inline["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode()
    put("seed-inline.gltf", json.dumps(inline).encode())
    (directory / "seed.bin").write_bytes(blob)
    texels = np.full((2, 2, 4), 200, np.uint8)
    (directory / "seed.png").write_bytes(encode_png(texels))
    external = copy.deepcopy(doc)
    external["buffers"][0]["uri"] = "seed.bin"
    external["images"], external["textures"] = [{"uri": "seed.png"}], [{"source": 0, "sampler": 0}]
    external["samplers"] = [{"magFilter": 9729, "minFilter": 9987, "wrapS": 33648, "wrapT": 33071}]
    external["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    uvs = (positions[:, :2] * 0.5 + 0.5).astype("<f4").tobytes()
    external["bufferViews"].append({"buffer": 1, "byteLength": len(uvs)})
    external["buffers"].append({"byteLength": len(uvs), "uri": "data:application/octet-stream;base64,"
                                + base64.b64encode(uvs).decode()})
    external["accessors"].append({"bufferView": 2, "componentType": 5126, "count": len(positions), "type": "VEC2"})
    external["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = 2
    put("seed-external.gltf", json.dumps(external).encode())
    (directory / "seed.mtl").write_bytes(b"newmtl seed\nKd 1 0.5 0\nd 0.5\nmap_Kd seed.png\nnewmtl other\nTr 0.25\n")
    put("seed.obj", obj_bytes(positions, faces, "seed").replace(b"f ", b"vt 0.5 0.5\nf ", 1)
        + b"o other\nusemtl other\nf 1/1 2/1 3/1\nf -1 -2 -3 -4\nl 1 2 3\n")
    # The MTL is mutated on its own, read through this OBJ (`fuzz_load`).
    (directory / "seed-m.obj").write_bytes(b"mtllib fuzz-m.mtl\nusemtl seed\nvt 0 0\n" + obj_bytes(positions, faces)
                                           + b"usemtl other\nf 1/1 2/1 3/1\n")
    put("seed.mtl", (directory / "seed.mtl").read_bytes())
    put("seed-ascii.ply", ply_bytes(positions, faces, binary=False))
    put("seed.ply", ply_bytes(positions, faces))
    put("seed-ascii.stl", stl_bytes(positions, faces, binary=False))
    put("seed.stl", stl_bytes(positions, faces))
    return out


# ---- --fuzz-load: mutations

HUGE = [2**31 - 1, 2**31, 2**32 - 1, 2**32, 2**53, 10**12, -1, -(2**31), 0]
ODD_NUMBERS = ["1e40", "-1e40", "nan", "inf", "-0", "99999999999", "-99999999999", "0x10", "1.5", "", "+"]


def _truncate(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    cut = rng.randrange(len(data)) if data else 0
    return data[:cut], f"truncated at {cut}"


def _flip(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    b, where = bytearray(data), []
    for _ in range(rng.randint(1, 8)):
        if b:
            i = rng.randrange(len(b))
            b[i] ^= 1 << rng.randrange(8)
            where.append(i)
    return bytes(b), f"bits flipped at {where}"


def _huge_word(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    """A 32-bit word made huge or negative (counts, lengths and offsets of the binary formats)."""
    if len(data) < 4:
        return data, "unchanged"
    i = rng.randrange(0, len(data) - 3)
    v = rng.choice(HUGE) & 0xFFFFFFFF
    return data[:i] + struct.pack("<I", v) + data[i + 4:], f"word at {i} = {v}"


def _text_token(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    """In a text format: a number made huge, negative or not a number, a line deleted or repeated."""
    lines = data.split(b"\n")
    i = rng.randrange(len(lines))
    choice = rng.random()
    if choice < 0.2:
        return b"\n".join(lines[:i] + lines[i + 1:]), f"line {i} deleted"
    if choice < 0.3:
        return b"\n".join(lines[:i] + [lines[i]] * rng.randint(2, 50) + lines[i + 1:]), f"line {i} repeated"
    words = lines[i].split(b" ")
    j = rng.randrange(len(words))
    new = rng.choice([str(v) for v in HUGE] + ODD_NUMBERS).encode()
    words[j] = new
    lines[i] = b" ".join(words)
    return b"\n".join(lines), f"line {i} word {j} = {new.decode()!r}"


def _json_paths(node: Any, path: tuple = ()) -> Iterator[tuple]:
    yield path
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _json_paths(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _json_paths(v, (*path, i))


def _at(doc: Any, path: tuple) -> Any:
    for p in path:
        doc = doc[p]
    return doc


def _mutate_json(doc: dict, rng: random.Random) -> str:
    """One structural change to a glTF document, in place; says which."""
    paths = [p for p in _json_paths(doc) if p]
    choice = rng.random()
    if choice < 0.3:
        p = rng.choice(paths)
        parent = _at(doc, p[:-1])
        del parent[p[-1]]
        return f"deleted {p}"
    if choice < 0.6:
        p = rng.choice(paths)
        new = rng.choice([None, True, "x", 1.0, 1.5, -1, 2**40, [], {}, [0, 1], {"a": 1}, "data:,"])
        _at(doc, p[:-1])[p[-1]] = new
        return f"{p} = {new!r}"
    if choice < 0.75:
        # Huge counts, lengths and offsets.
        keys = ("count", "byteLength", "byteOffset", "byteStride", "componentType", "mesh", "bufferView", "buffer",
                "indices", "POSITION", "source", "index", "camera", "scene", "material")
        cands = [p for p in paths if p[-1] in keys] or paths
        p = rng.choice(cands)
        v = rng.choice(HUGE)
        _at(doc, p[:-1])[p[-1]] = v
        return f"{p} = {v}"
    nodes = doc.get("nodes")
    if not isinstance(nodes, list) or not nodes or not all(isinstance(n, dict) for n in nodes):
        return "unchanged"
    if choice < 0.85:
        i = rng.randrange(len(nodes))
        j = rng.randrange(len(nodes))
        nodes[i].setdefault("children", [])
        if isinstance(nodes[i]["children"], list):
            nodes[i]["children"].append(j)
        return f"nodes[{i}].children += [{j}] (a cycle or a second parent)"
    if choice < 0.92:
        # Many nodes chained: a deep (or, closed, cyclic) graph.
        n0, depth = len(nodes), rng.choice([100, 10_000])
        nodes.extend({"children": [n0 + k + 1]} for k in range(depth))
        nodes.append({"mesh": 0, "children": [n0] if rng.random() < 0.5 else []})
        doc.setdefault("scenes", [{"nodes": []}])
        if isinstance(doc["scenes"], list) and doc["scenes"] and isinstance(doc["scenes"][0], dict):
            doc["scenes"][0]["nodes"] = [n0]
        return f"a chain of {depth} nodes"
    # A file that is not there.
    for key in ("buffers", "images"):
        items = doc.get(key)
        if isinstance(items, list) and items and isinstance(items[0], dict):
            items[0]["uri"] = f"missing-{key}.bin"
            return f"{key}[0].uri missing"
    return "unchanged"


def _glb_parts(data: bytes) -> tuple[dict, bytes] | None:
    try:
        n = struct.unpack_from("<I", data, 12)[0]
        doc = json.loads(data[20:20 + n])
        m = struct.unpack_from("<I", data, 20 + n)[0]
        return doc, data[28 + n:28 + n + m]
    except (struct.error, ValueError):
        return None


def _json_parts(data: bytes) -> tuple[dict, bytes] | None:
    try:
        return json.loads(data), b""
    except ValueError:
        return None


def mutate(data: bytes, suffix: str, rng: random.Random) -> tuple[bytes, str]:
    """One random mutation of a file's bytes, fitting its format; says what it did."""
    choice = rng.random()
    if suffix in (".gltf", ".glb") and choice < 0.5:
        parts = _glb_parts(data) if suffix == ".glb" else _json_parts(data)
        if parts is not None and isinstance(parts[0], dict):
            doc, blob = parts
            what = "; ".join(_mutate_json(doc, rng) for _ in range(rng.choice([1, 1, 2, 3])))
            return (glb_pack(doc, blob) if suffix == ".glb" else json.dumps(doc).encode()), what
    text = suffix in (".obj", ".mtl", ".gltf") or (suffix == ".ply" and b"ascii" in data[:40]) or (
        suffix == ".stl" and data[:5] == b"solid")
    if suffix == ".ply" and choice < 0.3:
        head_end = data.find(b"end_header")
        head, rest = data[:head_end], data[head_end:]
        lines = head.split(b"\n")
        i = rng.randrange(len(lines))
        if lines[i].startswith(b"element"):
            lines[i] = b" ".join([*lines[i].split(b" ")[:2], str(rng.choice(HUGE)).encode()])
        elif lines[i].startswith(b"property list"):
            lines[i] = lines[i].replace(b"uchar", rng.choice([b"uint", b"int", b"char", b"float"]))
        else:
            return _text_token(data, rng)
        return b"\n".join(lines) + rest, f"header line {i} = {lines[i].decode(errors='replace')!r}"
    if text and choice < 0.75:
        return _text_token(data, rng)
    kind = rng.choice([_truncate, _flip, _flip, _huge_word])
    return kind(data, rng)


# ---- --fuzz-load: the run


@dataclass
class FuzzReport:
    cases: int = 0
    outcomes: dict[str, int] = field(default_factory=dict)
    failures: list[str] = field(default_factory=list)
    slowest: tuple[float, str] = (0.0, "")
    rss_growth_mb: float = 0.0
    seconds: float = 0.0

    def summary(self) -> str:
        kinds = ", ".join(f"{k} {v}" for k, v in sorted(self.outcomes.items()))
        return (f"{self.cases} mutated files in {self.seconds:.1f} s: {kinds}; slowest load {self.slowest[0] * 1e3:.0f} ms "
                f"({self.slowest[1]}); peak memory grew {self.rss_growth_mb:.0f} MB; {len(self.failures)} failures")


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def fuzz_load(seconds: float, seed: int = 0, out: str | os.PathLike | None = None, max_cases: int | None = None,
              load: Callable[[str], Any] | None = None) -> FuzzReport:
    """Mutates the seed files for `seconds` (or `max_cases` files) from `seed` and loads each;
    failures (with the bytes, in `out` when given) are in the report. A load that runs past
    FUZZ_CASE_SECONDS ends the process with every thread's traceback (a hang cannot be stopped
    from Python while the loader runs); `out`/fuzz-last-case.txt then says which case it was."""
    from .._api import Scene

    load = load or Scene.from_file
    rng = random.Random(seed)
    report = FuzzReport()
    start_rss, start = _peak_mb(), time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="oit-fuzz-") as tmp:
        seeds = [(p.suffix.lower(), p.name, p.read_bytes()) for p in seed_files(Path(tmp) / "seeds")]
        work = Path(tmp) / "seeds"
        while time.perf_counter() - start < seconds and (max_cases is None or report.cases < max_cases):
            suffix, name, data = seeds[report.cases % len(seeds)]
            case = f"case {report.cases} (seed {seed}): {name}"
            for _ in range(rng.choice([1, 1, 1, 2, 3])):
                data, what = mutate(data, suffix, rng)
                case += f"; {what}"
            path = work / f"fuzz{suffix}"
            path.write_bytes(data)
            if suffix == ".mtl":
                path.rename(work / "fuzz-m.mtl")
                path = work / "seed-m.obj"
            if out is not None:
                # What a hang (which ends the process) was loading.
                Path(out).mkdir(parents=True, exist_ok=True)
                (Path(out) / "fuzz-last-case.txt").write_text(case + "\n")
                (Path(out) / f"fuzz-last-case{suffix}").write_bytes(data)
            outcome = _load_one(str(path), load, case, report)
            report.outcomes[outcome] = report.outcomes.get(outcome, 0) + 1
            if outcome not in ("loaded", "ValueError", "OSError", "FileNotFoundError") and out is not None:
                keep = Path(out) / f"fuzz-failure-{report.cases}{suffix}"
                keep.parent.mkdir(parents=True, exist_ok=True)
                keep.write_bytes(data)
            report.cases += 1
    if out is not None:
        # No hang: the last case's files are no longer needed.
        for p in Path(out).glob("fuzz-last-case*"):
            p.unlink()
    report.rss_growth_mb = _peak_mb() - start_rss
    report.seconds = time.perf_counter() - start
    if report.rss_growth_mb > FUZZ_RSS_GROWTH_MB:
        report.failures.append(f"peak resident memory grew {report.rss_growth_mb:.0f} MB (bound {FUZZ_RSS_GROWTH_MB} MB)")
    return report


def _load_one(path: str, load: Callable[[str], Any], case: str, report: FuzzReport) -> str:
    faulthandler.dump_traceback_later(FUZZ_CASE_SECONDS, exit=True)
    t = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            load(path)
        outcome = "loaded"
    except FileNotFoundError:
        outcome = "FileNotFoundError"
    except (ValueError, OSError) as e:
        outcome = "ValueError" if isinstance(e, ValueError) else "OSError"
        if path not in str(e) and os.path.basename(path) not in str(e):
            report.failures.append(f"{case}: the message does not name the file: {e}")
    except (KeyboardInterrupt, SystemExit):
        raise
    except BaseException as e:  # PanicException is a BaseException: that is the point
        outcome = type(e).__name__
        report.failures.append(f"{case}: {type(e).__name__}: {e}")
    finally:
        faulthandler.cancel_dump_traceback_later()
    dt = time.perf_counter() - t
    if dt > report.slowest[0]:
        report.slowest = (dt, case)
    return outcome
