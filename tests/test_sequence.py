"""Notebook display and frame sequences: Frame._repr_png_, `render --orbit N -o out.gif` with
its temporal error against the exact frames, and a clear message where MP4 cannot be written."""

from __future__ import annotations

import subprocess
import sys
import zlib

import numpy as np
import pytest

import oit
from files import box_and_panel_glb
from oit import sequence
from oit.imageio import to_srgb8
from oit.views import orbit_cameras

SIZE = 32


def test_a_frame_shows_as_png(renderer, tmp_path):
    scene = oit.Scene.from_file(box_and_panel_glb(tmp_path / "two.glb"))
    frame = renderer(SIZE, SIZE).render(scene, orbit_cameras(scene, 1)[0], "abuffer")
    png = frame._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    # IHDR: the frame's size, 8-bit RGB; the pixels are the sRGB encoding of its image.
    assert png[16:24] == np.array([SIZE, SIZE], ">u4").tobytes() and png[24:26] == bytes([8, 2])
    at, idat = 8, b""
    while at < len(png):
        n, kind = int.from_bytes(png[at:at + 4], "big"), png[at + 4:at + 8]
        idat += png[at + 8:at + 8 + n] if kind == b"IDAT" else b""
        at += 12 + n
    rows = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(SIZE, 1 + 3 * SIZE)
    assert (rows[:, 1:].reshape(SIZE, SIZE, 3) == to_srgb8(frame.image[..., :3])).all()


def test_orbit_views_turn_about_the_scene(tmp_path):
    scene = oit.Scene.from_file(box_and_panel_glb(tmp_path / "two.glb"))
    cams = orbit_cameras(scene, 4)
    assert len(cams) == 4
    # Each view looks at the box's center from its own side: the directions differ.
    dirs = [np.linalg.inv(c.view_proj) @ [0, 0, 1, 1] for c in cams]
    assert len({tuple(np.round(d[:3] / d[3], 3)) for d in dirs}) == 4
    with pytest.raises(ValueError, match="views must be a positive int"):
        orbit_cameras(scene, 0)


def test_sequence_temporal_error_is_zero_for_the_exact_method_and_not_for_an_approximate_one(renderer, tmp_path):
    scene = oit.Scene.from_file(box_and_panel_glb(tmp_path / "two.glb"), alpha=0.5)
    cams = orbit_cameras(scene, 3)
    exact = sequence.render_sequence(renderer(SIZE, SIZE), scene, cams, "abuffer")
    assert exact.temporal["flicker"] == 0 and exact.temporal["max_err"] == 0 and exact.temporal["change"] > 0
    approx = sequence.render_sequence(renderer(SIZE, SIZE), scene, cams, "wavg")
    assert approx.temporal["max_err"] > 0 and approx.temporal["flicker"] > 0
    assert [im.shape for im in approx.images] == [(SIZE, SIZE, 4)] * 3


def test_render_orbit_writes_a_gif_and_reports_the_temporal_error(tmp_path):
    pytest.importorskip("PIL", reason="GIFs are written with Pillow")
    from PIL import Image

    out = tmp_path / "two.gif"
    done = subprocess.run([sys.executable, "-m", "oit", "render", str(box_and_panel_glb(tmp_path / "two.glb")), "--orbit", "3",
                           "--method", "wavg", "--size", str(SIZE), str(SIZE), "-o", str(out)],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "3 views; against the exact frames: mean error" in done.stdout and "flicker" in done.stdout
    with Image.open(out) as gif:
        assert gif.n_frames == 3 and gif.size == (SIZE, SIZE)


def test_bad_animation_outputs(tmp_path, monkeypatch):
    with pytest.raises(ValueError, match=r"out\.gif or out\.mp4"):
        sequence.check_animation_path("x.avi")
    monkeypatch.setitem(sys.modules, "imageio", None)  # as if imageio were not installed
    with pytest.raises(RuntimeError, match=r"pip install 'oit\[video\]'"):
        sequence.write_animation(str(tmp_path / "x.mp4"), [np.zeros((4, 4, 4), np.float32)] * 2)
