"""`oit.compare(..., client=...)` and `python -m oit compare FILE... --dask`: the (scene, view,
method, parameters) jobs on a two-worker Dask cluster give the rows one process gives, times
aside; several files measure every view of every file."""

from __future__ import annotations

import subprocess
import sys
from functools import partial

import pytest

import oit
from files import box_and_panel_glb
from oit.comparison import cli_scene
from oit.views import orbit_cameras

distributed = pytest.importorskip("distributed", reason="dask.distributed is not installed: pip install 'oit[dask]'")

SIZE = 24
METHODS = ["abuffer", "wavg", "hybrid"]
TIMES = {"time_ms", "gpu_ms", "wall_ms", "meets"}  # "meets" has no time limit here, but says nothing beyond the rows


def _sources(tmp_path):
    """Two small files (the same scene at two alphas) as the workers load them."""
    path = str(box_and_panel_glb(tmp_path / "two.glb"))
    return [partial(cli_scene, path, alpha, "smooth", 0.25, [], (0.1, 0.1, 0.1)) for alpha in (0.5, 0.3)]


def _rows(result):
    """The rows without their times, NaN (no FLIP) as "nan" so that equal rows compare equal."""
    return [{k: "nan" if v != v else v for k, v in r.items() if k not in TIMES} for r in result.rows]


@pytest.fixture(scope="module")
def client():
    # processes: each worker its own device, as on a real cluster; one thread a worker.
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as c:
        yield c


def test_two_files_four_views_on_two_workers_give_the_single_process_rows(tmp_path, client):
    sources = _sources(tmp_path)
    cameras = [orbit_cameras(s(), 4) for s in sources]
    here = oit.compare(sources, cameras, SIZE, SIZE, METHODS, flip=False)
    there = oit.compare(sources, cameras, SIZE, SIZE, METHODS, flip=False, client=client)
    assert len(client.scheduler_info()["workers"]) == 2
    assert _rows(there) == _rows(here)
    assert all(r["views"] == 8 and r["status"] == "ok" for r in here.rows)
    assert set(there.images) == set(here.images) == set(METHODS)
    assert there.summary(time_ms=None).split(":")[0] == here.summary().split(":")[0]


def test_one_file_as_a_list_is_the_one_file(tmp_path):
    source = _sources(tmp_path)[0]
    cams = orbit_cameras(source(), 2)
    assert _rows(oit.compare([source], [cams], SIZE, SIZE, ["wavg"], flip=False)) == \
        _rows(oit.compare(source(), cams, SIZE, SIZE, ["wavg"], flip=False))


def test_a_scene_object_cannot_travel(tmp_path, client):
    scene = _sources(tmp_path)[0]()
    with pytest.raises(TypeError, match="file path the workers can read"):
        oit.compare(scene, orbit_cameras(scene, 1), SIZE, SIZE, ["wavg"], client=client)


def test_the_command_on_a_cluster_writes_the_table(tmp_path, client):
    glb = box_and_panel_glb(tmp_path / "two.glb")
    address = client.scheduler.address
    common = [sys.executable, "-m", "oit", "compare", str(glb), str(glb), "--size", str(SIZE), str(SIZE), "--views", "2",
              "--methods", "wavg", "--no-plots"]
    done = subprocess.run([*common, "--dask", address, "--out", str(tmp_path / "d")], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    alone = subprocess.run([*common, "--out", str(tmp_path / "s")], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert alone.returncode == 0, alone.stderr
    table = lambda d: [line.split("|")[1:3] + line.split("|")[4:-1] for line in (d / "compare.md").read_text().splitlines()  # noqa: E731
                       if line.startswith("| wavg")]
    assert table(tmp_path / "d") == table(tmp_path / "s") != []
    assert "two.glb, two.glb: 4 views" in (tmp_path / "d" / "compare.md").read_text()
