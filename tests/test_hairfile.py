"""The `.hair` reader and writer: round trips, defaults, the byte layout against a file
packed by hand from the specification, and the errors."""

from __future__ import annotations

import dataclasses
import struct

import numpy as np
import pytest

from oit.hairfile import read_hair, write_hair


def strands(counts=(3, 2, 4), seed=0):
    """Random points for strands of `counts` points each."""
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.0, 1.0, (sum(counts), 3)).astype(np.float32), np.array(counts)


def header(strands, points, flags, segments=0, thickness=1.0, transparency=0.0, color=(1.0, 1.0, 1.0), info=b""):
    """The 128-byte header, field by field as the specification lists them."""
    out = b"HAIR"
    out += struct.pack("<I", strands) + struct.pack("<I", points) + struct.pack("<I", flags)
    out += struct.pack("<I", segments) + struct.pack("<f", thickness) + struct.pack("<f", transparency)
    out += struct.pack("<fff", *color) + info.ljust(88, b"\0")
    assert len(out) == 128
    return out


def write_bytes(tmp_path, data, name="hand.hair"):
    path = tmp_path / name
    path.write_bytes(data)
    return path


def test_round_trip_of_every_array(tmp_path):
    points, counts = strands()
    rng = np.random.default_rng(1)
    widths = rng.uniform(0.1, 2.0, len(points)).astype(np.float32)
    colors = rng.uniform(0.0, 1.0, (len(points), 4)).astype(np.float32)
    write_hair(tmp_path / "a.hair", points, counts, widths=widths, colors=colors, info="a test model")
    data = (tmp_path / "a.hair").read_bytes()
    assert struct.unpack_from("<I", data, 12)[0] == 0b11111
    hair = read_hair(tmp_path / "a.hair")
    assert hair.points.dtype == np.float32 and hair.points.shape == (9, 3)
    assert hair.counts.dtype == np.int64 and hair.counts.tolist() == [3, 2, 4]
    assert hair.widths.dtype == np.float32 and hair.colors.dtype == np.float32
    np.testing.assert_array_equal(hair.points, points)
    np.testing.assert_array_equal(hair.widths, widths)
    np.testing.assert_array_equal(hair.colors[:, :3], colors[:, :3])
    # alpha goes through transparency = 1 - alpha in float32 and back
    np.testing.assert_allclose(hair.colors[:, 3], colors[:, 3], atol=1e-7)
    assert hair.info == "a test model"


def test_defaults_fill_absent_arrays(tmp_path):
    points, counts = strands()
    write_hair(tmp_path / "plain.hair", points, counts)
    data = (tmp_path / "plain.hair").read_bytes()
    assert struct.unpack_from("<I", data, 12)[0] == 0b00011  # segments and points only
    assert len(data) == 128 + 2 * 3 + 12 * 9
    hair = read_hair(tmp_path / "plain.hair")
    np.testing.assert_array_equal(hair.widths, np.ones(9, np.float32))
    np.testing.assert_array_equal(hair.colors, np.ones((9, 4), np.float32))
    assert hair.info == ""


def test_scalar_width_and_one_rgba_become_the_defaults(tmp_path):
    points, counts = strands()
    write_hair(tmp_path / "d.hair", points, counts, widths=0.25, colors=(0.5, 0.25, 0.125, 0.75))
    data = (tmp_path / "d.hair").read_bytes()
    assert struct.unpack_from("<I", data, 12)[0] == 0b00011
    assert struct.unpack_from("<5f", data, 20) == (0.25, 0.25, 0.5, 0.25, 0.125)
    hair = read_hair(tmp_path / "d.hair")
    np.testing.assert_array_equal(hair.widths, np.full(9, 0.25, np.float32))
    np.testing.assert_array_equal(hair.colors, np.tile(np.float32([0.5, 0.25, 0.125, 0.75]), (9, 1)))


