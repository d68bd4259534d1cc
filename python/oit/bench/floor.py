"""`python -m oit bench --peers-floor`: our floor and the methods over it against pygfx on the
same arrays, unlit and lit, as ratios to pygfx measured in the same run, held against a
baseline kept in the repository (docs/results.md, "Against pygfx").

The input never changes: `floor_scenes.npz` holds the positions, indices, colors, normals and
cameras of `oit.scenes.hair()`, `foliage()` and `glass()` as they were when the file was made
(`freeze`), so that a ratio means the same work from one build to the next however the scene
builders change. Unlit rows draw the vertex colors (pygfx `MeshBasicMaterial`); lit rows add the
normals, one directional light and an ambient term (pygfx `MeshPhongMaterial`). Times are wall
times of a render and its readback (ours: `Renderer.render`, whose frame holds the image;
pygfx: `render` + `snapshot`), medians of renders that alternate between the two libraries;
the ratio is the median of each render's ratio to the peer render taken right after it.
Milliseconds move by a third from run to run on a shared machine; ratios taken in one run move
far less, so the baseline keeps ratios, and a row whose ratio grew by more than GROWTH is
flagged."""

from __future__ import annotations

import json
import math
import statistics
import time
from pathlib import Path
from typing import Any

import numpy as np

from .. import peers
from .. import scenes as scene_lib
from .._api import Camera, Renderer
from .harness import Progress, Result, format_params

FLOOR_SCENES = Path(__file__).with_name("floor_scenes.npz")
BASELINE = Path(__file__).with_name("floor_baseline.json")
SCENES = ("hair", "glass", "foliage")
SHADINGS = ("unlit", "lit")
# (our method, its parameters, the pygfx alpha mode it is held against)
ROWS: tuple[tuple[str, dict[str, Any], str], ...] = (
    ("unsorted", {}, "blend"),
    ("wboit", {}, "weighted_blend"),
    ("hybrid64", {"k": 8}, "blend"),
    ("hybrid", {"k": 8}, "blend"),
    ("abuffer", {}, "blend"),
)
# The targets of the speed work: the largest ratio to pygfx each row should stay within (None:
# no target set). The floor and the weighted blend at most level with pygfx everywhere.
TARGETS: dict[tuple[str, str], float] = {
    **{(s, m): 1.0 for s in SCENES for m in ("unsorted", "wboit")},
    ("hair", "hybrid64"): 2.5, ("hair", "hybrid"): 3.5, ("hair", "abuffer"): 6.0,
    ("glass", "abuffer"): 4.0, ("foliage", "abuffer"): 4.0,
}
# A row is flagged when its ratio passes the baseline's by more than this fraction.
GROWTH = 0.15
# A row keeps pairing renders past `repeat` until ours have taken this long (at most
# MAX_PAIRS pairs): a short row's ratio moves with a few milliseconds of the machine's jitter
# (glass and foliage `unsorted`, about 20 ms a frame, moved by a fifth between runs of one
# build at 7 pairs), a long row's does not. Not in quick runs.
MIN_ROW_MS = 2000.0
MAX_PAIRS = 100
# The lit rows' surface and lights: the same on every mesh, ours and pygfx's.
LIT_SURFACE = {"specular": 0.3, "shininess": 32.0}
LIT_LIGHT = ((-0.3, -0.6, -1.0), (1.0, 1.0, 1.0), 1.0)
LIT_AMBIENT = (0.3, 0.3, 0.3)
QUICK_SIZE = 128

FLOOR_COLUMNS = [
    ("scene", "{}"), ("shading", "{}"), ("method", "{}"), ("params", "{}"), ("peer", "{}"), ("ours_ms", "{:.1f}"),
    ("peer_ms", "{:.1f}"), ("ratio", "{:.2f}"), ("target", "{:.1f}"), ("meets", "{}"), ("baseline", "{:.2f}"),
    ("growth", "{:+.0%}"), ("flag", "{}"), ("ns_per_fragment", "{:.1f}"), ("gpu_ms", "{:.1f}"), ("pairs", "{}"),
]


