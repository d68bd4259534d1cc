"""The built-in demo: three lit, transparent shapes generated here (nothing to download, so
every clone draws the same picture) -- a folded lump behind, a sphere in the middle, a ring in
front, overlapping on screen and submitted nearest first -- rendered with hybrid beside its
exact answer (abuffer) and the blends (sorted, unsorted), over their errors. Submitted nearest
first, `unsorted` blends every overlap in the wrong order; `sorted` puts the meshes back to front
and is wrong only where a mesh covers itself (the lump's folds, the ring seen through its hole).
Method names and errors are drawn in the picture (with Pillow, which matplotlib brings; without
it the tiles are left unlabelled).

Top row: the images. Bottom row: under abuffer, its deviation from the CPU float64 reference
(ambiguous pixels left black); under the others, |method - abuffer|, the largest over RGB. All
heatmaps share one scale (black 0, white the largest error).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import geometry
from ._api import Camera, Frame, Renderer, Scene, reference
from .imageio import heatmap, label, mosaic

METHODS = ("abuffer", "hybrid", "sorted", "unsorted")
BACKGROUND = (1.0, 1.0, 1.0)


def demo_scene(detail: int = 32) -> tuple[Scene, Camera, str]:
    """The demo scene, its camera (square aspect) and what it shows. `detail`: the ring's and
    sphere's segments around (the lump has twice as many)."""
    lump = geometry.blob((0.3, -0.05, -0.55), (0.5, 0.6, 0.42), bumps=0.28, rings=detail, segments=2 * detail, seed=3)
    sphere = geometry.uv_sphere((-0.22, 0.28, -0.05), 0.36, rings=detail, segments=2 * detail)
    ring = geometry.torus((-0.05, -0.12, 0.42), 0.38, 0.11, 2 * detail, detail // 2, axis=(0.35, 1.0, 0.5))
    # (mesh, straight linear RGBA), nearest first: the worst order for blending in submission order.
    shapes = ((ring, (0.1, 0.35, 0.95, 0.55)), (sphere, (0.15, 0.8, 0.35, 0.45)), (lump, (0.95, 0.45, 0.08, 0.6)))
    scene = Scene()
    for (p, idx), rgba in shapes:
        scene.add_mesh(p, idx, rgba, normals=geometry.vertex_normals(p, idx), shading="smooth", specular=0.4,
                       shininess=48.0)
    scene.add_light((-0.5, -0.8, -0.6), (1.0, 0.96, 0.9), 0.8)
    scene.add_light((0.9, -0.1, -0.2), (0.6, 0.7, 1.0), 0.3)
    scene.ambient = (0.3, 0.3, 0.3)
    camera = Camera.look_at(eye=(0.25, 0.45, 2.6), target=(0.0, 0.0, -0.05), fov_y=40.0, near=1.0, far=4.5)
    triangles = sum(len(idx) for (_, idx), _ in shapes)
    return scene, camera, f"a ring, a sphere and a folded lump, lit, submitted nearest first ({triangles} triangles)"


def reference_bound(ref: np.ndarray) -> np.ndarray:
    """docs/shading.md's bound of |exact method - reference| per pixel: float32 shading (4e-6)
    plus the shading's change over 1e-3 pixel (10^-3 of the largest step to a neighbour)."""
    c = ref[..., :3]
    step = np.zeros(c.shape[:2])
    for axis in (0, 1):
        d = np.abs(np.diff(c, axis=axis)).max(-1)
        pad = [(0, 0), (0, 0)]
        pad[axis] = (1, 0)
        step = np.maximum(step, np.pad(d, pad))
        pad[axis] = (0, 1)
        step = np.maximum(step, np.pad(d, pad))
    return 4e-6 + 1e-3 * step


@dataclass
class DemoResult:
    frames: dict[str, Frame]
    # Per method: |method - abuffer| (for abuffer: |abuffer - reference| off ambiguous pixels).
    errors: dict[str, np.ndarray]
    reference_max_error: float
    # Whether abuffer is within reference_bound of the reference on every unambiguous pixel.
    reference_within_bound: bool
    ambiguous_fraction: float
    # The error shown white in the heatmaps.
    vmax: float
    mosaic: np.ndarray
    subject: str = ""


def run(size: int = 384, adapter: str | None = None) -> DemoResult:
    """Renders the demo at `size` x `size` and compares every method with abuffer."""
    scene, camera, subject = demo_scene()
    renderer = Renderer(size, size, adapter=adapter)
    frames = {m: renderer.render(scene, camera, method=m, background=BACKGROUND, census=True) for m in METHODS}
    exact = frames["abuffer"].image[..., :3].astype(np.float64)
    ref, ambiguous = reference(scene, camera, size, size, background=BACKGROUND, return_mask=True)
    ref_diff = np.abs(exact - ref[..., :3]).max(axis=-1)
    ref_error = np.where(ambiguous, 0.0, ref_diff)
    within = bool(np.all((ref_diff <= reference_bound(ref)) | ambiguous))
    errors = {"abuffer": ref_error}
    for m in METHODS[1:]:
        errors[m] = np.abs(frames[m].image[..., :3] - exact).max(axis=-1)
    vmax = max(max(float(e.max()) for e in errors.values()), 1e-6)
    scale = max(1, round(size / 160))
    top = [label(frames[m].image[..., :3], m + (" (exact)" if m == "abuffer" else ""), scale) for m in METHODS]
    bottom = [label(heatmap(errors["abuffer"], vmax), f"vs reference: max {float(ref_error.max()):.1e}", scale)]
    bottom += [label(heatmap(errors[m], vmax), f"max {float(errors[m].max()):.3f} mean {float(errors[m].mean()):.4f}", scale)
               for m in METHODS[1:]]
    return DemoResult(
        frames=frames,
        errors=errors,
        reference_max_error=float(ref_error.max()),
        reference_within_bound=within,
        ambiguous_fraction=float(ambiguous.mean()),
        vmax=vmax,
        mosaic=mosaic([top, bottom], gap=max(2, size // 96), fill=(0.25, 0.25, 0.25)),
        subject=subject,
    )


def legend(result: DemoResult) -> str:
    """What the picture shows, as text: errors per method and abuffer against the reference."""
    lines = [
        f"scene: {result.subject}",
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
    within = "within" if result.reference_within_bound else "OUTSIDE"
    lines.append(
        f"abuffer vs CPU float64 reference: max |error| {result.reference_max_error:.2e} on non-ambiguous pixels, "
        f"{within} docs/shading.md's bound ({100 * result.ambiguous_fraction:.1f}% of pixels are ambiguous: edges, "
        "depth ties and grazing normals)"
    )
    return "\n".join(lines)
