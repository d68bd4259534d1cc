"""Every code block of README.md runs as written: the Python blocks executed at small sizes with
stand-in arrays for the README's placeholders (positions, p2, leaf_p, ...) and small files for
its file names, the `python -m oit` command lines run at small sizes, and the Rust block found
verbatim in crates/oit-core/examples/over_opaque.rs (which `cargo test` and clippy build)."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import files
from oit.hairfile import write_hair

REPO = Path(__file__).resolve().parent.parent
README = REPO / "README.md"
EXAMPLE = REPO / "crates" / "oit-core" / "examples" / "over_opaque.rs"


def blocks(language: str) -> list[str]:
    """The README's fenced code blocks in `language`, in order."""
    return re.findall(rf"^```{language}\n(.*?)^```", README.read_text(), flags=re.S | re.M)


def small(code: str) -> str:
    """The README's frame sizes cut down for lavapipe: 512 -> 48, 256 -> 32 pixels a side."""
    return re.sub(r"\b512\b", "48", re.sub(r"\b256\b", "32", code))


def squash(text: str) -> str:
    return " ".join(text.split())


def test_the_readme_has_the_blocks_this_test_runs():
    assert len(blocks("python")) == 2 and len(blocks("rust")) == 1 and len(blocks("sh")) >= 2


def test_the_rust_block_is_the_example_s_call():
    example = squash(EXAMPLE.read_text())
    for block in blocks("rust"):
        assert squash(block) in example, "README's Rust block differs from examples/over_opaque.rs: keep them one"


def _stand_ins(folder: Path) -> dict:
    """The placeholders of the README's first Python block, and its files in `folder`."""
    rng = np.random.default_rng(0)

    def quad(z: float, rgba: tuple) -> tuple:
        p = np.array([[-1, -1, z], [1, -1, z], [1, 1, z], [-1, 1, z]], np.float32)
        return p, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), np.array(rgba, np.float32)

    positions, indices, colors = quad(0.2, (1, 0, 0, 0.5))
    p2, i2, c2 = quad(-0.5, (0.5, 0.5, 0.5, 1))
    p3, i3, c3 = quad(0.0, (0, 0, 1, 0.4))
    leaf_p, leaf_i, leaf_c = quad(0.1, (0, 1, 0, 0.6))
    points = rng.uniform(-0.5, 0.5, (12, 3)).astype(np.float32)
    files.ply_points(folder / "cloud.ply")
    write_hair(folder / "model.hair", points, [4, 4, 4], colors=(0.6, 0.4, 0.2, 0.5))
    return {
        "positions": positions, "indices": indices, "colors": colors, "p2": p2, "i2": i2, "c2": c2,
        "p3": p3, "i3": i3, "c3": c3, "n3": np.tile([0, 0, 1], (4, 1)).astype(np.float32),
        "leaf_p": leaf_p * 0.2, "leaf_i": leaf_i, "leaf_c": leaf_c, "M": np.diag([1.0, 1.0, 1.0, 1.0]),
        "transforms": np.stack([np.eye(4) + np.pad([[0, 0, 0, x]], ((0, 3), (0, 0))) for x in (-0.5, 0.5)]),
        "factors": np.array([[1, 1, 1, 1], [1, 0.5, 0.5, 0.8]]),
        "points": points, "counts": np.array([4, 4, 4]), "rgba": np.array([0.6, 0.4, 0.2, 0.5]),
        "centers": rng.uniform(-0.5, 0.5, (20, 3)),
    }


def test_the_first_python_block_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    names = _stand_ins(tmp_path)
    exec(compile(small(blocks("python")[0]), "README.md (first Python block)", "exec"), names)
    assert names["frame"].image.shape == (48, 48, 4) and names["exact"].shape[:2] == (48, 48)


def test_the_notebook_block_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    files.box_and_panel_glb(tmp_path / "scene.glb")  # untextured: lavapipe compiles textured pipelines for a minute
    names: dict = {}
    exec(compile(small(blocks("python")[1]), "README.md (notebook block)", "exec"), names)
    assert names["result"].rows and isinstance(names["result"].summary(), str)


def commands() -> list[str]:
    """The `python -m oit` lines of the README's shell blocks and inline code, except `view`
    (tests/test_viewer.py) and `bench` (make test-bench runs --quick)."""
    lines = [re.sub(r"\s+#.*", "", line).strip() for b in blocks("sh") for line in b.splitlines()]
    lines += re.findall(r"`(python -m oit [^`]+)`", README.read_text())
    keep = [c for c in lines if c.startswith("python -m oit ") and c.split()[3] not in ("view", "bench")]
    return list(dict.fromkeys(keep))


def shrink_command(line: str) -> list[str]:
    """A README command line at a small size: 32 x 32 frames, 3 orbit views, 1 compare view."""
    args = shlex.split(line)[3:]
    out, i = [], 0
    while i < len(args):
        if args[i] == "--size":
            i += 3
            continue
        if args[i] in ("--orbit", "--views"):
            out += [args[i], "3" if args[i] == "--orbit" else "1"]
            i += 2
            continue
        out.append(args[i])
        i += 1
    if out[0] in ("render", "compare"):
        out += ["--size", "32", "32"]
    return out


def test_the_readme_names_the_commands_this_test_runs():
    subcommands = {c.split()[3] for c in commands()}
    assert {"render", "compare", "methods"} <= subcommands, commands()


@pytest.mark.parametrize("line", commands())
def test_a_readme_command_runs(line, tmp_path):
    files.box_and_panel_glb(tmp_path / "scene.glb")
    files.obj_with_dissolve(tmp_path / "mesh.obj")
    files.ply_gaussians(tmp_path / "splats.ply")
    done = subprocess.run([sys.executable, "-m", "oit", *shrink_command(line)], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, f"{line}\n{done.stdout}\n{done.stderr}"
    assert "error" not in done.stderr.lower(), done.stderr
    for word in shlex.split(line):
        if word.endswith((".png", ".gif")):
            assert (tmp_path / word).is_file(), f"{line} did not write {word}"


def test_the_readme_example_command_is_a_make_target():
    text = README.read_text()
    assert "make example" in text
    makefile = (REPO / "Makefile").read_text()
    assert re.search(r"^example:", makefile, flags=re.M)
    assert "--example over_opaque" in makefile


def test_the_example_runs_without_xdg_runtime_dir(tmp_path):
    # `make test` builds the example (cargo test builds examples) into the Makefile's target directory.
    target = Path(os.environ.get("CARGO_TARGET_DIR", Path.home() / ".cache" / "oit" / "target"))
    binary = target / "release" / "examples" / "over_opaque"
    if not binary.is_file():
        pytest.skip(f"no {binary}: `make test-rust` or `make example` builds it")
    env = {k: v for k, v in os.environ.items() if k != "XDG_RUNTIME_DIR"}
    done = subprocess.run([str(binary), str(tmp_path / "o.png")], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "XDG_RUNTIME_DIR" not in done.stderr, done.stderr
    assert (tmp_path / "o.png").is_file()