def vertex_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals (unit, float32; zero where a vertex has no area)."""
    p = positions.astype(np.float64)
    tri = p[indices]
    face = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n = np.zeros_like(p)
    for corner in range(3):
        np.add.at(n, indices[:, corner], face)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return (n / np.where(length > 0, length, 1.0)).astype(np.float32)


def freeze(path: Path = FLOOR_SCENES) -> None:
    """Writes the floor's input from the current scene builders. Run once: the file is the
    input from then on (rerunning it after a builder changed would change every baseline)."""
    arrays: dict[str, np.ndarray] = {}
    for name in SCENES:
        built = getattr(scene_lib, name)()
        arrays[f"{name}/view_proj"] = built.camera.view_proj
        arrays[f"{name}/opaque"] = np.array([m.opaque for m in built.meshes])
        for i, m in enumerate(built.meshes):
            key = f"{name}/{i}/"
            positions, indices = np.asarray(m.positions, np.float32), np.asarray(m.indices, np.uint32)
            normals = m.surface.get("normals")
            arrays[key + "positions"], arrays[key + "indices"] = positions, indices
            arrays[key + "colors"] = np.asarray(m.colors, np.float32)
            arrays[key + "normals"] = vertex_normals(positions, indices) if normals is None else np.asarray(normals, np.float32)
    np.savez_compressed(path, **arrays)


def floor_scene(name: str, lit: bool, size: tuple[int, int] = (512, 512)) -> scene_lib.BuiltScene:
    """Scene `name` of the floor's input, unlit or lit (normals, LIT_SURFACE, LIT_LIGHT, LIT_AMBIENT)."""
    if not FLOOR_SCENES.exists():
        raise FileNotFoundError(f"{FLOOR_SCENES} is missing: the floor's input ships with the package")
    with np.load(FLOOR_SCENES) as d:
        meshes = []
        for i, opaque in enumerate(d[f"{name}/opaque"]):
            key = f"{name}/{i}/"
            surface = {"normals": d[key + "normals"], **LIT_SURFACE} if lit else {}
            meshes.append(scene_lib.MeshArrays(d[key + "positions"], d[key + "indices"], d[key + "colors"], bool(opaque), surface))
        camera = Camera(d[f"{name}/view_proj"])
    lights, ambient = ([LIT_LIGHT], LIT_AMBIENT) if lit else ([], (0.0, 0.0, 0.0))
    return scene_lib.from_meshes(meshes, camera, size, {"floor": name}, lights, ambient)


def load_baseline(path: Path = BASELINE) -> dict[str, Any] | None:
    if not path.exists():
        return None
    with open(path) as f:
        return json.load(f)


def row_key(scene: str, shading: str, method: str) -> str:
    return f"{scene}/{shading}/{method}"


def _pygfx_version() -> str:
    import pygfx

    return pygfx.__version__


