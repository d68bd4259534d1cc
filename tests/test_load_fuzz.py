"""The loader never crashes, hangs or runs away with memory on any bytes: small files of every
format (oit.bench.load.seed_files, and tests/files.py's) mutated from a fixed seed (truncation,
bit flips, huge counts, odd numbers, glTF fields deleted or of another type, cycles, missing
files), each loaded by Scene.from_file in this process, must give a scene, ValueError or OSError.
`python -m oit bench --fuzz-load --seconds N` runs the same for longer."""

from __future__ import annotations

import json
import random
import re
import resource
import struct
import subprocess
import sys
import time
import warnings

import pytest

import files
import oit
from oit.bench import load as bench_load
from oit.bench.load import FUZZ_RSS_GROWTH_MB, fuzz_load, glb_pack, gltf_doc, grid, mutate, seed_files

# Well under a minute in CI: the run stops at whichever comes first.
FUZZ_SECONDS = 20.0
FUZZ_CASES = 5000


def test_the_seed_files_load():
    """Mutations start from files that load (else they test the refusal of a broken seed)."""
    for path in seed_files(_tmp() / "seeds"):
        if path.suffix == ".mtl":
            path = path.with_name("seed-m.obj")
            path.with_name("fuzz-m.mtl").write_bytes((path.parent / "seed.mtl").read_bytes())
        scene = oit.Scene.from_file(path)
        assert scene.triangle_count > 0, path


def test_mutated_files_load_or_raise_value_or_os_error(tmp_path):
    """The bench's fuzz run, short, in a fresh interpreter: loads run in it one after another,
    each timed (past FUZZ_CASE_SECONDS the run ends with a traceback: a hang), and its peak
    memory is its own."""
    command = [sys.executable, "-m", "oit", "bench", "--fuzz-load", "--seconds", str(FUZZ_SECONDS), "--seed", "0",
               "--fuzz-cases", str(FUZZ_CASES), "--out", str(tmp_path)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=FUZZ_SECONDS + 60)
    last = tmp_path / "fuzz-last-case.txt"
    assert done.returncode == 0, (done.stdout[-3000:] + done.stderr[-6000:]
                                  + (f"\nthe last case: {last.read_text()}" if last.exists() else ""))
    summary = done.stdout.strip().splitlines()[-1]
    cases = int(re.match(r"(\d+) mutated files", summary).group(1))
    assert cases >= 200, f"too few cases in {FUZZ_SECONDS} s: {summary}"
    # The mutations reach past the first check: some files still load, some are refused.
    assert re.search(r"loaded \d+", summary) and re.search(r"ValueError \d+", summary), summary


def test_a_short_run_in_process(tmp_path):
    report = fuzz_load(3.0, seed=7, out=tmp_path, max_cases=60)
    assert report.cases > 0 and not report.failures, "\n".join(report.failures[:20])
    assert report.slowest[0] < bench_load.FUZZ_CASE_SECONDS


def test_the_tests_own_files_mutated(tmp_path):
    """tests/files.py's writers (textures, two materials, RGBA PLY, point clouds) as seeds too."""
    made = [files.box_and_panel_glb(tmp_path / "box.glb"), files.textured_multi_node_glb(tmp_path / "tex.glb"),
            files.obj_with_dissolve(tmp_path / "glass.obj"), files.ply_rgba(tmp_path / "rgba.ply"),
            files.stl_cube(tmp_path / "cube.stl"), files.ply_points(tmp_path / "points.ply")]
    rng = random.Random(1)
    start = time.perf_counter()
    for i in range(240):
        src = made[i % len(made)]
        data, what = mutate(src.read_bytes(), src.suffix, rng)
        path = tmp_path / f"m{src.suffix}"
        if src.suffix == ".obj":
            path = src.with_name("m.obj")
        path.write_bytes(data)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", oit.OitLoadWarning)
                oit.Scene.from_file(path)
        except (ValueError, OSError):
            pass
        except BaseException as e:  # PanicException is a BaseException
            pytest.fail(f"{src.name}; {what}: {type(e).__name__}: {e}")
    assert time.perf_counter() - start < 30


def test_the_fuzzer_reports_what_is_not_allowed(tmp_path):
    """A panic (a BaseException), another exception, or a message without the file's name is a failure."""

    class FakePanic(BaseException):
        pass

    def panics(path):
        raise FakePanic("boom")

    def wrong_type(path):
        raise KeyError(path)

    def anonymous(path):
        raise ValueError("bad file")

    for load, words in ((panics, "FakePanic"), (wrong_type, "KeyError"), (anonymous, "does not name the file")):
        report = fuzz_load(5.0, seed=0, max_cases=3, load=load)
        assert len(report.failures) == 3 and words in report.failures[0], report.failures


