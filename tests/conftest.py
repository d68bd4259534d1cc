"""Shared fixtures: cached renderers, cameras and the optional mesh data; the scene
builders are in scenes.py (pytest advises against importing conftest).

The GPU in CI is lavapipe (a software rasterizer), so frames stay small (16 to 64 pixels a
side) and renderers are cached for the session: one device, one renderer per size.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Callable

import pytest

import oit
from oit.scenes import shared_data_dir
from scenes import IDENTITY, PERSPECTIVE

REPO = Path(__file__).resolve().parent.parent


# ---- the installed package should be the one in python/oit


def _source_drift() -> tuple[list[str], list[str]]:
    """Modules of python/oit missing from the imported package, and those that differ."""
    source = REPO / "python" / "oit"
    installed = Path(oit.__file__).parent
    missing, differ = [], []
    for f in sorted(source.rglob("*.py")):
        name = f.relative_to(source).as_posix()
        other = installed / name
        if not other.exists():
            missing.append(name)
        elif hashlib.sha256(f.read_bytes()).digest() != hashlib.sha256(other.read_bytes()).digest():
            differ.append(name)
    return missing, differ


def pytest_report_header(config: pytest.Config) -> list[str]:
    lines = [f"oit from {Path(oit.__file__).parent}"]
    missing, differ = _source_drift()
    drift = ([f"missing: {', '.join(missing)}"] if missing else []) + ([f"changed: {', '.join(differ)}"] if differ else [])
    if drift:
        lines.append(f"warning: the imported oit differs from python/oit ({'; '.join(drift)}) and the tests run "
                     "the imported copy: rebuild it with `make setup` (scripts/setup.sh)")
    return lines


# ---- renderers and cameras


@pytest.fixture(scope="session")
def renderer() -> Callable[..., oit.Renderer]:
    """renderer(width, height, max_binding_bytes=None): one cached oit.Renderer per arguments."""
    cache: dict[tuple[int, int, int | None], oit.Renderer] = {}

    def get(width: int, height: int, max_binding_bytes: int | None = None) -> oit.Renderer:
        key = (width, height, max_binding_bytes)
        if key not in cache:
            cache[key] = oit.Renderer(width, height, max_binding_bytes=max_binding_bytes)
        return cache[key]

    return get


@pytest.fixture(scope="session")
def identity_camera() -> oit.Camera:
    """x, y map to NDC and z to depth: geometry is placed on screen and in depth directly."""
    return IDENTITY


@pytest.fixture(scope="session")
def perspective_camera() -> oit.Camera:
    return PERSPECTIVE


@pytest.fixture
def shared_data() -> Path:
    """The optional mesh folder (meshes such as suzanne.obj), found as the library finds it
    (oit.scenes.shared_data_dir); the test is skipped when it is absent."""
    found = shared_data_dir()
    if found is None:
        pytest.skip("optional mesh data not found ($OIT_DATA, or a shared/data folder above the working directory): "
                    "tests that need it are skipped")
    return found


@pytest.fixture
def box_obj(tmp_path: Path) -> Path:
    """A 1 x 0.6 x 0.4 box written as OBJ by trimesh (the command-line tests' file)."""
    import trimesh

    path = tmp_path / "box.obj"
    trimesh.creation.box(extents=(1.0, 0.6, 0.4)).export(path)
    return path
