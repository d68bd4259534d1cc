"""Every entry point loads alike and fails alike: Scene.from_file, `python -m oit render` and
`compare`, and the viewer report the same warnings and refuse the same files with the same
message (ValueError or FileNotFoundError naming the file, and the missing file it refers to);
no public call can raise PanicException (crates/oit-py/src/guard.rs)."""

from __future__ import annotations

import contextlib
import copy
import json
import os
import re
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest

import oit
from oit import _oit, cli
from oit.bench.load import glb_pack, gltf_doc, grid
from test_viewer import VIEWER, needs_viewer

# ---- the panic guard


def _native_entries() -> set[str]:
    """Every callable the native module exposes, as the guard names them ("Scene.add_mesh",
    "Scene.new" for the constructor, "methods")."""
    names = set()
    for name, obj in vars(_oit).items():
        if isinstance(obj, type) and obj.__module__ == "oit._oit":
            for member in vars(obj):
                if member == "__new__":
                    names.add(f"{name}.new")
                elif not member.startswith("__"):
                    names.add(f"{name}.{member}")
        elif callable(obj) and not isinstance(obj, type):
            names.add(name)
    return names


def test_every_native_entry_runs_under_the_panic_guard():
    """Python reaches Rust only through `oit._oit`; every function, method, getter and
    constructor there is wrapped by `guarded!`, which lists it in `_GUARDED`."""
    entries = _native_entries()
    assert {"Scene.new", "Scene.add_mesh", "Renderer.render", "load_file", "reference"} <= entries
    assert entries - set(_oit._GUARDED) == set()


def test_a_panic_arrives_as_a_runtime_error_that_says_it_is_a_bug():
    with pytest.raises(RuntimeError, match="bug in oit") as e:
        _oit._panic_for_test()
    assert "_panic_for_test" in str(e.value) and "a panic on purpose" in str(e.value)
    assert type(e.value) is RuntimeError  # not pyo3_runtime.PanicException (a BaseException)


# ---- files


def _glb(path: Path, edit=None) -> Path:
    doc, blob = gltf_doc(*grid(8))
    if edit:
        edit(doc)
    path.write_bytes(glb_pack(doc, blob))
    return path


def _gltf_external(tmp_path: Path, bin_uri="mesh.bin", image_uri=None) -> Path:
    """A .gltf with its buffer in `bin_uri` (written as mesh.bin) and maybe an image."""
    doc, blob = gltf_doc(*grid(8))
    (tmp_path / "mesh.bin").write_bytes(blob)
    doc["buffers"][0]["uri"] = bin_uri
    if image_uri:
        doc["images"], doc["textures"] = [{"uri": image_uri}], [{"source": 0}]
        doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    path = tmp_path / "ext.gltf"
    path.write_text(json.dumps(doc))
    return path


def _with_warnings(doc: dict) -> None:
    """Features oit reads past without drawing: an animation (with a channel that has no target
    node, as the validator allows) and an unknown used extension."""
    doc["animations"] = [{"channels": [{"sampler": 0, "target": {"path": "translation"}}],
                          "samplers": [{"input": 0, "output": 0}]}]
    doc["extensionsUsed"] = ["EXT_oit_test_unknown"]


def _warnings_of_from_file(path: Path) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        oit.Scene.from_file(path)
    return [str(w.message) for w in caught if issubclass(w.category, oit.OitLoadWarning)]


# ---- warnings


def test_from_file_warns_once_a_feature_naming_the_file(tmp_path):
    path = _glb(tmp_path / "anim.glb", _with_warnings)
    said = _warnings_of_from_file(path)
    assert said, "an animation is read past with a warning"
    assert all(m.startswith(f"{path}: ") for m in said), said
    assert len(said) == len(set(said)), f"said twice: {said}"
    assert issubclass(oit.OitLoadWarning, UserWarning)


def test_the_command_line_prints_the_same_warnings_a_line_each(tmp_path, capsys):
    path = _glb(tmp_path / "anim.glb", _with_warnings)
    said = _warnings_of_from_file(path)
    assert cli.main(["render", str(path), "--size", "32", "32", "-o", str(tmp_path / "a.png")]) == 0
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if ": warning: " in line]
    assert [line.split(": warning: ", 1)[1] for line in lines] == said, err
    assert all(line.startswith("python -m oit render: warning: ") for line in lines), err


def test_compare_prints_the_same_warnings(tmp_path, capsys):
    path = _glb(tmp_path / "anim.glb", _with_warnings)
    said = _warnings_of_from_file(path)
    code = cli.main(["compare", str(path), "--methods", "abuffer", "--size", "32", "32", "--out", str(tmp_path / "cmp"),
                     "--no-plots"])
    err = capsys.readouterr().err
    assert code == 0, err
    assert [line.split(": warning: ", 1)[1] for line in err.splitlines() if ": warning: " in line] == said, err


# ---- refusals and missing files


def test_a_missing_buffer_is_file_not_found_naming_it(tmp_path):
    path = _gltf_external(tmp_path, bin_uri="gone.bin")
    with pytest.raises(FileNotFoundError, match=re.escape("gone.bin")) as e:
        oit.Scene.from_file(path)
    assert "ext.gltf" in str(e.value) and "buffers[0]" in str(e.value)


