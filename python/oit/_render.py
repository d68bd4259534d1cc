"""Rendering: `oit.Renderer` and the `oit.Frame` it returns with its `oit.Stats`, the CPU
reference, and what the core declares (the methods, their memory formula, shared constants)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, TypedDict

import numpy as np

from . import _oit
from ._camera import Camera
from ._checks import _I64_MAX, _U32_MAX, _int
from ._memory import available_memory
from ._scene import Scene
from .imageio import encode_png


class Stats(TypedDict, total=False):
    """`frame.stats`: what every frame reports; method-specific figures are under `extra`. The
    keys, their types and meanings are the core's (`oit._oit.stats_schema()`,
    crates/oit-core/src/stats/); tests/test_contract.py holds this class to them."""

    method: str  # the method's name
    params: dict[str, Any]  # every parameter, defaults filled in
    census: bool  # whether the fragment census ran (render(census=True), or a method that plans from it)
    fragments: int | None  # transparent fragments in front of the opaque depth (summed over samples); None without a census
    max_depth_complexity: int | None  # the most transparent fragments of a pixel; None without a census
    memory_bytes: int  # what the method allocated (oit.memory_bytes gives its formula)
    target_bytes: int  # the frame's targets and readbacks as allocated (tile-sized under a small budget)
    scene_bytes: int  # the scene's GPU buffers (one copy of each mesh, the instance table), apart from the frame's
    expanded_bytes: int  # the part of scene_bytes that strands and particles build on the GPU each frame, not uploaded
    texture_bytes: int  # the part of scene_bytes that textures take (each image once, with its mips, 4 bytes a texel)
    scene_bytes_by_primitive: dict[str, float]  # scene_bytes by kind: 'triangles' (and instances), 'strands', 'particles', 'gaussians'
    gpu_time_ms: float | None  # the passes' GPU time; None where the adapter has no timestamp queries
    pass_times_ms: dict[str, float]  # GPU time per pass; a pass run more than once adds up
    overflow_fragments: int  # fragments a bounded structure could not hold
    wall_time_ms: float  # the render's wall time, readback included
    antialias: int  # samples a pixel (1: no antialiasing)
    antialias_mode: str  # 'frames' or 'coverage'
    tiles: int  # screen tiles the frame was rendered in (1: untiled), summed over antialiasing samples
    geometry_chunks: int  # chunks the transparent geometry was uploaded in (1 unless it passes a binding)
    instances: int  # instances drawn, over every mesh (a mesh added once counts one)
    peak_memory_bytes: int  # memory_bytes + target_bytes: all the frame allocated at once, within memory_budget
    adapter: str  # the adapter's name
    extra: dict[str, float]  # method-specific figures, each declared with its merge rule (oit._oit.extra_merge_rules())
    error_bound_max: float  # the largest of frame.error_bound, where the method derives one


@dataclass
class Frame:
    """One rendered frame. `image`: (h, w, 4) float32, linear; RGB is the final color and A
    the coverage of the background. `depth_complexity`: transparent fragments per pixel, where
    the census ran (`stats["census"]`), else None.
    `error_bound`: (h, w, 3) float32, a bound of |image RGB - the exact composite| at every
    pixel and channel, for the methods that derive one (hybrid, hybrid64, ktab, auto);
    otherwise None, and `error_bound_reason` says why."""

    image: np.ndarray
    stats: Stats
    depth_complexity: np.ndarray | None = field(repr=False)
    error_bound: np.ndarray | None = field(default=None, repr=False)
    error_bound_reason: str = ""

    def _repr_png_(self) -> bytes:
        """The image as PNG (sRGB), so that a frame shows inline in Jupyter."""
        return encode_png(self.image[..., :3])


class Renderer:
    """Renders scenes at one size. `adapter` (or the OIT_ADAPTER variable) picks an adapter by
    a substring of its name; otherwise a hardware adapter is preferred over a software one.
    `memory_budget` (bytes) bounds everything a frame allocates (the method's storage, the
    frame's targets and readbacks: `stats["peak_memory_bytes"]`): where that would pass the
    budget, or the storage a binding, the frame is rendered in screen tiles
    (`frame.stats["tiles"]`), with the same image, or within float32 rounding of it where the
    targets themselves are tiled (docs/methods.md, "Tiles")."""

    def __init__(self, width: int, height: int, adapter: str | None = None, max_binding_bytes: int | None = None,
                 memory_budget: int | None = None) -> None:
        for name, v in (("width", width), ("height", height)):
            if _int(v, name) <= 0:
                raise ValueError(f"{name} must be positive, got {v}")
        if adapter is not None and not isinstance(adapter, str):
            raise TypeError(f"adapter must be a string (part of an adapter's name) or None, "
                            f"got {type(adapter).__name__}")
        # Byte counts as the native layer takes them (i64; the core caps a binding limit at the
        # adapter's and checks both).
        if max_binding_bytes is not None:
            max_binding_bytes = max(min(_int(max_binding_bytes, "max_binding_bytes", "an int (bytes) or None"), _I64_MAX), -_I64_MAX)
        if memory_budget is not None:
            memory_budget = max(min(_int(memory_budget, "memory_budget", "an int (bytes) or None"), _I64_MAX), -_I64_MAX)
        self.width, self.height = int(width), int(height)
        # Sizes past u32 are past every adapter's largest texture: let the core say which
        # size is the largest, about the size asked for.
        w, h = min(self.width, _U32_MAX), min(self.height, _U32_MAX)
        try:
            self._native = _oit.Renderer(w, h, adapter, max_binding_bytes, memory_budget)
        except MemoryError as e:
            if (w, h) == (self.width, self.height):
                raise
            raise MemoryError(str(e).replace(f"{w} x {h}", f"{self.width} x {self.height}", 1)) from None
        if (w, h) != (self.width, self.height):  # no adapter has 2^32-pixel textures
            raise MemoryError(f"{self.width} x {self.height} is past the adapter's largest texture")

    @property
    def adapter_info(self) -> dict:
        return self._native.adapter_info

    @property
    def pipelines_built(self) -> int:
        """Pipelines this adapter's device has compiled so far (renderers on one adapter share
        them): a frame whose configuration was rendered before compiles none."""
        return self._native.pipelines_built

    def render(self, scene: Scene, camera: Camera, method: str = "abuffer",
               background: Sequence[float] = (1.0, 1.0, 1.0), antialias: int = 1, antialias_mode: str = "frames",
               shading_cost: int = 0, census: bool = False, **params: Any) -> Frame:
        """Renders `scene` with `method` (see `oit.methods()`); parameters go as keywords.
        `antialias` S in (1, 2, 4, 8, 16): S samples a pixel on the standard pattern. With
        antialias_mode "frames" each sample is a frame of its own with the method's buffers
        reused, averaged (any method; memory as at one sample, time about S times); with
        "coverage" (abuffer, S = 4) the transparent geometry is rasterized once, multisampled,
        and each stored fragment keeps its sample mask (docs/methods.md, "Antialiasing").
        `shading_cost` N: every shaded fragment evaluates N extra lights whose result is
        discarded, so the image is unchanged and shading costs more (docs/shading.md).
        `census=True` counts every pixel's transparent fragments (`stats["fragments"]`,
        `stats["max_depth_complexity"]`, `frame.depth_complexity`) with one more geometry pass;
        methods that plan their storage from the counts (the A-buffers, peeling, adaptive_lists, mlab_lists,
        auto) and hybrid with tail="compact" (its tail count) always do, the others by default do not, and
        report None there."""
        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be an oit.Scene, got {type(scene).__name__}")
        if not isinstance(camera, Camera):
            raise TypeError(f"camera must be an oit.Camera, got {type(camera).__name__}")
        if not isinstance(method, str):
            raise TypeError(f"method must be a string, got {type(method).__name__}")
        bg = _background(background)
        if not isinstance(antialias_mode, str):
            raise TypeError(f"antialias_mode must be 'frames' or 'coverage', got {antialias_mode!r}")
        cost = _int(shading_cost, "shading_cost", "an int (extra light evaluations per fragment)")
        if not 0 <= cost <= 65536:
            raise ValueError(f"shading_cost must be in [0, 65536], got {cost}")
        if not isinstance(census, bool):
            raise TypeError(f"census must be True or False, got {census!r}")
        options = {"background": bg, "antialias": _antialias(antialias), "antialias_mode": antialias_mode,
                   "shading_cost": cost, "census": census}
        image, dc, stats, bound = self._native.render(scene._native, camera.view_proj, method, params, options)
        if bound is not None:
            return Frame(image=image, stats=stats, depth_complexity=dc, error_bound=np.repeat(bound[..., None], 3, axis=2))
        exact = any(m["name"] == method and m["error_bound"] == "exact" for m in methods())
        reason = ("exact method: the error is float32 compositing, at most about (n + 2) * 2**-23 for n layers"
                  if exact else f"no per-pixel bound is derived for '{method}' (docs/methods.md)")
        return Frame(image=image, stats=stats, depth_complexity=dc, error_bound_reason=reason)


ANTIALIAS = tuple(_oit.constants()["ANTIALIAS_SAMPLES"])  # the core's standard patterns


def _antialias(antialias: Any) -> int:
    samples = _int(antialias, "antialias", f"an int, one of {ANTIALIAS} samples a pixel")
    if samples not in ANTIALIAS:
        raise ValueError(f"antialias must be one of {ANTIALIAS} samples a pixel (the standard patterns), got {samples}")
    return samples


def _background(background: Sequence[float]) -> tuple[float, float, float]:
    try:
        bg = np.asarray(background, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"background must be three linear RGB values in [0, 1], got {background!r}") from None
    if bg.shape != (3,) or not np.isfinite(bg).all() or bg.min() < 0 or bg.max() > 1:
        raise ValueError(f"background must be three linear RGB values in [0, 1], got {background!r}")
    return (float(bg[0]), float(bg[1]), float(bg[2]))


def methods() -> list[dict]:
    """Every method and what the core knows of it: name, summary, `exact`, `bounded_memory`,
    `passes`, `params` (defaults and ranges), the adapter `features` it needs, `order` (how
    its image depends on submission order: "bitwise", "bitwise_except_ties", "rounding" or
    "submission") and `order_independent`, `antialias_modes`, `memory` (its "kind" -- "frame",
    "scene" or "slots" -- and "formula") and `error_bound` ("exact", "per_pixel" or "none")."""
    return _oit.methods()


def memory_bytes(method: str, width: int, height: int, slots: int | None = None, **params: Any) -> int | None:
    """GPU bytes `method` allocates for a width x height frame with `params`, from the core's
    formula (what `frame.stats["memory_bytes"]` reports); None when that grows with the scene
    (the storing methods). `auto` chooses its slots per frame: pass `slots` =
    frame.stats["extra"]["auto_slots"] for the bytes of the hybrid it rendered."""
    if not isinstance(method, str):
        raise TypeError(f"method must be a string, got {type(method).__name__}")
    w, h = _int(width, "width"), _int(height, "height")
    if slots is not None:
        slots = _int(slots, "slots")
    return _oit.memory_bytes(method, w, h, params, slots)


def constants() -> dict:
    """The numbers the core, its shaders and these models share (crates/oit-core/src/consts.rs):
    accumulator words, fixed-point scales, the 8-bit alpha's bias and error, the depth maximum
    of packed keys, rounding terms, the antialiasing sample counts."""
    return dict(_CONSTANTS)


_CONSTANTS = _oit.constants()


def reference(scene: Scene, camera: Camera, width: int, height: int, background: Sequence[float] = (1.0, 1.0, 1.0),
              return_mask: bool = False, antialias: int = 1):
    """The CPU float64 reference image (h, w, 4). With return_mask=True, also a boolean
    (h, w) mask of ambiguous pixels: a pixel center on a triangle edge or on two nearly
    equal depths, where a rasterizer may legitimately differ (docs/methods.md). With
    `antialias` S, the mean over the S standard sample positions of each pixel, as
    Renderer.render(..., antialias=S) renders it (ambiguous where any sample is)."""
    if not isinstance(scene, Scene) or not isinstance(camera, Camera):
        raise TypeError("reference(scene, camera, width, height): scene must be an oit.Scene and camera an oit.Camera")
    w, h = _int(width, "width"), _int(height, "height")
    if not (1 <= w <= 65536 and 1 <= h <= 65536):
        raise ValueError(f"width and height must be in [1, 65536], got {w} x {h}")
    # float64 RGBA, the ambiguity mask and the depth complexity: a failed allocation in the
    # core would abort the process, so refuse what this machine cannot hold.
    need = w * h * (4 * 8 + 1 + 4)
    avail = available_memory()
    if w * h > _U32_MAX or (avail is not None and need > avail):
        raise MemoryError(f"reference at {w} x {h} needs {need / 2**30:.1f} GiB"
                          + (f" but {avail / 2**30:.1f} GiB are available" if avail is not None else "")
                          + ": use a smaller size (it costs 37 bytes a pixel)")
    samples = _antialias(antialias)
    image, ambiguous, _ = _oit.reference(scene._native, camera.view_proj, w, h, _background(background), samples)
    return (image, ambiguous) if return_mask else image
