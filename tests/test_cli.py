"""`python -m oit`: render, methods and demo write what they say; errors end cleanly."""

from __future__ import annotations

import csv
import struct
import subprocess
import sys
from pathlib import Path

import pytest

import oit
from oit import cli, scenes
from oit.bench import harness


def run_oit(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "oit", *args], cwd=cwd, capture_output=True, text=True, timeout=120)


def png_size(path: Path) -> tuple:
    """(width, height) from the PNG signature and IHDR chunk."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    length, kind = struct.unpack(">I4s", data[8:16])
    assert kind == b"IHDR" and length == 13
    return struct.unpack(">II", data[16:24])


def test_render_writes_a_png_of_the_requested_size(tmp_path, box_obj):
    out = tmp_path / "sub" / "box.png"
    done = run_oit("render", str(box_obj), "--method", "abuffer", "--alpha", "0.4", "-o", str(out),
                   "--size", "40", "24", "--background", "0", "0", "0.2", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert png_size(out) == (40, 24)
    assert "fragments" in done.stdout and "max depth complexity" in done.stdout
    assert f"wrote {out}" in done.stdout


def test_methods_lists_the_methods(tmp_path):
    done = run_oit("methods", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    names = [line.split()[0] for line in done.stdout.splitlines()[2:] if line.strip() and ":" not in line]
    assert {"abuffer", "unsorted", "sorted"} <= set(names)
    assert "abuffer: exact A-buffer" in done.stdout


def test_demo_writes_the_mosaic(tmp_path):
    out = tmp_path / "tmp" / "demo.png"
    done = run_oit("demo", "-o", str(out), "--size", "64", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    # Two rows of four 64-pixel tiles, 2-pixel gaps.
    assert png_size(out) == (4 * 64 + 3 * 2, 2 * 64 + 2)
    for method in ("abuffer", "hybrid", "sorted", "unsorted"):
        assert any(line.startswith(method) for line in done.stdout.splitlines())
    assert "abuffer vs CPU float64 reference" in done.stdout


def test_render_suzanne(tmp_path, shared_data):
    out = tmp_path / "suzanne.png"
    done = run_oit("render", str(shared_data / "suzanne.obj"), "-o", str(out), "--size", "48", "32", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert png_size(out) == (48, 32)
    assert "968 triangles" in done.stdout


def test_render_default_output_path(tmp_path, box_obj):
    done = run_oit("render", str(box_obj), "--size", "16", "16", "--method", "unsorted", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert png_size(tmp_path / "out" / "box-unsorted.png") == (16, 16)


@pytest.mark.parametrize("args,status,message", [
    (["render", "{box}", "--method", "abufer", "--size", "8", "8"], 2, "did you mean 'abuffer'?"),
    (["render", "{box}", "--param", "k=4", "--size", "8", "8"], 2, "has no parameter 'k'"),
    (["render", "missing.obj"], 2, "no such file: missing.obj"),
    (["render", "{box}", "--param", "novalue"], 2, "parameters are written name=value"),
    (["render", "{box}", "--size", "0", "8"], 2, "expected a positive integer, got 0"),
    (["render", "{box}", "--alpha", "1.5"], 2, "expected a number in [0, 1], got 1.5"),
    (["render", "{box}", "--background", "1", "2", "0"], 2, "expected a number in [0, 1], got 2.0"),
    (["frobnicate"], 2, "invalid choice: 'frobnicate'"),
    ([], 2, "the following arguments are required: COMMAND"),
])
def test_errors_end_with_a_message(tmp_path, box_obj, monkeypatch, capsys, args, status, message):
    monkeypatch.chdir(tmp_path)
    args = [a.replace("{box}", str(box_obj)) for a in args]
    try:
        code = cli.main(args)
    except SystemExit as e:  # argparse's own errors
        code = e.code
    assert code == status
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("text,expected", [
    ("k=4", ("k", 4)), ("alpha=0.25", ("alpha", 0.25)), ("weight=eq7", ("weight", "eq7")), ("x=", ("x", "")),
])
def test_parse_param(text, expected):
    assert cli.parse_param(text) == expected


def test_every_subcommand_has_help(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    for name, *_ in cli.SUBCOMMANDS:
        assert name in out
    assert len(cli.SUBCOMMANDS) == len({name for name, *_ in cli.SUBCOMMANDS})


@pytest.mark.parametrize("name", [name for name, *_ in cli.SUBCOMMANDS])
def test_each_subcommand_prints_its_help(name, capsys):
    # argparse formats every option's help only here (a stray % in one fails at --help alone).
    with pytest.raises(SystemExit) as e:
        cli.main([name, "--help"])
    assert e.value.code == 0
    assert f"python -m oit {name}" in capsys.readouterr().out


def test_demo_result():
    # The demo's claims: abuffer matches the reference (lit, within docs/shading.md's bound),
    # hybrid is close to it, the blend methods visibly are not.
    from oit import demo

    result = demo.run(48)
    assert result.reference_within_bound and result.reference_max_error <= 1e-4
    assert result.ambiguous_fraction < 0.15
    assert result.errors["hybrid"].max() < 0.02
    for method in ("sorted", "unsorted"):
        assert result.errors[method].max() > 0.1
    assert result.mosaic.shape == (2 * 48 + 2, 4 * 48 + 3 * 2, 3)


def test_bench_quick_writes_its_tables(tmp_path):
    # Three methods on the smallest scene: the command end to end, in a few seconds.
    out = tmp_path / "bench"
    result = run_oit("bench", "--quick", "--scenes", "glass", "--methods", "unsorted", "abuffer", "hybrid",
                     "--no-peers", "--no-plots", "--out", str(out), cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    table = (out / "results.md").read_text()
    assert table.startswith("Adapter: ")
    assert [line.split(" | ")[2] for line in table.splitlines() if line.startswith("| glass |")] == ["abuffer", "unsorted", "hybrid"]
    with open(out / "results.csv") as f:
        rows = {r["method"]: r for r in csv.DictReader(f)}
    assert list(rows) == ["abuffer", "unsorted", "hybrid"]
    for r in rows.values():
        assert r["status"] == "ok" and r["size"] == "64x64" and float(r["wall_ms"]) > 0
        assert int(r["max_depth"]) >= 2  # the glass shells overlap
    assert rows["hybrid"]["params"] == "k=8 tail=exact"
    assert float(rows["abuffer"]["mean_err"]) == 0.0
    # Glass is ordered worst for submission-order blending; hybrid's 8 slots hold its few layers.
    assert float(rows["hybrid"]["mean_err"]) < 0.01 < float(rows["unsorted"]["mean_err"])


def test_bench_quick_defaults_run_every_showcase_scene_and_method():
    # What `bench --quick` would run, without running it (that takes half a minute).
    args = cli.build_parser().parse_args(["bench", "--quick"])
    assert args.scenes == list(scenes.SHOWCASE) and args.methods is None and args.sizes is None
    plan = harness.method_plan(args.methods, args.quick)
    assert [method for method, _, _ in plan] == [m["name"] for m in oit.methods()]
    assert all(is_default for *_, is_default in plan)
    assert {m: p for m, p, _ in plan}["hybrid"] == {"k": 8, "tail": "exact"}
