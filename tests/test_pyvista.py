"""oit.pyvista: a PyVista plotter rendered by oit. Opaque scenes land within one 8-bit step of
PyVista's own screenshot (antialiasing off; VTK's values pass unchanged, as oit.peers matches
VTK), translucent ones are exact (the A-buffer against oit.reference) where PyVista's own
blending is not, and points and lines are drawn."""

from __future__ import annotations

import os

import numpy as np
import pytest

import oit
from oit import peers

# VTK opens its offscreen window through EGL here, as oit.peers does (its docstring says why).
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
pv = pytest.importorskip("pyvista", reason="pyvista is not installed; `pip install 'oit[pyvista]'` adds it")
opv = pytest.importorskip("oit.pyvista")

needs_vtk_context = pytest.mark.skipif(peers.vtk_missing() is not None, reason=str(peers.vtk_missing()))
# Not square, so that a transposed matrix or a lost aspect ratio shows.
W, H = 64, 48
BACKGROUND = (0.2, 0.4, 0.6)


def plotter() -> pv.Plotter:
    pl = pv.Plotter(off_screen=True, window_size=(W, H))
    pl.disable_anti_aliasing()  # PyVista's default MSAA would blend edges oit draws aliased
    pl.set_background(BACKGROUND)
    return pl


def opaque_plotter(smooth: bool, lighting: bool, parallel: bool) -> pv.Plotter:
    pl = plotter()
    sphere = pv.Sphere(radius=0.6, center=(0.3, 0.0, 0.0))
    sphere["height"] = sphere.points[:, 2]
    pl.add_mesh(sphere, scalars="height", cmap="viridis", interpolate_before_map=False, show_scalar_bar=False,
                smooth_shading=smooth, lighting=lighting)
    cube = pv.Cube(center=(-0.5, 0.2, -0.3))
    cube.cell_data["face"] = np.arange(cube.n_cells, dtype=float)
    pl.add_mesh(cube, scalars="face", cmap="plasma", show_scalar_bar=False, lighting=lighting)  # colors per cell
    pl.add_mesh(pv.Plane(center=(0, -0.7, 0), i_size=2.5, j_size=2.0), color="tan", lighting=lighting)
    pl.camera_position = [(2.5, 1.5, 3.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
    if parallel:
        pl.enable_parallel_projection()
    return pl


@needs_vtk_context
@pytest.mark.parametrize(("smooth", "lighting", "parallel"),
                         [(False, True, False), (True, True, False), (False, False, True), (True, True, True)])
def test_an_opaque_plotter_matches_pyvistas_screenshot(smooth, lighting, parallel):
    """Scalars through a lookup table (per point and per cell), an actor color, the light kit
    (flat and smooth), the camera (perspective and parallel) and the background: oit's frame,
    as 8-bit values, within one step of PyVista's screenshot on every pixel, edges included."""
    pl = opaque_plotter(smooth, lighting, parallel)
    ours = opv.screenshot(pl).astype(np.int64)
    theirs = pl.screenshot().astype(np.int64)
    pl.close()
    assert ours.shape == theirs.shape == (H, W, 3)
    assert np.abs(ours - theirs).max() <= 1
    # It means something: the meshes cover much of the frame, in many colors.
    covered = np.abs(theirs - np.rint(np.array(BACKGROUND) * 255)).max(-1) > 2
    assert 0.3 < covered.mean() < 0.95 and len(np.unique(theirs[covered], axis=0)) > 50


def translucent_plotter() -> pv.Plotter:
    """Three translucent unlit layers crossing one another, one with per-point opacity."""
    pl = plotter()
    for k, color in enumerate(("red", "green", "blue")):
        plane = pv.Plane(center=(0.1 * k, 0.05 * k, -0.3 * k), direction=(0.2 * (k - 1), 0.1, 1.0), i_size=1.6, j_size=1.2,
                         i_resolution=4, j_resolution=4)
        pl.add_mesh(plane, color=color, opacity=0.5, lighting=False)
    sphere = pv.Sphere(radius=0.5, center=(0.1, 0.0, -0.2), theta_resolution=12, phi_resolution=12)
    sphere["x"] = sphere.points[:, 0]
    pl.add_mesh(sphere, scalars="x", cmap="viridis", opacity=np.linspace(0.2, 0.8, sphere.n_points), lighting=False,
                show_scalar_bar=False, interpolate_before_map=False)
    pl.camera_position = [(0.4, 0.3, 3.0), (0.1, 0.0, -0.2), (0.0, 1.0, 0.0)]
    return pl


def test_a_translucent_plotter_is_exact():
    """The A-buffer of the plotter's scene equals the float64 reference of the same scene (all
    but ambiguous pixels, to float32 compositing); no OpenGL context is needed for this."""
    pl = translucent_plotter()
    scene, camera, background = opv.scene(pl)
    frame = opv.render(pl)
    assert frame.stats["max_depth_complexity"] >= 4
    exact, ambiguous = oit.reference(scene, camera, W, H, background, return_mask=True)
    error = np.abs(frame.image[..., :3] - exact[..., :3]).max(-1)
    assert error[~ambiguous].max() <= 1e-5 and ambiguous.mean() < 0.1
    assert scene.primitives() == ["triangles"] * 4
    assert sum(not m["opaque"] for m in scene.materials) == 4
    alphas = scene.materials[3]
    assert alphas["alpha_min"] == pytest.approx(0.2, abs=0.01) and alphas["alpha_max"] == pytest.approx(0.8, abs=0.01)
    pl.close()


@needs_vtk_context
def test_pyvistas_own_blending_of_the_translucent_plotter_is_not():
    """PyVista's default translucent pass (VTK's weighted average, no depth peeling) misses the
    exact composite by many steps, where oit's A-buffer is exact (the test above)."""
    pl = translucent_plotter()
    ours = opv.screenshot(pl).astype(np.int64)
    theirs = pl.screenshot().astype(np.int64)
    pl.close()
    difference = np.abs(ours - theirs).max(-1)
    assert difference.max() > 20 and (difference > 4).mean() > 0.05


@needs_vtk_context
def test_points_and_lines_are_drawn():
    """A point cloud (vertex cells) as particles and a polyline and a wireframe as strands, in
    their colors, where PyVista draws them (VTK's pixel sizes taken at the focal distance)."""
    pl = plotter()
    rng = np.random.default_rng(3)
    cloud = pv.PolyData(rng.uniform(-0.6, 0.6, (40, 3)))
    pl.add_mesh(cloud, color="yellow", point_size=6, lighting=False)
    t = np.linspace(0, 2 * np.pi, 50)
    helix = pv.lines_from_points(np.c_[0.8 * np.cos(t), 0.5 * np.sin(t), 0.1 * t - 0.3])
    pl.add_mesh(helix, color="red", line_width=3, lighting=False)
    pl.add_mesh(pv.Cube(center=(0, 0, -0.5), x_length=0.6, y_length=0.6, z_length=0.6), color="white", style="wireframe",
                line_width=2, lighting=False)
    pl.camera_position = [(0.0, 0.0, 3.5), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
    scene, _, _ = opv.scene(pl)
    assert scene.primitives() == ["particles", "strands", "strands"]
    ours = opv.screenshot(pl).astype(np.int64)
    theirs = pl.screenshot().astype(np.int64)
    pl.close()
    for rgb in ((255, 255, 0), (255, 0, 0), (255, 255, 255)):
        mine, vtk = (np.abs(image - rgb).max(-1) <= 1 for image in (ours, theirs))
        assert mine.sum() > 10 and vtk.sum() > 10
        # Mostly the same pixels (sizes and ends differ a little: discs and ribbons against
        # VTK's squares and lines).
        assert (mine & vtk).sum() > 0.4 * min(mine.sum(), vtk.sum())


def test_what_is_missing_is_said():
    assert opv.pyvista_missing() is None