def _tmp():
    import tempfile
    from pathlib import Path

    return Path(tempfile.mkdtemp(prefix="oit-fuzz-test-"))


def _gltf(tmp_path, doc, blob=None, name="x.glb"):
    path = tmp_path / name
    path.write_bytes(glb_pack(doc, blob) if name.endswith(".glb") else json.dumps(doc).encode())
    return path


@pytest.mark.parametrize("children", [[[1], [0]], [[0]], [[1], [2], [1]]], ids=["two-cycle", "self", "three-cycle"])
def test_nodes_in_a_cycle_are_refused_naming_a_node(tmp_path, children):
    doc, blob = gltf_doc(*grid(8))
    doc["nodes"] = [{"children": c, "mesh": 0} for c in children]
    doc["scenes"] = [{"nodes": [0]}]
    start = time.perf_counter()
    with pytest.raises(ValueError, match=r"nodes\[\d+\]") as e:
        oit.Scene.from_file(_gltf(tmp_path, doc, blob))
    assert "x.glb" in str(e.value)
    assert time.perf_counter() - start < 2


def test_a_node_with_two_parents_is_refused_naming_it(tmp_path):
    doc, blob = gltf_doc(*grid(8))
    doc["nodes"] = [{"children": [2]}, {"children": [2]}, {"mesh": 0}]
    doc["scenes"] = [{"nodes": [0, 1]}]
    with pytest.raises(ValueError, match=r"nodes\[2\]"):
        oit.Scene.from_file(_gltf(tmp_path, doc, blob))


@pytest.mark.parametrize("fmt", ["stl", "ply", "glb"])
def test_a_huge_count_is_refused_without_allocating_it(tmp_path, fmt):
    """Counts that promise gigabytes in a file of a few bytes: refused from the file's size, not
    by trying to allocate."""
    if fmt == "stl":
        data = b"\0" * 80 + struct.pack("<I", 0xFFFFFFFF) + b"\0" * 50
    elif fmt == "ply":
        data = (b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
                b"property float z\nelement face 4000000000\nproperty list uint int vertex_indices\nend_header\n" + b"\0" * 64)
    else:
        doc, blob = gltf_doc(*grid(8))
        doc["accessors"][0]["count"] = 2**31
        doc["accessors"][1]["count"] = 3 * 2**30
        data = glb_pack(doc, blob)
    path = tmp_path / f"huge.{fmt}"
    path.write_bytes(data)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    with pytest.raises(ValueError, match="huge"):
        oit.Scene.from_file(path)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024 - before < FUZZ_RSS_GROWTH_MB


def test_the_load_bench_writes_its_table(tmp_path):
    """`python -m oit bench --load`, on a small mesh: a row a format with its rate and peak memory."""
    from oit import cli

    assert cli.main(["bench", "--load", "--load-triangles", "2000", "--out", str(tmp_path)]) == 0
    table = (tmp_path / "load.md").read_text()
    rows = [line for line in table.splitlines() if line.startswith("| ") and "---" not in line][1:]
    assert [r.split("|")[1].strip() for r in rows] == ["obj", "glb", "ply", "stl"], table
    assert all("failed" not in r for r in rows), table
    n = grid(2000)[1].shape[0]
    assert all(f"{n:,}" in r for r in rows), table


@pytest.mark.parametrize("edit", ["image-without-fields", "position-accessor-missing", "indices-accessor-missing",
                                  "buffer-view-past-buffer", "scene-node-missing"])
def test_the_issues_crashers_are_refused_or_read(tmp_path, edit):
    """The two files that crashed through a panic in the glTF crate, and their neighbours:
    refused with ValueError naming the file (or read, where the specification allows it)."""
    doc, blob = gltf_doc(*grid(8))
    if edit == "image-without-fields":
        doc["images"], doc["textures"] = [{}], [{"source": 0}]
        doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    elif edit == "position-accessor-missing":
        doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 99
    elif edit == "indices-accessor-missing":
        doc["meshes"][0]["primitives"][0]["indices"] = 99
    elif edit == "buffer-view-past-buffer":
        doc["bufferViews"][1]["byteOffset"] = 10**6
    else:
        doc["scenes"][0]["nodes"] = [7]
    path = _gltf(tmp_path, doc, blob)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", oit.OitLoadWarning)
            oit.Scene.from_file(path)
    except ValueError as e:
        assert "x.glb" in str(e), e