def test_write_hair_matches_the_specification_byte_for_byte(tmp_path):
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 0, 1], [0, 0, 2]], np.float32)
    widths = np.array([1.0, 0.5, 0.25, 2.0, 3.0], np.float32)
    colors = np.array([[1, 0, 0, 1], [0, 1, 0, 0.5], [0, 0, 1, 0.25], [1, 1, 0, 0], [0, 1, 1, 0.75]], np.float32)
    write_hair(tmp_path / "w.hair", points, [3, 2], widths=widths, colors=colors, info="by hand")
    expected = header(2, 5, 0b11111, info=b"by hand")
    expected += struct.pack("<2H", 2, 1)
    expected += b"".join(struct.pack("<3f", *p) for p in points)
    expected += b"".join(struct.pack("<f", w) for w in widths)
    expected += b"".join(struct.pack("<f", 1.0 - a) for a in colors[:, 3])
    expected += b"".join(struct.pack("<3f", *c) for c in colors[:, :3])
    assert (tmp_path / "w.hair").read_bytes() == expected


def test_reads_a_file_packed_by_hand(tmp_path):
    # No segments array: two strands of the default 2 segments; thickness and color arrays,
    # transparency from the header; trailing bytes are ignored.
    pts = [(0.0, 0.0, 0.0), (1.0, 2.0, 3.0), (4.0, 5.0, 6.0), (-1.0, -2.0, -3.0), (7.5, 8.5, 9.5), (0.125, 0.25, 0.5)]
    data = header(2, 6, 0b10110, segments=2, thickness=9.0, transparency=0.25, color=(0.1, 0.2, 0.3), info=b"hand-packed")
    data += b"".join(struct.pack("<3f", *p) for p in pts)
    data += b"".join(struct.pack("<f", 0.5 * i) for i in range(6))
    data += b"".join(struct.pack("<3f", 0.1 * i, 0.0, 1.0) for i in range(6))
    hair = read_hair(write_bytes(tmp_path, data + b"extra"))
    assert hair.counts.tolist() == [3, 3]
    np.testing.assert_array_equal(hair.points, np.array(pts, np.float32))
    np.testing.assert_array_equal(hair.widths, np.float32([0.5 * i for i in range(6)]))
    np.testing.assert_array_equal(hair.colors[:, 0], np.float32([0.1 * i for i in range(6)]))
    np.testing.assert_array_equal(hair.colors[:, 3], np.full(6, 0.75, np.float32))
    assert hair.info == "hand-packed"


