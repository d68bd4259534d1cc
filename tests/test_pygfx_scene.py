"""`oit.pygfx.render`: a pygfx scene graph and camera rendered by oit. Opaque pixels within one
8-bit step of pygfx's own offscreen render (driven as oit.peers drives it: rgba8 sRGB target,
pixel_scale 1, ppaa off); translucent ones exact against oit.reference where pygfx's blending
is not; points and lines drawn where pygfx draws them."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from oit.imageio import linear_to_srgb
from oit.peers import pygfx_missing

if pygfx_missing():
    pytest.skip(pygfx_missing(), allow_module_level=True)

import pygfx as gfx

from oit import pygfx as opg

W, H = 64, 48


def quad(z: float, color: str, size: float = 1.0, **material) -> gfx.Mesh:
    pos = np.array([[-size, -size, z], [size, -size, z], [size, size, z], [-size, size, z]], np.float32)
    geometry = gfx.Geometry(positions=pos, indices=np.array([[0, 1, 2], [0, 2, 3]], np.uint32))
    return gfx.Mesh(geometry, gfx.MeshBasicMaterial(color=color, **material))


def camera(kind: str = "perspective") -> gfx.Camera:
    cam = gfx.PerspectiveCamera(50, W / H) if kind == "perspective" else gfx.OrthographicCamera(5, 4)
    cam.local.position = (0.3, 0.2, 5)
    cam.look_at((0, 0, 0))
    return cam


def pygfx_render(scene: gfx.Scene, cam: gfx.Camera) -> np.ndarray:
    """pygfx's own frame, 8-bit sRGB RGB (h, w, 3)."""
    target = gfx.Texture(dim=2, size=(W, H, 1), format="rgba8unorm")
    renderer = gfx.WgpuRenderer(target, pixel_scale=1, ppaa="none")
    renderer.render(scene, cam)
    return renderer.snapshot()[..., :3].astype(int)


def srgb8(image: np.ndarray) -> np.ndarray:
    return np.rint(linear_to_srgb(np.clip(image[..., :3], 0, 1)) * 255).astype(int)


def opaque_scene() -> gfx.Scene:
    scene = gfx.Scene()
    scene.add(gfx.Background.from_color("#204060"))
    group = gfx.Group()
    group.local.position = (-0.5, 0, 0)
    group.local.scale = (1.2, 1.0, 1.0)
    group.add(quad(0, "#ff8000", alpha_mode="solid"))
    scene.add(group)
    pos = np.array([[0, 0, 0.5], [1.5, 0, 0.5], [0.5, 1.2, 0.5]], np.float32)
    colors = np.array([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1]], np.float32)
    tri = gfx.Mesh(gfx.Geometry(positions=pos, indices=np.array([[0, 1, 2]], np.uint32), colors=colors),
                   gfx.MeshBasicMaterial(color_mode="vertex", alpha_mode="solid"))
    tri.local.rotation = (0, 0, 0.1, 0.995)
    scene.add(tri)
    return scene


@pytest.mark.parametrize("kind", ["perspective", "orthographic"])
def test_an_opaque_scene_matches_pygfx_within_one_step(kind):
    scene, cam = opaque_scene(), camera(kind)
    theirs = pygfx_render(scene, cam)
    ours = srgb8(opg.render(scene, cam, size=(W, H)).image)
    oscene, ocam, bg = opg.to_oit(scene, cam, (W, H))
    _, ambiguous = oit.reference(oscene, ocam, W, H, bg, return_mask=True)  # pixel centers on an edge
    diff = np.abs(ours - theirs).max(-1)
    assert diff[~ambiguous].max() <= 1, f"{(diff[~ambiguous] > 1).sum()} pixels past one 8-bit step"
    assert len(np.unique(ours.reshape(-1, 3), axis=0)) > 10, "the quad, the gradient and the background are there"


def translucent_scene() -> gfx.Scene:
    """Two quads crossing each other at alpha 0.5: no order of the objects is right everywhere."""
    scene = gfx.Scene()
    scene.add(gfx.Background.from_color("#ffffff"))
    a = quad(0, "#ff0000", alpha_mode="blend", opacity=0.5)
    b = quad(0, "#0000ff", alpha_mode="blend", opacity=0.5)
    a.local.rotation = (0, 0.38, 0, 0.92)  # about +45 degrees around y
    b.local.rotation = (0, -0.38, 0, 0.92)
    scene.add(a, b)
    return scene


def test_a_translucent_scene_is_exact_where_pygfx_blending_is_not():
    scene, cam = translucent_scene(), camera()
    frame = opg.render(scene, cam, size=(W, H))
    oscene, ocam, bg = opg.to_oit(scene, cam, (W, H))
    ref, ambiguous = oit.reference(oscene, ocam, W, H, bg, return_mask=True)
    ok = ~ambiguous
    assert np.abs(frame.image[..., :3] - ref[..., :3])[ok].max() < 1e-5
    theirs = pygfx_render(scene, cam)
    err = np.abs(theirs - srgb8(ref)).max(-1)[ok]
    assert err.max() > 20, "pygfx sorts by object: on one side of the crossing the order is wrong"


def test_points_and_lines_are_drawn_where_pygfx_draws_them():
    scene = gfx.Scene()
    pts = np.array([[-1.5, 1, 0], [1.5, 1, 0]], np.float32)
    scene.add(gfx.Points(gfx.Geometry(positions=pts), gfx.PointsMaterial(size=8, color="#00ff00", alpha_mode="solid")))
    line = np.array([[-1.5, -1, 0], [1.5, -1, 0], [np.nan, 0, 0], [-1, -0.5, 0], [1, -0.5, 0]], np.float32)
    scene.add(gfx.Line(gfx.Geometry(positions=line), gfx.LineMaterial(thickness=4, color="#ff0000", alpha_mode="blend",
                                                                     opacity=0.6)))
    cam = camera()
    ours = srgb8(opg.render(scene, cam, size=(W, H)).image)
    theirs = pygfx_render(scene, cam)
    oscene, _, _ = opg.to_oit(scene, cam, (W, H))
    assert oscene.primitives() == ["particles", "strands"]
    for image in (ours, theirs):
        green = (image[..., 1] > 200) & (image[..., 0] < 50)
        red = (image[..., 0] > 100) & (image[..., 1] < 50)
        assert green.sum() >= 2 * 20 and red.sum() >= 2 * 30
    covered = lambda im: (im.max(-1) > 30)  # noqa: E731
    both = covered(ours) & covered(theirs)
    assert both.sum() >= 0.7 * covered(theirs).sum(), "the same pixels are drawn"


def test_modes_oit_cannot_composite_are_refused():
    scene = gfx.Scene()
    scene.add(quad(0, "#ff0000", alpha_mode="add"))
    with pytest.raises(ValueError, match="alpha_mode 'add' is not compositing"):
        opg.to_oit(scene, camera(), (W, H))


def test_show_draws_the_frame_in_an_offscreen_canvas():
    from rendercanvas.offscreen import RenderCanvas

    frame = opg.render(opaque_scene(), camera(), size=(W, H))
    canvas = opg.show(frame, RenderCanvas(size=(W, H), pixel_ratio=1))
    shown = np.asarray(canvas.draw())[..., :3].astype(int)
    assert shown.shape == (H, W, 3)
    assert np.abs(shown - srgb8(frame.image)).max() <= 1
