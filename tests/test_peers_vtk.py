"""VTK, the second peer: the same input gives the same picture (camera, colors, background on
opaque scenes), its depth peeling lands within its 8-bit rounding of the A-buffer, and the
bench puts its rows in the table, failed with VTK's own word when it does not peel."""

from __future__ import annotations

import ctypes.util
import math
import os

import numpy as np
import pytest

import oit
from oit import geometry, peers, scenes
from oit.bench import results

needs_vtk = pytest.mark.skipif(peers.vtk_missing() is not None, reason=str(peers.vtk_missing()))
# Not square, so that a transposed matrix or a lost aspect ratio shows.
W, H = 56, 40
STEP = 1.0 / 255.0  # one step of VTK's 8-bit framebuffer (linear, no sRGB)


def opaque_spheres() -> scenes.BuiltScene:
    rng = np.random.default_rng(5)
    meshes = []
    for _ in range(5):
        p, i = geometry.uv_sphere(rng.uniform(-0.5, 0.5, 3), rng.uniform(0.2, 0.4), 8, 16)
        meshes.append(scenes.MeshArrays(p, i, rng.uniform(0, 1, (len(p), 4)).astype(np.float32), opaque=True))
    camera = oit.Camera.look_at(eye=(0.7, 0.5, 2.5), target=(0.1, -0.1, 0.0), fov_y=45.0, near=1.0, far=5.0)
    return scenes.from_meshes(meshes, camera)


def transparent_quads(layers: int = 6) -> scenes.BuiltScene:
    """`layers` overlapping quads at distinct depths, submitted in a shuffled order, with
    per-vertex colors and alphas on the 8-bit grid (so VTK's 8-bit inputs are exact)."""
    rng = np.random.default_rng(1)
    camera = oit.Camera.look_at(eye=(0.3, 0.2, 3.0), target=(0.0, 0.0, 0.0), fov_y=45.0, near=1.0, far=6.0)
    meshes = [scenes.MeshArrays(*geometry.quad((0.1 * k, 0.05 * k, 0.5 - 0.3 * k), 1.2),
                                (rng.integers(20, 256, (4, 4)) / 255.0).astype(np.float32))
              for k in rng.permutation(layers)]
    return scenes.from_meshes(meshes, camera)


@needs_vtk
@pytest.mark.parametrize("mode", peers.VTK_MODES)
def test_vtk_draws_an_opaque_scene_as_we_do(renderer, mode):
    """Opaque meshes with random linear vertex colors under an off-center perspective camera, on
    a colored background. VTK gets the colors rounded to 8 bits (1/510 at most, and linear
    interpolation keeps that bound) and stores 8 bits (1/510 more), so one 8-bit step is the
    tolerance on every pixel, edges included; a wrong matrix order, depth range, color space,
    lighting or interpolation would move whole regions by far more."""
    built, background = opaque_spheres(), (0.2, 0.5, 0.9)
    frame = renderer(W, H).render(built.scene, built.camera, "abuffer", background=background)
    theirs, wall = peers.vtk_renderer(W, H).render(built, mode, background)
    assert theirs.shape == (H, W, 4) and wall > 0
    ours = frame.image[..., :3].astype(np.float64)
    assert np.abs(ours - theirs[..., :3]).max() <= STEP + 1e-6
    # The comparison means something: spheres cover a good part of the frame, in many colors.
    drawn = np.abs(ours - background).max(-1) > 0.05
    assert 0.2 < drawn.mean() < 0.9 and len(np.unique(np.rint(ours[drawn] * 255), axis=0)) > 100


@needs_vtk
def test_vtk_depth_peeling_is_within_its_rounding_of_the_abuffer(renderer):
    """Six transparent quads, shuffled. Dual depth peeling stores each peel in RGBA8 textures: a
    front layer's accumulated color and alpha are rounded once each (2/510 a channel, since an
    alpha error only scales what lies behind it), a back layer's premultiplied color, the back
    accumulation and its alpha once each (3/510), and the final composite onto the opaque
    framebuffer twice more: (2.5 L + 2)/510 a channel with L layers, about 8.5 steps for 6. VTK
    blending the same quads unsorted must miss by far more, or the check would prove nothing."""
    built = transparent_quads()
    frame = renderer(W, H).render(built.scene, built.camera, "abuffer")
    layers = frame.stats["max_depth_complexity"]
    assert layers == 6
    exact = frame.image[..., :3].astype(np.float64)
    vtk = peers.vtk_renderer(W, H)
    peeled, _ = vtk.render(built, "depth_peeling")
    assert vtk.peeled()
    bound = (2.5 * layers + 2) / 510
    assert np.abs(peeled[..., :3] - exact).max() <= bound
    blended, _ = vtk.render(built, "blend")
    assert not vtk._renderers["blend"].GetLastRenderingUsedDepthPeeling()
    assert np.abs(blended[..., :3] - exact).max() > 4 * bound
    # VTK's blend is our unsorted (actor order), up to one 8-bit rounding a layer.
    unsorted = renderer(W, H).render(built.scene, built.camera, "unsorted").image[..., :3]
    assert np.abs(blended[..., :3] - unsorted).max() <= (layers + 1) / 510


