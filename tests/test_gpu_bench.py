"""The GPU bench (issue 40, scripts/gpu-bench.sh, oit.bench.gpu) run here with --small, so that it
cannot rot before a GPU runs it: every part, the results files, the refusal of a software adapter
without --small, and the prepared folder's size when scripts/gpu-prepare.sh has been run."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest

import oit
from oit import peers

ROOT = Path(__file__).resolve().parents[1]
BENCH = ROOT / "scripts" / "gpu-bench.sh"
PREPARED = ROOT / ".gpu"
PARTS = ["defaults", "hair", "sweeps", "claims", "floor"]

pytestmark = pytest.mark.skipif(not BENCH.exists(), reason="scripts/gpu-bench.sh is not here: run from a checkout")


def _software_adapter() -> bool:
    info = oit.Renderer(1, 1).adapter_info
    return info["device_type"] == "Cpu"


def test_small_run_writes_every_part(tmp_path: Path) -> None:
    # The preparation needs the network (pip download, apt-get download), so the bench runs on
    # the installed package: OIT_GPU_PREP points the script at a folder with no wheels.
    env = dict(os.environ, PYTHON=sys.executable, TMPDIR=str(tmp_path), OIT_GPU_PREP=str(tmp_path / "unprepared"))
    out = tmp_path / "out"
    t0 = time.perf_counter()
    r = subprocess.run(["bash", str(BENCH), "--small", str(out)], cwd=ROOT, env=env, capture_output=True, text=True,
                       timeout=240)
    seconds = time.perf_counter() - t0
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-4000:]
    assert "adapter: " in r.stdout and "driver: " in r.stdout
    assert "[defaults 1/" in r.stdout  # progress, a line a row
    data = json.loads((out / "gpu.json").read_text())
    parts = {p["name"]: p for p in data["parts"]}
    assert list(parts) == PARTS
    assert data["environment"]["small"] is True and data["environment"]["adapter"]
    for name in PARTS[:3]:
        p = parts[name]
        assert p["status"] == "done" or p["status"].startswith("stopped at its time limit"), (name, p["status"])
        ok = [r for r in p["rows"] if r["status"] == "ok"]
        assert ok, f"{name}: no row measured"
        assert all(r["gpu_ms"] is None or r["gpu_ms"] > 0 for r in ok)
        assert all(r["mean_err"] >= 0 and math.isfinite(r["mean_err"]) for r in ok)
        # A stopped part stops between rows: it counts what it measured.
        assert p["done"] <= p["total"] and p["elapsed_s"] <= p["limit_s"] + 30
    assert any(r["method"] == "abuffer" and r["mean_err"] == 0 for r in parts["defaults"]["rows"])
    if parts["claims"]["rows"]:
        assert parts["claims"]["rows"][0]["verdict"]
    if peers.pygfx_missing():
        assert parts["floor"]["status"].startswith("skipped")
    else:
        assert parts["floor"]["status"] == "done" or parts["floor"]["status"].startswith("stopped")
    md = (out / "gpu.md").read_text()
    assert md.startswith(f"# oit on {data['environment']['adapter']}")
    assert all(f"## {name}:" in md for name in PARTS)
    # The small run's limits add up to 55 s; the interpreter's start and the scenes come on top.
    assert seconds < 120, f"--small took {seconds:.0f} s"


@pytest.mark.skipif(not _software_adapter(), reason="this machine has a hardware adapter: nothing to refuse")
def test_refuses_a_software_adapter(tmp_path: Path) -> None:
    r = subprocess.run([sys.executable, "-m", "oit", "bench", "--gpu", "--out", str(tmp_path)], capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 3
    assert "no hardware adapter" in r.stderr
    assert not (tmp_path / "gpu.md").exists()


@pytest.mark.skipif(not PREPARED.is_dir(), reason="no .gpu/: scripts/gpu-prepare.sh downloads wheels and Debian packages, "
                    "so it needs the network and tests do not run it; the bench itself is tested on the installed package")
def test_prepared_folder_fits() -> None:
    total = sum(f.stat().st_size for f in PREPARED.rglob("*") if f.is_file())
    assert total < 60 * 2 ** 20, f".gpu/ is {total / 2 ** 20:.1f} MiB: it must travel within 60 MiB"
    wheels = sorted((PREPARED / "wheels").glob("oit-*-abi3-*.whl"))
    assert len(wheels) == 1
    with zipfile.ZipFile(wheels[0]) as z:
        assert "oit/bench/gpu.py" in z.namelist(), f"{wheels[0].name} predates the GPU bench: rerun scripts/gpu-prepare.sh"
    assert list((PREPARED / "vulkan").rglob("libvulkan.so.1*"))
