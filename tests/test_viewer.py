"""The viewer (crates/oit-viewer): scene files, `python -m oit view`, and `--screenshot` under
Xvfb compared with the library's render of the same scene and camera. The tests that run the
binary are skipped without it (`make viewer`), the screenshot tests also without `xvfb-run`
(Debian's xvfb)."""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

import oit
from oit import cli, scenefile, scenes, view
from oit.imageio import to_srgb8
from oit.scenefile import LookAt
from oit.scenes import MeshArrays


def _viewer():
    try:
        return view.find_viewer()
    except RuntimeError:
        return None


VIEWER = _viewer()
needs_viewer = pytest.mark.skipif(VIEWER is None, reason="needs the oit-viewer binary (`make viewer`)")
needs_screen = pytest.mark.skipif(VIEWER is None or shutil.which("xvfb-run") is None,
                                  reason="needs the oit-viewer binary (`make viewer`) and xvfb-run (apt-get install xvfb)")


def read_png(path: Path) -> np.ndarray:
    """(h, w, 4) uint8 of an 8-bit RGBA PNG as the viewer writes it (no row filters)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    at, idat, size = 8, b"", None
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if kind == b"IHDR":
            w, h, depth, color = struct.unpack(">IIBB", body[:10])
            assert (depth, color) == (8, 6), "expected 8-bit RGBA"
            size = (w, h)
        elif kind == b"IDAT":
            idat += body
        at += 12 + length
    w, h = size
    rows = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(h, 1 + 4 * w)
    assert (rows[:, 0] == 0).all(), "the viewer writes PNG rows unfiltered"
    return rows[:, 1:].reshape(h, w, 4)


def screenshot(tmp_path: Path, args, size=(480, 320), through_python=False) -> np.ndarray:
    """Runs the viewer on `args` under Xvfb, or through `python -m oit view` with the built-in
    scene args[0] (exported to a file that Python starts the same binary on), and reads its
    --crop-view screenshot."""
    out = tmp_path / "shot.png"
    w, h = size
    shot = ["--size", str(w), str(h), "--screenshot", str(out), "--frames", "2"]
    if through_python:
        # `python -m oit view --scene NAME ...`, the viewer-only options after `--`.
        viewer = [sys.executable, "-m", "oit", "view", "--scene", *args, *shot, "--", "--hide-panel", "--crop-view"]
    else:
        viewer = [str(VIEWER), *args, *shot, "--hide-panel", "--crop-view"]
    command = ["xvfb-run", "-a", "-s", f"-screen 0 {w + 64}x{h + 64}x24", *viewer]
    done = subprocess.run(command, capture_output=True, text=True, timeout=180, env={**os.environ, "OIT_VIEWER": str(VIEWER)})
    assert done.returncode == 0, done.stdout + done.stderr
    return read_png(out)


def assert_matches(shot: np.ndarray, frame_image: np.ndarray) -> None:
    """The screenshot shows the frame: the 8-bit sRGB encoding of its linear RGB. On lavapipe
    (Mesa llvmpipe) the display path (egui samples an sRGB texture and writes the window) is
    exact: 0 pixels differ. The slack, one level on at most 0.1% of the pixels, is for
    drivers that round the texture round trip differently."""
    expected = to_srgb8(frame_image[..., :3]).astype(np.int16)
    got = shot[..., :3].astype(np.int16)
    assert got.shape == expected.shape
    background = (got == 255).all(axis=2).mean()
    assert 0.05 < background < 0.95, f"the screenshot is blank or all scene ({background:.1%} background)"
    diff = np.abs(got - expected).max(axis=2)
    assert diff.max() <= 1 and (diff > 0).mean() <= 0.001, \
        f"{(diff > 0).sum()} of {diff.size} pixels differ, by up to {diff.max()} levels"


def test_scene_files_keep_surfaces_and_lights(tmp_path):
    built = scenes.glass(detail=8)
    path = tmp_path / "glass.oitscene"
    scenefile.save_scene(built, path)
    meshes, camera, _ = scenefile.load_scene(path)
    lights, ambient = scenefile.load_lights(path)
    assert path.read_bytes()[8:12] == (2).to_bytes(4, "little")
    assert [m.surface["shading"] for m in meshes] == ["smooth", "flat", "smooth", "smooth"]
    assert len(lights) == 2 and ambient == pytest.approx(built.ambient)
    r = oit.Renderer(24, 24)
    same = scenefile.scene_of(meshes, lights, ambient)
    assert np.array_equal(r.render(same, camera).image, r.render(built.scene, built.camera).image)
    # Without surfaces or lights, the file stays version 1 (older viewers read it).
    plain = [scenes.MeshArrays(m.positions, m.indices, m.colors, m.opaque) for m in built.meshes]
    scenefile.save_scene(plain, path)
    assert path.read_bytes()[8:12] == (1).to_bytes(4, "little")


def test_scene_file_round_trip(tmp_path):
    built = scenes.glass(detail=8)
    path = tmp_path / "glass.oitscene"
    scenefile.save_scene(built, path)
    meshes, camera, size = scenefile.load_scene(path)
    assert size == built.size and np.array_equal(camera.view_proj, built.camera.view_proj)
    for a, b in zip(meshes, built.meshes):
        assert a.opaque == b.opaque
        for x, y in ((a.positions, b.positions), (a.indices, b.indices), (a.colors, b.colors)):
            assert np.array_equal(x, y)
    look = LookAt(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), fov_y=40.0, near=1.0, far=5.0)
    scenefile.save_scene(built.meshes[:1], path, camera=look)
    assert scenefile.load_scene(path)[1] == look
    with pytest.raises(TypeError, match="BuiltScene"):
        scenefile.save_scene(built.scene, path)


def test_scene_files_keep_texels_exactly_and_name_a_bad_file(tmp_path):
    """The core's codec writes the arrays as given (a texture between 8-bit levels included),
    and a file it cannot read is refused with its path and where it went wrong."""
    texture = np.random.default_rng(3).uniform(0.0, 1.0, (2, 3, 4)).astype(np.float32)
    uvs = np.float32([[0, 0], [1, 0], [0, 1]])
    mesh = MeshArrays(np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.uint32([[0, 1, 2]]), np.float32([[1, 0, 0, 0.5]] * 3),
                      surface={"uvs": uvs, "texture": texture, "shading": "flat", "cull_back_faces": True})
    path = tmp_path / "textured.oitscene"
    scenefile.save_scene([mesh], path)
    (back,), _, _ = scenefile.load_scene(path)
    assert back.surface["shading"] == "flat" and back.surface["cull_back_faces"] and "normals" not in back.surface
    assert np.array_equal(back.surface["texture"], texture) and np.array_equal(back.surface["uvs"], uvs)
    path.write_bytes(path.read_bytes()[:-5])
    with pytest.raises(ValueError, match=r"textured\.oitscene: file ends inside the ambient term"):
        scenefile.load_scene(path)


# tests/data/two_quads.oitscene: one file that this test and crates/oit-viewer/src/scenefile.rs
# (`the_shared_scene_file`) both read and check value by value. Written by save_scene from
# the values below; every number is exact in f32.
SHARED_FILE = Path(__file__).parent / "data" / "two_quads.oitscene"
SHARED_NAMES = ["back (opaque)", "red quad", "triangle, α per vertex"]
SHARED_CAMERA = LookAt(eye=(0.5, 0.25, 4.0), target=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), fov_y=45.0, near=1.0, far=10.0)
SHARED_SIZE = (64, 48)


def shared_meshes() -> list[MeshArrays]:
    def f32(rows):
        return np.array(rows, np.float32)

    quad = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
    return [
        MeshArrays(f32([[-1, -1, -0.5], [1, -1, -0.5], [1, 1, -0.5], [-1, 1, -0.5]]), quad, f32([[0.5, 0.5, 0.5, 1.0]] * 4),
                   opaque=True),
        MeshArrays(f32([[-0.25, -0.5, 0], [0.75, -0.5, 0], [0.75, 0.5, 0], [-0.25, 0.5, 0]]), quad,
                   f32([[1.0, 0.25, 0.125, 0.5]] * 4)),
        MeshArrays(f32([[-0.75, -0.25, 0.25], [0.25, -0.25, 0.25], [-0.25, 0.75, 0.25]]), np.array([[0, 1, 2]], np.uint32),
                   f32([[1, 0, 0, 0.25], [0, 1, 0, 0.5], [0, 0, 1, 0.75]])),
    ]


def test_shared_scene_file(tmp_path):
    """The checked-in file reads as the scene above, and writing it again gives its bytes."""
    meshes, camera, size = scenefile.load_scene(SHARED_FILE)
    assert size == SHARED_SIZE and camera == SHARED_CAMERA
    expected = shared_meshes()
    assert [m.opaque for m in meshes] == [True, False, False] and len(expected) == 3
    for got, want in zip(meshes, expected):
        for x, y in ((got.positions, want.positions), (got.colors, want.colors), (got.indices, want.indices)):
            assert x.dtype == y.dtype and np.array_equal(x, y)
    again = tmp_path / "again.oitscene"
    scenefile.save_scene(meshes, again, camera=camera, size=size, names=SHARED_NAMES)
    assert again.read_bytes() == SHARED_FILE.read_bytes()
    scenefile.save_scene(expected, again, camera=SHARED_CAMERA, size=SHARED_SIZE, names=SHARED_NAMES)
    assert again.read_bytes() == SHARED_FILE.read_bytes()


def test_view_export_writes_the_builtin_scene(tmp_path):
    out = tmp_path / "stacks.oitscene"
    assert cli.main(["view", "--scene", "stacks", "--export", str(out)]) == 0
    meshes, camera, size = scenefile.load_scene(out)
    assert len(meshes) == 1 and size == (10, 10) and np.array_equal(camera.view_proj, np.eye(4))
    assert cli.main(["view", "--scene", "nope", "--export", str(out)]) == 2


def test_view_without_the_binary_says_how_to_build_it(tmp_path, monkeypatch, capsys):
    monkeypatch.delenv("OIT_VIEWER", raising=False)
    monkeypatch.setenv("CARGO_TARGET_DIR", str(tmp_path))
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.setattr(view.Path, "home", lambda: tmp_path)
    monkeypatch.chdir(tmp_path)
    assert cli.main(["view", "--scene", "glass"]) == 1
    assert "make viewer" in capsys.readouterr().err


@needs_viewer
def test_the_binary_sends_builtin_scenes_to_python():
    """The viewer does not start Python: its --scene says which command to run."""
    done = subprocess.run([str(VIEWER), "--scene", "glass"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert "run `python -m oit view --scene glass`" in done.stderr


@needs_screen
def test_screenshot_equals_the_library_render(tmp_path):
    """A look-at camera: the viewer re-aims it at the view's aspect as Camera.look_at does."""
    built = scenes.glass(detail=12)
    look = LookAt(eye=(1.2, 0.9, 1.8), target=(0.0, 0.0, 0.0), fov_y=45.0, near=1.0, far=5.0)
    path = tmp_path / "glass.oitscene"
    scenefile.save_scene(built.meshes, path, camera=look)
    shot = screenshot(tmp_path, [str(path), "--method", "abuffer"], size=(480, 320))
    h, w = shot.shape[:2]
    assert (w, h) == (480, 320)
    frame = oit.Renderer(w, h).render(scenefile.scene_of(built.meshes), look.camera(aspect=w / h), method="abuffer")
    assert_matches(shot, frame.image)


