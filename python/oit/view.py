"""`python -m oit view`: starts the viewer (crates/oit-viewer), a separate binary built with
`make viewer`. Built-in scenes are exported to a scene file (`oit.scenefile`) that it reads."""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from collections.abc import Sequence
from pathlib import Path

BUILD_HELP = ("build it with `make viewer` (cargo build --release -p oit-viewer) in the oit repository, "
              "or put oit-viewer on PATH")


def find_viewer() -> Path:
    """The viewer binary: $OIT_VIEWER, $CARGO_TARGET_DIR/release, ~/.cache/oit/target/release
    (where `make` builds), ./target/release, then PATH."""
    names = []
    if os.environ.get("OIT_VIEWER"):
        names.append(Path(os.environ["OIT_VIEWER"]))
    if os.environ.get("CARGO_TARGET_DIR"):
        names.append(Path(os.environ["CARGO_TARGET_DIR"]) / "release" / "oit-viewer")
    names += [Path.home() / ".cache" / "oit" / "target" / "release" / "oit-viewer",
              Path("target") / "release" / "oit-viewer"]
    for p in names:
        if p.is_file() and os.access(p, os.X_OK):
            return p
    on_path = shutil.which("oit-viewer")
    if on_path:
        return Path(on_path)
    looked = ", ".join(str(p) for p in names)
    raise RuntimeError(f"the viewer binary oit-viewer was not found (looked in {looked} and PATH): {BUILD_HELP}")


def export_scene(name: str, path: str) -> None:
    """Builds the built-in scene `name` (oit.scenes) and writes it as a scene file."""
    from . import scenes
    from .scenefile import save_scene

    if name not in scenes.SCENES:
        raise ValueError(f"unknown scene '{name}'; built-in scenes: {', '.join(scenes.SCENES)}")
    save_scene(scenes.SCENES[name](), path)


def viewer_command(files: Sequence[str], extra: Sequence[str] = ()) -> list[str]:
    return [str(find_viewer()), *files, *extra]


def run(files: Sequence[str], scene: str | None = None, extra: Sequence[str] = ()) -> int:
    """Runs the viewer on `files` and the built-in `scene` (exported to a temporary file);
    returns its exit status."""
    for f in files:
        if not os.path.isfile(f):
            raise ValueError(f"no such file: {f}")
    if scene is None and not files:
        raise ValueError("name a file to open or a built-in scene with --scene")
    command = viewer_command(files, extra)  # fails before exporting when the binary is missing
    with tempfile.TemporaryDirectory(prefix="oit-view-") as tmp:
        if scene is not None:
            path = os.path.join(tmp, f"{scene}.oitscene")
            export_scene(scene, path)
            command.insert(1, path)
        return subprocess.call(command)