def peers_floor(scenes: tuple[str, ...] = SCENES, repeat: int = 5, quick: bool = False, show_progress: bool = True,
                baseline: dict[str, Any] | None = None) -> Result:
    """Every ROWS method on each scene, unlit and lit, against its pygfx mode: wall medians of
    `repeat` alternating renders after a warm-up of each, the ratio, its target and its growth
    over `baseline` (a `load_baseline()` dict, compared only when it was measured at this run's
    frame size: 512 x 512, or QUICK_SIZE with `quick`). Short rows take more pairs, until ours
    have taken MIN_ROW_MS."""
    missing = peers.pygfx_missing()
    if missing:
        raise RuntimeError(f"--peers-floor measures against pygfx: {missing}")
    size = (QUICK_SIZE, QUICK_SIZE) if quick else (512, 512)
    result = Result(rows=[])
    version = _pygfx_version()
    same_size = baseline is not None and baseline.get("size") == f"{size[0]}x{size[1]}"
    base = baseline.get("ratios", {}) if baseline is not None and same_size else {}
    if baseline is not None and same_size and baseline.get("pygfx") != version:
        result.notes.append(f"the baseline was measured against pygfx {baseline.get('pygfx')}, this run against {version}: "
                            "its growth column compares different peers")
    renderer = Renderer(*size)
    peer = peers.pygfx_renderer(*size)
    progress = Progress(len(scenes) * len(SHADINGS) * len(ROWS), enabled=show_progress)
    for name in scenes:
        for shading in SHADINGS:
            built = floor_scene(name, shading == "lit", size)
            # Fragments once per scene (the census), for the time per fragment.
            fragments = renderer.render(built.scene, built.camera, method="unsorted", census=True).stats["fragments"]
            for method, params, mode in ROWS:
                progress.show(f"{name} {shading} {method}")
                result.rows.append(_floor_row(renderer, peer, built, name, shading, method, params, mode, repeat, fragments,
                                              base, version, 0.0 if quick else MIN_ROW_MS))
                progress.step(f"{name} {shading} {method}")
    return result


def _floor_row(renderer: Renderer, peer: peers.PygfxRenderer, built: scene_lib.BuiltScene, name: str, shading: str,
               method: str, params: dict[str, Any], mode: str, repeat: int, fragments: int, base: dict[str, float],
               version: str, min_ms: float) -> dict:
    def ours() -> tuple[float, float | None]:
        t0 = time.perf_counter()
        frame = renderer.render(built.scene, built.camera, method=method, background=(1.0, 1.0, 1.0), **params)
        return (time.perf_counter() - t0) * 1e3, frame.stats.get("gpu_time_ms")

    ours()
    peer.render(built, mode)  # warm-up: pipelines, pools, uploads
    walls, gpus, peer_walls = [], [], []
    while len(walls) < max(1, repeat) or (sum(walls) < min_ms and len(walls) < MAX_PAIRS):
        wall, gpu = ours()
        walls.append(wall)
        if gpu is not None:
            gpus.append(gpu)
        peer_walls.append(peer.render(built, mode)[1])
    ours_ms, peer_ms = statistics.median(walls), statistics.median(peer_walls)
    # The median of each render's ratio to the peer's render right after it: the machine's
    # speed drifts over seconds, and a pair taken together shares the drift.
    ratio = statistics.median(w / p for w, p in zip(walls, peer_walls))
    key = row_key(name, shading, method)
    target = TARGETS.get((name, method))
    old = base.get(key)
    growth = ratio / old - 1.0 if old else math.nan
    return {
        "scene": name, "shading": shading, "method": method, "params": format_params(params), "peer": f"pygfx {version} {mode}",
        "ours_ms": ours_ms, "peer_ms": peer_ms, "ratio": ratio, "target": target if target is not None else math.nan,
        "meets": "" if target is None else ("yes" if ratio <= target else "no"), "baseline": old if old else math.nan,
        "growth": growth, "flag": "slower" if growth > GROWTH else "", "ns_per_fragment": ours_ms * 1e6 / max(fragments, 1),
        "gpu_ms": statistics.median(gpus) if gpus else math.nan, "fragments": fragments, "pairs": len(walls), "status": "ok",
        "message": "",
        "adapter": renderer.adapter_info["name"], "size": f"{renderer.width}x{renderer.height}",
    }


def write_baseline(result: Result, path: Path = BASELINE) -> None:
    """Keeps this run's ratios as the baseline later runs are held against."""
    ratios = {row_key(r["scene"], r["shading"], r["method"]): round(r["ratio"], 4) for r in result.rows}
    adapter = result.rows[0]["adapter"] if result.rows else ""
    size = result.rows[0]["size"] if result.rows else ""
    data = {"pygfx": _pygfx_version(), "adapter": adapter, "size": size, "ratios": ratios}
    with open(path, "w") as f:
        json.dump(data, f, indent=1, sort_keys=True)
        f.write("\n")
