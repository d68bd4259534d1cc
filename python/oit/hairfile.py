"""Cem Yuksel's `.hair` files (cemyuksel.com/research/hairmodels): strands of points with
optional per-point thickness, transparency and color. numpy only.

The layout, all little-endian: a 128-byte header,

    b"HAIR", strands u32, points u32, flags u32 (bit 0 segments, bit 1 points, bit 2
    thickness, bit 3 transparency, bit 4 color), default segments u32, default thickness
    f32, default transparency f32, default color 3 f32, file information 88 bytes (ASCII,
    NUL-padded)

then the arrays whose bit is set, in this order: segments u16 per strand (a strand has
segments + 1 points), points 3 f32, thickness f32, transparency f32 and color 3 f32 per
point. The points array is required; an absent array takes the header's default.
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass

import numpy as np

__all__ = ["HairStrands", "read_hair", "write_hair", "SIGNATURE", "HEADER_SIZE"]

SIGNATURE = b"HAIR"
HEADER_SIZE = 128
INFO_SIZE = 88
MAX_SEGMENTS = 0xFFFF  # the segments array is uint16
SEGMENTS, POINTS, THICKNESS, TRANSPARENCY, COLOR = (1 << i for i in range(5))
_HEADER = struct.Struct("<4sIIIIff3f88s")


@dataclass(frozen=True, eq=False)
class HairStrands:
    """The strands of a `.hair` file, one row per point (arrays are read-only).

    `points` (n, 3) float32; `counts` (strands,) int64, the points of each strand in order
    (segments + 1); `widths` (n,) float32, the thickness; `colors` (n, 4) float32 straight
    RGBA in [0, 1], alpha = 1 - transparency; `info` the file's information text."""

    points: np.ndarray
    counts: np.ndarray
    widths: np.ndarray
    colors: np.ndarray
    info: str


