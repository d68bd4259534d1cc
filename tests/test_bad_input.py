"""Bad input fails early with the right exception type and a message that names the
problem; odd but valid input (non-contiguous arrays, empty meshes) works."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from scenes import IDENTITY

P = np.float32([[0.0, 0.0, 0.5], [1.0, 0.0, 0.5], [0.0, 1.0, 0.5]])
I = np.array([[0, 1, 2]])  # noqa: E741 - P, I, C: positions, indices, color
C = (1.0, 0.0, 0.0, 0.5)


def with_nan(a, where, value=np.nan):
    a = np.array(a, dtype=np.float64)
    a[where] = value
    return a


ADD_MESH_CASES = [
    # dtypes
    ([["a", "b", "c"]] * 3, I, C, TypeError, "positions must be a float array"),
    (np.ones((3, 3), dtype=bool), I, C, TypeError, "positions must be a float array"),
    (np.array([[0, 0, 0], [1, 0, 0], [0, 1, None]], dtype=object), I, C, TypeError, "got dtype object"),
    (P, I.astype(np.float32), C, TypeError, "indices must be an integer array"),
    (P, np.ones((1, 3), dtype=bool), C, TypeError, "indices must be an integer array"),
    (P, [["0", "1", "2"]], C, TypeError, "indices must be an integer array"),
    (P, I, "red", TypeError, "colors must be a float array"),
    # shapes
    (np.zeros((3, 2)), I, C, ValueError, "positions must have shape (n, 3), got (3, 2)"),
    (np.zeros(9), I, C, ValueError, "positions must have shape (n, 3), got (9,)"),
    (P, [[0, 1]], C, ValueError, "indices must have shape (n, 3), got (1, 2)"),
    (P, [[[0, 1, 2]]], C, ValueError, "indices must have shape (n, 3)"),
    (P, I, (1.0, 0.0, 0.0), ValueError, "colors must have shape (3, 4)"),
    (P, I, np.full((2, 4), 0.5), ValueError, "colors has 2 rows but positions has 3"),
    # values: checked once, in the core
    (with_nan(P, (0, 2)), I, C, ValueError, "positions[0] = [0.0, 0.0, NaN] is not finite"),
    (with_nan(P, (1, 0), np.inf), I, C, ValueError, "positions[1] = [inf, 0.0, 0.5] is not finite"),
    (with_nan(P, (1, 0), 1e39), I, C, ValueError, "too large for float32"),
    (P, I, (1.0, np.nan, 0.0, 0.5), ValueError, "colors[0] = [1.0, NaN, 0.0, 0.5] is outside [0, 1] (or NaN)"),
    (P, I, (1.0, 0.0, np.inf, 0.5), ValueError, "colors[0] = [1.0, 0.0, inf, 0.5] is outside [0, 1]"),
    (P, I, (1.5, 0.0, 0.0, 0.5), ValueError, "colors are straight linear RGBA in [0, 1]"),
    (P, I, (1.0, 0.0, 0.0, -0.1), ValueError, "colors are straight linear RGBA in [0, 1]"),
    (P, I, (1.0, 0.0, 0.0, 1.01), ValueError, "[1.0, 0.0, 0.0, 1.01] is outside [0, 1]"),
    (P, [[0, -1, 2]], C, ValueError, "indices has an entry -1; indices must be in [0, 3)"),
    (P, [[0, 1, 3]], C, ValueError, "indices[0] = [0, 1, 3] refers past the last vertex (3 vertices)"),
    (P, [[0, 1, 2**40]], C, ValueError, "indices must be in [0, 3)"),
]


@pytest.mark.parametrize("positions,indices,colors,error,message", ADD_MESH_CASES,
                         ids=[f"{i}-{case[4]}" for i, case in enumerate(ADD_MESH_CASES)])
def test_add_mesh_rejects(positions, indices, colors, error, message):
    scene = oit.Scene()
    with pytest.raises(error) as info:
        scene.add_mesh(positions, indices, colors)
    assert message in str(info.value)
    assert scene.mesh_count == 0


def test_opaque_must_be_a_bool():
    with pytest.raises(TypeError, match="opaque must be a bool"):
        oit.Scene().add_mesh(P, I, C, opaque="yes")


def test_set_mesh_alpha_checks_alpha_and_mesh():
    scene = oit.Scene()
    scene.add_mesh(P, I, C)
    with pytest.raises(ValueError, match=r"alpha 1.5 is outside \[0, 1\]"):
        scene.set_mesh_alpha(0, 1.5)
    with pytest.raises(ValueError, match="alpha NaN is outside"):
        scene.set_mesh_alpha(0, float("nan"))
    with pytest.raises(ValueError, match="mesh index 3 is out of range: the scene has 1 meshes"):
        scene.set_mesh_alpha(3, 0.5)


def test_non_contiguous_arrays_are_copied(renderer):
    # Every other row of a bigger array, a Fortran-ordered copy, float64 and int8 inputs:
    # all accepted, converted, and copied (later changes to the caller's arrays do nothing).
    big = np.zeros((6, 3))
    big[::2] = P
    positions = big[::2]
    indices = np.asfortranarray(I.astype(np.int8))
    colors = np.tile(np.float64(C), (3, 1))[:, ::-1][:, ::-1]
    assert not positions.flags.c_contiguous
    scene = oit.Scene()
    scene.add_mesh(positions, indices, colors)
    reference = oit.Scene()
    reference.add_mesh(P, I.astype(np.uint32), np.tile(np.float32(C), (3, 1)))
    r = renderer(16, 16)
    before = r.render(scene, IDENTITY).image
    big[:] = 7.0
    colors[:] = 0.0
    after = r.render(scene, IDENTITY).image
    assert np.array_equal(before, r.render(reference, IDENTITY).image)
    assert np.array_equal(before, after)
    assert (before[..., 3] > 0).any()


def test_empty_meshes_are_allowed(renderer):
    scene = oit.Scene()
    scene.add_mesh(np.zeros((0, 3)), [], (1.0, 0.0, 0.0, 0.5))
    scene.add_mesh(P, np.zeros((0, 3), dtype=np.int64), C)
    assert scene.mesh_count == 2 and scene.triangle_count == 0
    frame = renderer(16, 16).render(scene, IDENTITY, background=(0.5, 0.25, 0.0))
    assert np.array_equal(frame.image, np.broadcast_to(np.float32([0.5, 0.25, 0.0, 0.0]), (16, 16, 4)))


@pytest.mark.parametrize("width,height,error,message", [
    (0, 16, ValueError, "width must be positive, got 0"),
    (16, -1, ValueError, "height must be positive, got -1"),
    (16.0, 16, TypeError, "width must be an int, got float"),
    (True, 16, TypeError, "width must be an int, got bool"),
    (16, "16", TypeError, "height must be an int, got str"),
])
def test_renderer_size(width, height, error, message):
    with pytest.raises(error) as info:
        oit.Renderer(width, height)
    assert message in str(info.value)


def test_renderer_larger_than_the_adapter_allows():
    with pytest.raises(MemoryError, match="largest texture"):
        oit.Renderer(1 << 20, 1)


def test_renderer_binding_limit_too_small():
    with pytest.raises(ValueError, match="max_binding_bytes must be at least 256 bytes, got 100"):
        oit.Renderer(8, 8, max_binding_bytes=100)


def test_unknown_adapter():
    with pytest.raises(RuntimeError, match="no adapter name contains 'no-such-gpu'; available: "):
        oit.Renderer(8, 8, adapter="no-such-gpu")


@pytest.fixture
def small(renderer):
    scene = oit.Scene()
    scene.add_mesh(P, I, C)
    return renderer(8, 8), scene


def test_unknown_method_lists_methods_and_suggests(small):
    r, scene = small
    with pytest.raises(ValueError) as info:
        r.render(scene, IDENTITY, method="abufer")
    message = str(info.value)
    assert "unknown method 'abufer'" in message
    assert "did you mean 'abuffer'?" in message
    assert "valid methods: abuffer, unsorted, sorted" in message


def test_method_must_be_a_string(small):
    r, scene = small
    with pytest.raises(TypeError, match="method must be a string, got NoneType"):
        r.render(scene, IDENTITY, method=None)


def test_unknown_parameter(small):
    r, scene = small
    with pytest.raises(ValueError, match="method 'abuffer' has no parameter 'k'; its parameters: none"):
        r.render(scene, IDENTITY, method="abuffer", k=4)


@pytest.mark.parametrize("value,message", [
    (True, "parameter 'k' must be a number or a string, not a bool"),
    ([1], "parameter 'k' must be a number or a string, got list"),
])
def test_parameter_of_the_wrong_kind(small, value, message):
    r, scene = small
    with pytest.raises(ValueError) as info:
        r.render(scene, IDENTITY, k=value)
    assert message in str(info.value)


def test_parameters_are_checked_against_their_method(small):
    # Methods with parameters (listed by oit.methods()): a typo, a value out of range and
    # a value of the wrong type, each named in the message.
    r, scene = small
    with_params = [(m["name"], p) for m in oit.methods() for p in m["params"] if p["type"] == "int"]
    if not with_params:
        pytest.skip("no method has an integer parameter")
    method, p = with_params[0]
    with pytest.raises(ValueError, match=rf"has no parameter '{p['name']}x' \(did you mean '{p['name']}'\?\)"):
        r.render(scene, IDENTITY, method=method, **{p["name"] + "x": p["default"]})
    with pytest.raises(ValueError, match=f"{p['name']} = {p['max'] + 1} is out of range"):
        r.render(scene, IDENTITY, method=method, **{p["name"]: p["max"] + 1})
    with pytest.raises(ValueError, match=rf"{p['name']} must be an integer in \[{p['min']}, {p['max']}\], got the string 'four'"):
        r.render(scene, IDENTITY, method=method, **{p["name"]: "four"})


def test_method_names_are_suggested_whatever_the_case(small):
    r, scene = small
    with pytest.raises(ValueError, match=r"unknown method 'ABUFFER' \(did you mean 'abuffer'\?\)"):
        r.render(scene, IDENTITY, method="ABUFFER")


@pytest.mark.parametrize("call,error,message", [
    (lambda: oit.Camera("eye"), TypeError, "view_proj must be a 4 x 4 array of numbers"),
    (lambda: oit.Renderer(4, 4, max_binding_bytes=-5), ValueError, "max_binding_bytes must be at least 256 bytes, got -5"),
])
def test_arguments_of_the_wrong_kind_are_named(call, error, message):
    with pytest.raises(error, match=message):
        call()


def test_background_of_the_wrong_kind(small):
    r, scene = small
    with pytest.raises(ValueError, match="background must be three linear RGB values"):
        r.render(scene, IDENTITY, background="white")


def test_set_mesh_alpha_rejects_negative_mesh_indices():
    scene = oit.Scene()
    scene.add_mesh(P, I, C)
    with pytest.raises(ValueError, match="mesh index -1 is out of range: the scene has 1 meshes"):
        scene.set_mesh_alpha(-1, 0.5)


@pytest.mark.parametrize("matrix,message", [
    (np.zeros((4, 4)), "view_proj is singular"),
    (np.diag([1.0, 1.0, 0.0, 1.0]), "view_proj is singular"),
    (np.eye(3), "view_proj must be a 4 x 4 matrix, got shape (3, 3)"),
    (np.eye(4).ravel(), "view_proj must be a 4 x 4 matrix, got shape (16,)"),
    (with_nan(np.eye(4), (0, 3)), "view_proj has NaN or Inf entries"),
    (with_nan(np.eye(4), (2, 2), np.inf), "view_proj has NaN or Inf entries"),
])
def test_bad_camera_matrix(matrix, message):
    with pytest.raises(ValueError) as info:
        oit.Camera(matrix)
    assert message in str(info.value)


def test_camera_builders_reject_degenerate_volumes():
    with pytest.raises(ValueError, match="eye and target must differ"):
        oit.Camera.look_at((0, 0, 1), (0, 0, 1))
    with pytest.raises(ValueError, match="up must not be parallel"):
        oit.Camera.look_at((0, 1, 0), (0, 0, 0))
    with pytest.raises(ValueError, match="need 0 < near < far"):
        oit.Camera.look_at((0, 0, 1), (0, 0, 0), near=0.0)
    with pytest.raises(ValueError, match="non-zero extent"):
        oit.Camera.orthographic(0, 0, 0, 1, 0, 1)


def test_render_needs_a_scene_and_a_camera(small):
    r, scene = small
    with pytest.raises(TypeError, match=r"camera must be an oit\.Camera, got ndarray"):
        r.render(scene, np.eye(4))
    with pytest.raises(TypeError, match=r"scene must be an oit\.Scene, got NoneType"):
        r.render(None, IDENTITY)


@pytest.mark.parametrize("background", [(1.0, 1.0), (2.0, 0.0, 0.0), (-0.1, 0.0, 0.0), (np.nan, 0.0, 0.0), (1, 1, 1, 1)])
def test_bad_background(small, background):
    r, scene = small
    with pytest.raises(ValueError, match="background must be three linear RGB values in"):
        r.render(scene, IDENTITY, background=background)
    with pytest.raises(ValueError, match="background must be three linear RGB values in"):
        oit.reference(scene, IDENTITY, 8, 8, background=background)


def test_reference_size():
    with pytest.raises(ValueError, match=r"width and height must be in \[1, 65536\], got 0 x 16"):
        oit.reference(oit.Scene(), IDENTITY, 0, 16)