def test_alpha_is_clipped_and_the_result_is_read_only(tmp_path):
    data = header(1, 2, 0b01011) + struct.pack("<H", 1) + struct.pack("<6f", 0, 0, 0, 1, 1, 1) + struct.pack("<2f", -0.5, 1.5)
    hair = read_hair(write_bytes(tmp_path, data))
    assert hair.colors[:, 3].tolist() == [1.0, 0.0]
    with pytest.raises(ValueError, match="read-only"):
        hair.points[0, 0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        hair.info = "changed"


def test_info_of_88_bytes_fills_the_field(tmp_path):
    points, counts = strands()
    write_hair(tmp_path / "i.hair", points, counts, info="x" * 88)
    assert read_hair(tmp_path / "i.hair").info == "x" * 88
    with pytest.raises(ValueError, match="at most 88"):
        write_hair(tmp_path / "j.hair", points, counts, info="x" * 89)
    with pytest.raises(ValueError, match="ASCII"):
        write_hair(tmp_path / "j.hair", points, counts, info="α")


def test_zero_strands(tmp_path):
    write_hair(tmp_path / "empty.hair", np.zeros((0, 3)), [])
    hair = read_hair(tmp_path / "empty.hair")
    assert hair.points.shape == (0, 3) and hair.counts.shape == (0,) and hair.colors.shape == (0, 4)


# -- errors on read


def test_wrong_signature(tmp_path):
    data = b"HAIX" + header(1, 2, 0b11)[4:] + struct.pack("<H", 1) + bytes(24)
    with pytest.raises(ValueError, match=r"not a \.hair file: the signature is b'HAIX', expected b'HAIR'"):
        read_hair(write_bytes(tmp_path, data))


def test_truncated_header(tmp_path):
    with pytest.raises(ValueError, match=r"truncated \.hair file: expected at least the 128-byte header, found 40 bytes"):
        read_hair(write_bytes(tmp_path, header(1, 2, 0b11)[:40]))


def test_truncated_arrays(tmp_path):
    points, counts = strands()
    write_hair(tmp_path / "t.hair", points, counts, widths=np.ones(9))
    data = (tmp_path / "t.hair").read_bytes()
    assert len(data) == 128 + 6 + 108 + 36
    for cut in (130, 200, len(data) - 1):
        with pytest.raises(ValueError, match=rf"truncated .* expected 278 bytes .* found {cut}"):
            read_hair(write_bytes(tmp_path, data[:cut]))


def test_point_total_must_match_the_segments(tmp_path):
    data = header(2, 6, 0b11) + struct.pack("<2H", 2, 1) + bytes(12 * 6)
    with pytest.raises(ValueError, match=r"header says 6 points, but the 2 strands' segments \+ 1 add up to 5"):
        read_hair(write_bytes(tmp_path, data))
    # without a segments array, from the default segment count
    data = header(2, 6, 0b10, segments=1) + bytes(12 * 6)
    with pytest.raises(ValueError, match="add up to 4"):
        read_hair(write_bytes(tmp_path, data))


def test_points_array_is_required(tmp_path):
    data = header(1, 2, 0b101) + struct.pack("<H", 1) + bytes(8)
    with pytest.raises(ValueError, match=r"no points array .*needs one"):
        read_hair(write_bytes(tmp_path, data))


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_points_on_read(tmp_path, bad):
    data = header(1, 3, 0b11) + struct.pack("<H", 2) + struct.pack("<9f", 0, 0, 0, 1, 1, 1, 2, bad, 2)
    with pytest.raises(ValueError, match=r"1 of the 3 points are NaN or infinite \(the first is point 2\)"):
        read_hair(write_bytes(tmp_path, data))


# -- errors on write


def test_too_many_segments(tmp_path):
    counts = [2, 65537]
    with pytest.raises(ValueError, match=r"strand 1 has 65536 segments; .* at most 65535"):
        write_hair(tmp_path / "x.hair", np.zeros((sum(counts), 3)), counts)
    write_hair(tmp_path / "ok.hair", np.zeros((65536, 3)), [65536])  # 65535 segments fit
    assert read_hair(tmp_path / "ok.hair").counts.tolist() == [65536]


@pytest.mark.parametrize("count", [1, 0, -1])
def test_strands_need_two_points(tmp_path, count):
    with pytest.raises(ValueError, match=f"strand 1 has {count} points; a strand needs at least two"):
        write_hair(tmp_path / "x.hair", np.zeros((3 + max(count, 0), 3)), [3, count])


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_values_on_write(tmp_path, bad):
    points, counts = strands()
    bent = points.copy()
    bent[4, 1] = bad
    with pytest.raises(ValueError, match="points has NaN or infinite"):
        write_hair(tmp_path / "x.hair", bent, counts)
    with pytest.raises(ValueError, match="widths has NaN or infinite"):
        write_hair(tmp_path / "x.hair", points, counts, widths=np.full(9, bad))
    with pytest.raises(ValueError, match=r"colors .*has NaN or infinite"):
        write_hair(tmp_path / "x.hair", points, counts, colors=np.full((9, 4), bad))


@pytest.mark.parametrize(
    "kwargs,message",
    [
        (dict(points=np.zeros((9, 2))), r"points must have shape \(n, 3\), got \(9, 2\)"),
        (dict(points=np.zeros(27)), r"points must have shape \(n, 3\)"),
        (dict(points=np.zeros((8, 3))), "counts add up to 9 points, but points has 8 rows"),
        (dict(points=np.zeros((9, 3), complex)), "points must be real numbers, got dtype complex128"),
        (dict(points=np.zeros((9, 3), bool)), "points must be real numbers, got dtype bool"),
        (dict(counts=np.array([3.0, 2.0, 4.0])), "counts must be a 1-D array of integers.*float64"),
        (dict(counts=np.array([[3, 2, 4]])), r"counts must be a 1-D array .*shape \(1, 3\)"),
        (dict(widths=np.ones(8)), r"widths must have shape \(9,\), got \(8,\)"),
        (dict(widths="wide"), "widths must be real numbers"),
        (dict(colors=np.ones((9, 3))), r"colors .*must have shape \(9, 4\), got \(9, 3\)"),
        (dict(colors=(1.0, 1.0, 1.0)), r"colors .*must have shape \(9, 4\), got \(3,\)"),
    ],
)
def test_wrong_shapes_and_dtypes_on_write(tmp_path, kwargs, message):
    points, counts = strands()
    args = {"points": points, "counts": counts, **kwargs}
    with pytest.raises(ValueError, match=message):
        write_hair(tmp_path / "x.hair", **args)
    assert not (tmp_path / "x.hair").exists()
