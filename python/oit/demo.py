"""The built-in demo: three interpenetrating transparent spheres around an opaque box,
rendered with abuffer, sorted and unsorted, beside their errors. Needs no files.

Top row: the three images. Bottom row: under abuffer, its deviation from the CPU
reference (ambiguous pixels left black); under the others, |method - abuffer|, the
largest over RGB. All heatmaps share one scale (black 0, white the largest error).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import geometry
from ._api import Camera, Frame, Renderer, Scene, reference
from .imageio import heatmap, mosaic

METHODS = ("abuffer", "sorted", "unsorted")
BACKGROUND = (1.0, 1.0, 1.0)
# (center, straight linear RGBA), submitted nearest first so that `unsorted` and `sorted`
# differ; alphas span 0.35 to 0.6.
SPHERES = (
    ((0.0, -0.40, 0.20), (0.05, 0.20, 0.95, 0.60)),
    ((-0.45, 0.25, 0.0), (0.90, 0.10, 0.05, 0.45)),
    ((0.45, 0.25, -0.15), (0.05, 0.70, 0.15, 0.35)),
)
SPHERE_RADIUS = 0.7


def demo_scene(detail: int = 24) -> tuple[Scene, Camera]:
    """The demo scene and its camera (square aspect). `detail` is the sphere's ring count."""
    scene = Scene()
    for center, rgba in SPHERES:
        positions, indices = geometry.uv_sphere(center, SPHERE_RADIUS, rings=detail, segments=2 * detail)
        # A vertical gradient so that the layers inside one another stay distinguishable.
        shade = 0.75 + 0.25 * (positions[:, 1:2] - center[1]) / SPHERE_RADIUS
        colors = np.empty((len(positions), 4), dtype=np.float32)
        colors[:, :3] = np.clip(np.asarray(rgba[:3]) * shade, 0.0, 1.0)
        colors[:, 3] = rgba[3]
        scene.add_mesh(positions, indices, colors)
    positions, indices = geometry.box((0.55, -0.35, 0.25), (0.6, 0.6, 0.6))
    scene.add_mesh(positions, indices, (0.85, 0.75, 0.25, 1.0), opaque=True)
    camera = Camera.look_at(eye=(0.8, 1.0, 3.8), target=(0.0, 0.0, 0.0), fov_y=40.0, near=1.5, far=7.0)
    return scene, camera


@dataclass
class DemoResult:
    frames: dict[str, Frame]
    # Per method: |method - abuffer| (for abuffer: |abuffer - reference| off ambiguous pixels).
    errors: dict[str, np.ndarray]
    reference_max_error: float
    ambiguous_fraction: float
    # The error shown white in the heatmaps.
    vmax: float
    mosaic: np.ndarray


def run(size: int = 384, adapter: str | None = None) -> DemoResult:
    """Renders the demo at `size` x `size` and compares every method with abuffer."""
    scene, camera = demo_scene()
    renderer = Renderer(size, size, adapter=adapter)
    frames = {m: renderer.render(scene, camera, method=m, background=BACKGROUND) for m in METHODS}
    exact = frames["abuffer"].image[..., :3].astype(np.float64)
    ref, ambiguous = reference(scene, camera, size, size, background=BACKGROUND, return_mask=True)
    ref_error = np.where(ambiguous, 0.0, np.abs(exact - ref[..., :3]).max(axis=-1))
    errors = {"abuffer": ref_error}
    for m in METHODS[1:]:
        errors[m] = np.abs(frames[m].image[..., :3] - exact).max(axis=-1)
    vmax = max(max(float(e.max()) for e in errors.values()), 1e-6)
    rows = [[frames[m].image[..., :3] for m in METHODS], [heatmap(errors[m], vmax) for m in METHODS]]
    return DemoResult(
        frames=frames,
        errors=errors,
        reference_max_error=float(ref_error.max()),
        ambiguous_fraction=float(ambiguous.mean()),
        vmax=vmax,
        mosaic=mosaic(rows, gap=max(2, size // 96), fill=(0.25, 0.25, 0.25)),
    )


def legend(result: DemoResult) -> str:
    """What the picture shows, as text: errors per method and abuffer against the reference."""
    lines = [
        "top, left to right: " + ", ".join(METHODS),
        "bottom: |abuffer - reference|, " + ", ".join(f"|{m} - abuffer|" for m in METHODS[1:])
        + f" (largest over RGB), black 0 -> white {result.vmax:.3g}",
        f"{'method':<10} {'mean |m - abuffer|':>19} {'max':>8} {'fragments':>10} {'gpu ms':>8}",
    ]
    for m in METHODS:
        f = result.frames[m]
        gpu = f.stats.get("gpu_time_ms")
        gpu_text = f"{gpu:8.2f}" if gpu is not None else f"{'n/a':>8}"
        if m == "abuffer":
            errors = f"{'(the exact image)':>19} {'':>8}"
        else:
            errors = f"{float(result.errors[m].mean()):19.5f} {float(result.errors[m].max()):8.5f}"
        lines.append(f"{m:<10} {errors} {f.stats['fragments']:10d} {gpu_text}")
    lines.append(
        f"abuffer vs CPU float64 reference: max |error| {result.reference_max_error:.2e} on non-ambiguous pixels "
        f"({100 * result.ambiguous_fraction:.1f}% of pixels are ambiguous: edges and depth ties)"
    )
    return "\n".join(lines)