def _frozen(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


def read_hair(path: str | os.PathLike) -> HairStrands:
    """Reads a `.hair` file; bytes after the last array are ignored."""
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < HEADER_SIZE:
        raise ValueError(f"{path}: truncated .hair file: expected at least the {HEADER_SIZE}-byte header, found {len(data)} bytes")
    fields = _HEADER.unpack_from(data)
    sig, n_strands, n_points, flags, d_segments, d_thickness, d_transparency = fields[:7]
    d_color, info_bytes = fields[7:10], fields[10]
    if sig != SIGNATURE:
        raise ValueError(f"{path}: not a .hair file: the signature is {sig!r}, expected {SIGNATURE!r}")
    if not flags & POINTS:
        raise ValueError(f"{path}: the header says there is no points array (flags {flags:#x}, bit 1 clear); a .hair file needs one")
    layout = [(SEGMENTS, "<u2", 1, n_strands), (POINTS, "<f4", 3, n_points), (THICKNESS, "<f4", 1, n_points),
              (TRANSPARENCY, "<f4", 1, n_points), (COLOR, "<f4", 3, n_points)]
    arrays, pos = {}, HEADER_SIZE
    for bit, dtype, width, rows in layout:
        if not flags & bit:
            continue
        size = np.dtype(dtype).itemsize * width * rows
        if bit == POINTS:  # the segments are known now: check the point total before trusting it
            counts = arrays[SEGMENTS].astype(np.int64) + 1 if flags & SEGMENTS else None
            total = int(counts.sum()) if counts is not None else n_strands * (d_segments + 1)  # no array for a bad header
            if total != n_points:
                raise ValueError(f"{path}: the header says {n_points} points, but the {n_strands} strands' segments + 1 add up to "
                                 f"{total}; the file is damaged or was written wrongly")
            if counts is None:
                counts = np.full(n_strands, d_segments + 1, np.int64)
        end = pos + size
        if len(data) < end:
            total = HEADER_SIZE + sum(np.dtype(d).itemsize * w * r for b, d, w, r in layout if flags & b)
            raise ValueError(f"{path}: truncated .hair file: expected {total} bytes for {n_strands} strands and {n_points} "
                             f"points (flags {flags:#x}), found {len(data)}")
        arrays[bit] = np.frombuffer(data, dtype, width * rows, pos).reshape((rows, width) if width > 1 else rows)
        pos = end
    points = arrays[POINTS].astype(np.float32)
    bad = ~np.isfinite(points).all(axis=1)
    if bad.any():
        first = int(np.argmax(bad))
        raise ValueError(f"{path}: {int(bad.sum())} of the {n_points} points are NaN or infinite (the first is point {first})")
    widths = arrays[THICKNESS].astype(np.float32) if flags & THICKNESS else np.full(n_points, d_thickness, np.float32)
    colors = np.empty((n_points, 4), np.float32)
    colors[:, :3] = arrays[COLOR] if flags & COLOR else d_color
    colors[:, 3] = 1.0 - (arrays[TRANSPARENCY] if flags & TRANSPARENCY else np.float32(d_transparency))
    np.clip(colors, 0.0, 1.0, out=colors)
    info = info_bytes.split(b"\0", 1)[0].decode("ascii", errors="replace")
    return HairStrands(_frozen(points), _frozen(counts), _frozen(widths), _frozen(colors), info)


def _floats(name: str, value, shape: tuple[int, ...]) -> np.ndarray:
    a = np.asarray(value)
    if a.dtype == np.bool_ or not (np.issubdtype(a.dtype, np.floating) or np.issubdtype(a.dtype, np.integer)):
        raise ValueError(f"{name} must be real numbers, got dtype {a.dtype}")
    if a.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {a.shape}")
    a = a.astype(np.float32)
    if not np.isfinite(a).all():
        raise ValueError(f"{name} has NaN or infinite values; a .hair file takes finite numbers only")
    return a


def write_hair(path: str | os.PathLike, points, counts, widths=None, colors=None, info: str = "") -> None:
    """Writes strands to a `.hair` file: `points` (n, 3), `counts` (strands,) integers of at
    least 2 (the points of each strand, in order) that add up to n.

    `widths` is None (no thickness array, default 1), one number (the default thickness) or
    (n,) per point; `colors` is None (no color arrays, default opaque white), one straight
    RGBA (the defaults) or (n, 4) per point, written as color and transparency = 1 - alpha
    arrays. `info` is ASCII text of at most 88 bytes. The segments array is always written."""
    c = np.asarray(counts)
    if c.ndim != 1 or not (np.issubdtype(c.dtype, np.integer) or c.size == 0) or c.dtype == np.bool_:
        raise ValueError(f"counts must be a 1-D array of integers (points per strand), got dtype {c.dtype} and shape {c.shape}")
    c = c.astype(np.int64)
    if (c < 2).any():
        i = int(np.argmax(c < 2))
        raise ValueError(f"strand {i} has {int(c[i])} points; a strand needs at least two points (one segment)")
    if (c - 1 > MAX_SEGMENTS).any():
        i = int(np.argmax(c - 1 > MAX_SEGMENTS))
        raise ValueError(f"strand {i} has {int(c[i]) - 1} segments; a .hair file holds at most {MAX_SEGMENTS} per strand: split it")
    p = np.asarray(points)
    if p.ndim != 2 or p.shape[1:] != (3,):
        raise ValueError(f"points must have shape (n, 3), got {p.shape}")
    n = int(c.sum())
    if p.shape[0] != n:
        raise ValueError(f"counts add up to {n} points, but points has {p.shape[0]} rows; they must match")
    p = _floats("points", p, (n, 3))
    flags, arrays = SEGMENTS | POINTS, [(c - 1).astype("<u2"), p.astype("<f4")]
    d_thickness, d_transparency, d_color = 1.0, 0.0, (1.0, 1.0, 1.0)
    if widths is not None:
        if np.ndim(widths) == 0:
            d_thickness = float(_floats("widths", widths, ()))
        else:
            flags |= THICKNESS
            arrays.append(_floats("widths", widths, (n,)).astype("<f4"))
    if colors is not None:
        if np.shape(colors) == (4,):
            rgba = _floats("colors", colors, (4,))
            d_color, d_transparency = tuple(float(x) for x in rgba[:3]), float(1.0 - rgba[3])
        else:
            rgba = _floats("colors (one RGBA, or one per point)", colors, (n, 4))
            flags |= TRANSPARENCY | COLOR
            arrays += [(1.0 - rgba[:, 3]).astype("<f4"), np.ascontiguousarray(rgba[:, :3]).astype("<f4")]
    try:
        info_bytes = info.encode("ascii")
    except UnicodeEncodeError:
        raise ValueError(f"info must be ASCII text, got {info!r}") from None
    if len(info_bytes) > INFO_SIZE:
        raise ValueError(f"info is {len(info_bytes)} bytes; a .hair file holds at most {INFO_SIZE}: shorten it")
    header = _HEADER.pack(SIGNATURE, len(c), n, flags, 0, d_thickness, d_transparency, *d_color, info_bytes)
    with open(path, "wb") as f:
        f.write(header + b"".join(a.tobytes() for a in arrays))