@needs_vtk
def test_a_vtk_row_fails_when_vtk_does_not_peel(monkeypatch):
    """A depth peeling row on which VTK reports it did not peel (as on a driver without it:
    VTK then draws the translucent geometry some other way) is failed with that message, with
    no time, no errors and no image, never another mode's picture under its name."""
    built = transparent_quads()
    vtk = peers.vtk_renderer(W, H)
    monkeypatch.setattr(vtk, "peeled", lambda: False)
    with pytest.raises(RuntimeError, match="did not use depth peeling"):
        vtk.render(built, "depth_peeling")
    exact = np.ones((H, W, 4), np.float32)
    sheet: dict = {}
    row = results._peer_row("quads", built, W, H, "vtk", "depth_peeling", 1, exact, np.ones((H, W), bool), sheet)
    assert row["status"] == "failed" and "did not use depth peeling" in row["message"], row
    assert math.isnan(row["wall_ms"]) and math.isnan(row["mean_err"]) and "vtk-depth_peeling" not in sheet
    # An opaque scene has nothing to peel: VTK says it did not, and that is no failure.
    image, _ = vtk.render(opaque_spheres(), "depth_peeling")
    assert image.shape == (H, W, 4)


@needs_vtk
def test_bench_puts_vtk_rows_in_the_table():
    tiny = dict(scenes=["glass"], methods=["abuffer", "unsorted"], sizes=[32], repeat=1, quick=True, show_progress=False)
    rows = {r["method"]: r for r in results.run(**tiny, with_peers=True).rows}
    for mode in peers.VTK_MODES:
        row = rows[f"vtk-{mode}"]
        assert row["status"] == "ok" and row["wall_ms"] > 0 and row["mean_err"] >= 0, row
        assert row["adapter"].startswith("VTK ") and math.isnan(row["gpu_ms"])
    # Peeling is exact but for 8-bit rounding; blending in actor order is not.
    assert rows["vtk-depth_peeling"]["mean_err"] < 0.01 < rows["vtk-blend"]["mean_err"]
    without = results.run(**tiny, with_peers=False)
    assert not [r for r in without.rows if r["method"].startswith(("vtk-", "pygfx-"))]
    assert not [n for n in without.notes if "vtk" in n or "pygfx" in n]


@needs_vtk
@pytest.mark.skipif(bool(os.environ.get("DISPLAY") or ctypes.util.find_library("OSMesa")),
                    reason="VTK could open a context through X or OSMesa here, without EGL")
def test_vtk_missing_says_so_when_no_context_opens(monkeypatch):
    """With no EGL driver to load (and neither X nor OSMesa), VTK crashes opening a window; the
    probe runs in a child process, so this gives a reason instead of taking the tests down."""
    monkeypatch.setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/egl_vendor.json")
    peers.vtk_missing.cache_clear()
    try:
        reason = peers.vtk_missing()
    finally:
        monkeypatch.undo()
        peers.vtk_missing.cache_clear()
    assert reason is not None and "could not open an OpenGL context" in reason and "EGL" in reason
    assert peers.vtk_missing() is None


def test_bench_notes_why_vtk_rows_are_missing(monkeypatch):
    """Where VTK cannot render, the sweep runs without its rows and says why (needs no VTK)."""
    for library, (modes, _, make) in list(peers.PEERS.items()):
        monkeypatch.setitem(peers.PEERS, library, (modes, lambda lib=library: f"{lib} left out here", make))
    result = results.run(scenes=["glass"], methods=["unsorted"], sizes=[16], repeat=1, quick=True, show_progress=False)
    assert [r["method"] for r in result.rows] == ["unsorted"]
    assert "vtk rows are missing: vtk left out here" in result.notes
    assert "pygfx rows are missing: pygfx left out here" in result.notes