def test_a_missing_image_is_file_not_found_naming_it(tmp_path):
    path = _gltf_external(tmp_path, image_uri="gone.png")
    with pytest.raises(FileNotFoundError, match=re.escape("gone.png")) as e:
        oit.Scene.from_file(path)
    assert "images[0]" in str(e.value)


def test_a_missing_obj_texture_is_file_not_found_naming_it(tmp_path):
    (tmp_path / "t.mtl").write_text("newmtl m\nKd 1 1 1\nmap_Kd gone.png\n")
    path = tmp_path / "t.obj"
    path.write_text("mtllib t.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\n")
    with pytest.raises(FileNotFoundError, match=re.escape("gone.png")):
        oit.Scene.from_file(path)


def test_a_broken_file_says_what_is_wrong_not_that_it_has_no_triangles(tmp_path):
    """Float indices: the accessor and the rule, not 'has no triangles'."""

    def float_indices(doc):
        doc["accessors"][1]["componentType"] = 5126

    with pytest.raises(ValueError) as e:
        oit.Scene.from_file(_glb(tmp_path / "five.glb", float_indices))
    assert "five.glb" in str(e.value) and "accessors[1]" in str(e.value), e.value
    assert "no triangles" not in str(e.value)


def test_a_file_without_anything_to_draw_says_so(tmp_path):
    path = tmp_path / "empty.obj"
    path.write_text("# only a comment and a group\ng nothing\n")
    with pytest.raises(ValueError, match=re.escape("empty.obj")) as e:
        oit.Scene.from_file(path)
    assert "triangles" in str(e.value) or "nothing" in str(e.value)


@pytest.mark.parametrize("case", ["missing-bin", "invalid"])
def test_the_command_line_refuses_with_the_same_message(tmp_path, capsys, case):
    if case == "missing-bin":
        path, kind = _gltf_external(tmp_path, bin_uri="gone.bin"), FileNotFoundError
    else:
        path, kind = _glb(tmp_path / "five.glb", lambda d: d["accessors"][1].update(componentType=5126)), ValueError
    with pytest.raises(kind) as e:
        oit.Scene.from_file(path)
    for command in ("render", "compare"):
        assert cli.main([command, str(path)]) == cli.EXIT_USAGE
        err = capsys.readouterr().err
        assert str(e.value) in err and "Traceback" not in err, err


# ---- the viewer




def _run_viewer(args, tmp_path, display=False):
    env = {k: v for k, v in os.environ.items() if display or k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    return subprocess.run([str(VIEWER), *args], capture_output=True, text=True, timeout=120, env=env, cwd=tmp_path)


@needs_viewer
@pytest.mark.parametrize("screenshot", [False, True], ids=["window", "screenshot"])
def test_the_viewer_exits_non_zero_with_the_message_on_a_refused_file(tmp_path, screenshot):
    path = _gltf_external(tmp_path, bin_uri="gone.bin")
    with pytest.raises(FileNotFoundError) as e:
        oit.Scene.from_file(path)
    shot = tmp_path / "shot.png"
    done = _run_viewer([str(path), *(["--screenshot", str(shot)] if screenshot else [])], tmp_path)
    assert done.returncode != 0
    assert str(e.value) in done.stderr, done.stderr
    assert not shot.exists()


@needs_viewer
def test_the_viewer_prints_the_same_warnings(tmp_path):
    """Loading comes before the window: without a display it fails after saying them."""
    path = _glb(tmp_path / "anim.glb", _with_warnings)
    said = _warnings_of_from_file(path)
    done = _run_viewer([str(path)], tmp_path)
    lines = [line.split(": warning: ", 1)[1] for line in done.stderr.splitlines() if ": warning: " in line]
    assert lines == said, done.stderr


def test_every_entry_point_reads_the_same_scene(tmp_path):
    """Scene.from_file and the command line's loader (`views.load_for_viewing`) give the same
    triangles and materials."""
    from argparse import Namespace

    from oit.views import load_for_viewing

    path = _glb(tmp_path / "same.glb")
    direct = oit.Scene.from_file(path, specular=0.25)
    via_cli = load_for_viewing(Namespace(file=str(path), alpha=None, shading="smooth", specular=0.25))
    assert direct.triangle_count == via_cli.triangle_count and direct.mesh_names == via_cli.mesh_names
    assert [m["opaque"] for m in direct.materials] == [m["opaque"] for m in via_cli.materials]
    np.testing.assert_allclose(np.array(direct.bounds), np.array(via_cli.bounds))


def test_no_public_call_raises_panic_exception_on_bad_arguments():
    """A sweep of the public API with wrong arguments: only ordinary exceptions come out."""
    bad = [None, -1, 2**70, float("nan"), "x", [], np.zeros((0, 3), np.float32), np.zeros((2, 2, 2))]
    scene = oit.Scene()
    calls = [lambda b: scene.add_mesh(b, b, b), lambda b: scene.add_light(b), lambda b: oit.memory_bytes(b, 4, 4),
             lambda b: oit.Renderer(b, b), lambda b: scene.set_mesh_alpha(b, b), lambda b: oit.Camera(b),
             lambda b: oit.Scene.from_file(b)]
    for call in calls:
        for b in bad:
            # Any ordinary exception is allowed here; a BaseException (PanicException) fails the test.
            with contextlib.suppress(Exception):
                call(copy.copy(b))
