"""Writing images without extra dependencies: sRGB encoding, an 8-bit PNG writer
(zlib + struct), a heatmap colormap for error images, and a mosaic of equal tiles.

Renders are linear light; everything here that takes floats treats RGB as linear and
alpha as coverage (never sRGB-encoded), so `write_png(path, frame.image)` is right.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Sequence
from os import PathLike

import numpy as np

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def linear_to_srgb(linear: np.ndarray) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1) on values clipped to [0, 1]; NaN becomes 0."""
    c = np.clip(np.nan_to_num(np.asarray(linear, dtype=np.float64), nan=0.0), 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


def srgb_to_linear(srgb: np.ndarray) -> np.ndarray:
    """Inverse of `linear_to_srgb` on values clipped to [0, 1]."""
    c = np.clip(np.asarray(srgb, dtype=np.float64), 0.0, 1.0)
    return np.where(c <= 0.04045, c / 12.92, np.power((c + 0.055) / 1.055, 2.4))


def to_srgb8(linear: np.ndarray) -> np.ndarray:
    """(h, w, 3) or (h, w, 4) linear floats to uint8: RGB sRGB-encoded, alpha scaled as is."""
    a = np.asarray(linear)
    if a.ndim != 3 or a.shape[2] not in (3, 4):
        raise ValueError(f"expected an (h, w, 3) or (h, w, 4) image, got shape {a.shape}")
    out = np.empty(a.shape, dtype=np.uint8)
    out[..., :3] = np.rint(linear_to_srgb(a[..., :3]) * 255.0)
    if a.shape[2] == 4:
        alpha = np.clip(np.nan_to_num(a[..., 3].astype(np.float64), nan=0.0), 0.0, 1.0)
        out[..., 3] = np.rint(alpha * 255.0)
    return out


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def encode_png(image: np.ndarray) -> bytes:
    """PNG bytes of an (h, w, 3) or (h, w, 4) image: uint8 is written as is, floats are
    treated as linear and go through `to_srgb8`."""
    a = np.asarray(image)
    if a.ndim != 3 or a.shape[2] not in (3, 4):
        raise ValueError(f"expected an (h, w, 3) or (h, w, 4) image, got shape {a.shape}")
    h, w, channels = a.shape
    if h == 0 or w == 0:
        raise ValueError(f"cannot write an empty image ({h} x {w})")
    if a.dtype != np.uint8:
        if not np.issubdtype(a.dtype, np.floating):
            raise TypeError(f"expected uint8 (already encoded) or float (linear) pixels, got dtype {a.dtype}")
        a = to_srgb8(a)
    color_type = 2 if channels == 3 else 6  # truecolor, truecolor with alpha
    header = struct.pack(">IIBBBBB", w, h, 8, color_type, 0, 0, 0)
    # Filter type 0 (none) at the start of every scanline.
    rows = np.concatenate([np.zeros((h, 1), dtype=np.uint8), np.ascontiguousarray(a).reshape(h, w * channels)], axis=1)
    return PNG_SIGNATURE + _chunk(b"IHDR", header) + _chunk(b"IDAT", zlib.compress(rows.tobytes(), 6)) + _chunk(b"IEND", b"")


def write_png(path: str | PathLike, image: np.ndarray) -> None:
    """Writes `image` (see `encode_png`) to `path`."""
    data = encode_png(image)
    with open(path, "wb") as f:
        f.write(data)


def heatmap(values: np.ndarray, vmax: float) -> np.ndarray:
    """(h, w) values to (h, w, 3) linear RGB on a black -> red -> yellow -> white ramp,
    0 black and `vmax` (or more) white. The ramp is even in display (sRGB) values, and
    the result is linear so that it goes through `write_png` like a render."""
    if not np.isfinite(vmax) or vmax <= 0:
        raise ValueError(f"vmax must be positive and finite, got {vmax}")
    t = np.clip(np.nan_to_num(np.asarray(values, dtype=np.float64), nan=0.0) / vmax, 0.0, 1.0)
    display = np.stack([np.clip(3.0 * t - k, 0.0, 1.0) for k in range(3)], axis=-1)
    return srgb_to_linear(display)


def mosaic(rows: Sequence[Sequence[np.ndarray]], gap: int = 4, fill: Sequence[float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Tiles of equal shape (h, w, c) in a grid with `gap` pixels of `fill` between them."""
    tiles = [np.asarray(t, dtype=np.float64) for row in rows for t in row]
    if not tiles:
        raise ValueError("mosaic needs at least one tile")
    shape = tiles[0].shape
    if any(t.shape != shape for t in tiles) or len(shape) != 3:
        raise ValueError(f"mosaic tiles must share one (h, w, c) shape, got {sorted({t.shape for t in tiles})}")
    h, w, c = shape
    n_cols = max(len(row) for row in rows)
    out = np.empty((len(rows) * h + (len(rows) - 1) * gap, n_cols * w + (n_cols - 1) * gap, c))
    out[...] = np.resize(np.asarray(fill, dtype=np.float64), c)
    for i, row in enumerate(rows):
        for j, tile in enumerate(row):
            out[i * (h + gap):i * (h + gap) + h, j * (w + gap):j * (w + gap) + w] = tile
    return out


def label(image: np.ndarray, text: str, scale: int = 1) -> np.ndarray:
    """`image` (h, w, 3) linear RGB with `text` written in its top-left corner, white on a dark
    outline so that it reads on any tile. Uses Pillow's built-in font; without Pillow the
    image is returned as it is."""
    try:
        from PIL import Image, ImageDraw, ImageFont
    except ImportError:
        return image
    h, w = image.shape[:2]
    try:
        font = ImageFont.load_default(size=10 * scale)
    except TypeError:  # Pillow < 10.1: one bitmap size
        font = ImageFont.load_default()
    mask = Image.new("L", (w, h), 0)
    outline = Image.new("L", (w, h), 0)
    at = (3 * scale, 2 * scale)
    ImageDraw.Draw(mask).text(at, text, fill=255, font=font)
    ImageDraw.Draw(outline).text(at, text, fill=255, font=font, stroke_width=max(1, scale), stroke_fill=255)
    m = np.asarray(mask, dtype=np.float64)[..., None] / 255.0
    o = np.asarray(outline, dtype=np.float64)[..., None] / 255.0
    out = np.asarray(image, dtype=np.float64) * (1.0 - o) + 0.02 * o
    return out * (1.0 - m) + 1.0 * m
