"""Frame sequences: N views around a scene rendered with one method, written as a GIF
(Pillow) or an MP4 (imageio with its ffmpeg plugin, the `video` extra), with the sequence's
temporal error against the exact frames (oit.bench.temporal.frame_changes: how much of its
frame-to-frame change is not the true change)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._api import Camera, Renderer, Scene
from .bench.harness import image_errors
from .bench.temporal import frame_changes
from .imageio import to_srgb8

ANIMATIONS = (".gif", ".mp4")


@dataclass
class Orbit:
    """The method's frames and the exact (abuffer) ones, and `temporal`: frame_changes'
    change, flicker and max_flicker, with the mean and largest error of any frame."""

    images: list[np.ndarray]
    exact: list[np.ndarray]
    temporal: dict[str, float]


def render_sequence(renderer: Renderer, scene: Scene, cameras: Sequence[Camera], method: str = "abuffer",
                    background: Sequence[float] = (1.0, 1.0, 1.0), **params: Any) -> Orbit:
    """Renders every camera with `method` and with abuffer, and compares the two sequences."""
    exact_frames = [renderer.render(scene, c, "abuffer", background=background) for c in cameras]
    exact = [f.image for f in exact_frames]
    covered = [f.depth_complexity > 0 for f in exact_frames]
    if method == "abuffer" and not params:
        images = exact
    else:
        images = [renderer.render(scene, c, method, background=background, **params).image for c in cameras]
    errors = [image_errors(im, ex, cov, flip=False) for im, ex, cov in zip(images, exact, covered)]
    temporal = frame_changes(images, exact, covered) if len(images) > 1 else {}
    temporal.update(mean_err=float(np.mean([e["mean_err"] for e in errors])), max_err=max(e["max_err"] for e in errors))
    return Orbit(images, exact, temporal)


def check_animation_path(path: str) -> str:
    """The extension of an animation file name, refused with what to do unless .gif or .mp4."""
    ext = os.path.splitext(path)[1].lower()
    if ext not in ANIMATIONS:
        raise ValueError(f"an orbit is written as .gif or .mp4, got {path!r}: name the output out.gif or out.mp4")
    return ext


def write_animation(path: str, images: Sequence[np.ndarray], fps: float = 12.0) -> None:
    """Writes linear RGB(A) frames as an sRGB GIF (Pillow) or MP4 (imageio + imageio-ffmpeg)."""
    ext = check_animation_path(path)
    frames = [to_srgb8(np.ascontiguousarray(im[..., :3])) for im in images]
    if ext == ".gif":
        try:
            from PIL import Image
        except ImportError:
            raise RuntimeError("writing a GIF needs Pillow: pip install pillow (or 'oit[video]')") from None
        first, *rest = [Image.fromarray(f) for f in frames]
        first.save(path, save_all=True, append_images=rest, duration=round(1000 / fps), loop=0)
        return
    try:
        import imageio.v3 as iio
        import imageio_ffmpeg  # noqa: F401
    except ImportError:
        raise RuntimeError("writing an MP4 needs imageio and imageio-ffmpeg: pip install 'oit[video]' "
                           "(or pip install imageio imageio-ffmpeg), or write a .gif") from None
    # H.264 wants even sizes: pad by repeating the last row and column.
    h, w = frames[0].shape[:2]
    frames = [np.pad(f, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge") for f in frames]
    iio.imwrite(path, np.stack(frames), fps=fps, codec="libx264", macro_block_size=1)
