"""The PNG writer, sRGB encoding and the heatmap (decoded here with zlib alone)."""

from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest

from oit import imageio


def decode_png(data: bytes) -> np.ndarray:
    """Decodes the 8-bit RGB/RGBA, filter-0, non-interlaced PNGs that imageio writes."""
    assert data[:8] == imageio.PNG_SIGNATURE
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
        assert crc == zlib.crc32(kind + body) & 0xFFFFFFFF, f"bad CRC in {kind!r}"
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    assert kind == b"IEND"
    w, h, depth, color_type, _, _, interlace = header
    assert depth == 8 and interlace == 0
    channels = {2: 3, 6: 4}[color_type]
    rows = np.frombuffer(zlib.decompress(idat), dtype=np.uint8).reshape(h, 1 + w * channels)
    assert (rows[:, 0] == 0).all(), "imageio writes filter type 0 only"
    return rows[:, 1:].reshape(h, w, channels)


def test_srgb_encoding_known_values():
    linear = np.array([[[0.0, 1.0, 0.5], [0.0031308, 0.25, 2.0]]])
    # sRGB(0.5) = 0.7354 -> 188; sRGB(0.0031308) = 0.04045 -> 10; sRGB(0.25) = 0.5371 -> 137;
    # values above 1 clip to 255.
    assert imageio.to_srgb8(linear).tolist() == [[[0, 255, 188], [10, 137, 255]]]
    assert imageio.to_srgb8(np.array([[[np.nan, -1.0, 0.5, 0.5]]])).tolist() == [[[0, 0, 188, 128]]]


def test_srgb_round_trip():
    x = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(imageio.srgb_to_linear(imageio.linear_to_srgb(x)), x, atol=1e-12)


@pytest.mark.parametrize("channels", [3, 4])
def test_png_round_trip(tmp_path, channels):
    rng = np.random.default_rng(0)
    pixels = rng.integers(0, 256, (7, 5, channels), dtype=np.uint8)
    path = tmp_path / "x.png"
    imageio.write_png(path, pixels)
    assert np.array_equal(decode_png(path.read_bytes()), pixels)
    # Floats are linear: they come back sRGB-encoded (alpha as is).
    image = rng.uniform(0, 1, (3, 4, channels)).astype(np.float32)
    assert np.array_equal(decode_png(imageio.encode_png(image)), imageio.to_srgb8(image))


@pytest.mark.parametrize("shape,dtype,error", [
    ((4, 4), np.float32, ValueError), ((4, 4, 2), np.float32, ValueError), ((0, 4, 3), np.float32, ValueError),
    ((4, 4, 3), np.int32, TypeError),
])
def test_png_rejects(shape, dtype, error):
    with pytest.raises(error):
        imageio.encode_png(np.zeros(shape, dtype=dtype))


def test_heatmap_ramp():
    values = np.array([[0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0, 5.0]])
    display = imageio.linear_to_srgb(imageio.heatmap(values, vmax=1.0))
    expected = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 1], [1, 1, 1]]  # black, red, yellow, white
    np.testing.assert_allclose(display[0], expected, atol=1e-9)
    ramp = imageio.linear_to_srgb(imageio.heatmap(np.linspace(0, 1, 50)[None], vmax=1.0))[0].sum(axis=-1)
    assert (np.diff(ramp) > 0).all()
    with pytest.raises(ValueError, match="vmax must be positive"):
        imageio.heatmap(values, vmax=0.0)


def test_mosaic_layout():
    a, b = np.zeros((2, 3, 3)), np.ones((2, 3, 3))
    out = imageio.mosaic([[a, b], [b]], gap=1, fill=(0.5, 0.5, 0.5))
    assert out.shape == (5, 7, 3)
    assert (out[0:2, 4:7] == 1).all() and (out[3:5, 0:3] == 1).all()
    assert (out[2] == 0.5).all() and (out[:, 3] == 0.5).all() and (out[3:5, 4:7] == 0.5).all()