@needs_screen
def test_builtin_scene_through_python_keeps_its_camera(tmp_path):
    """`python -m oit view --scene` (view.run) exports the scene and starts the viewer on the
    file; the BuiltScene's matrix camera is read back into a look-at, so a square view shows
    exactly the library's frame."""
    built = scenes.glass()
    shot = screenshot(tmp_path, ["glass", "--method", "abuffer"], size=(256, 256), through_python=True)
    frame = oit.Renderer(256, 256).render(built.scene, built.camera, method="abuffer")
    assert_matches(shot, frame.image)


@needs_screen
def test_the_viewer_draws_an_opaque_gltf_box_opaque(tmp_path):
    """The viewer reads files with the core's loader: the OPAQUE red box in front of the BLEND
    blue panel hides it. Lit red has equal green and blue (the white highlight alone), so a box
    pixel with more blue than green would be the panel showing through."""
    from files import box_and_panel_glb

    shot = screenshot(tmp_path, [str(box_and_panel_glb(tmp_path / "two.glb")), "--method", "abuffer"], size=(160, 120))
    rgb = shot[..., :3].astype(np.int16)
    box = rgb[..., 0] > rgb[..., 1] + 40
    assert box.mean() > 0.02, "the box is in view"
    assert (rgb[box][:, 1] == rgb[box][:, 2]).all(), "the box is exactly opaque"
    assert (rgb[..., 2] > rgb[..., 1] + 20).any(), "the panel blends beside it"
