"""`tailbeam sweep` on a real Dask scheduler and workers (separate processes, 127.0.0.1):
the dataset's signals equal a direct simulation of each case's scene, a failing case is
recorded and does not stop the sweep, a rerun resumes, a grown sweep appends; the Zarr store
opens with xarray.open_zarr and each modal basis is computed once."""

import os
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("dask.distributed")
pytest.importorskip("xarray")

import pandas as pd  # noqa: E402
import xarray as xr  # noqa: E402

from tailbeam.cli import main  # noqa: E402
from tailbeam.io.scene_file import loads_scene  # noqa: E402
from tailbeam.simulation import simulate as solve  # noqa: E402

BASE = """
duration = 0.01
[plate]
model = "modal"
fmax = 3000.0
size = [0.6, 0.6, 0.0099]  # a plate no other test uses: its basis is this module's own
[[balls]]
name = "rock"
material = "coal"
radius = 0.02
position = [0.05, -0.05, 0.0205]
velocity = [0.0, 0.0, -2.0]
[[sensors]]
name = "S1"
position = [0.1, 0.1]
sample_rate = 8000.0
noise = 0.5
[[sensors]]
name = "S2"
position = [-0.2, 0.05]
sample_rate = 8000.0
"""

# plate.fmax = 1 Hz passes the scene check but fails at run time: no mode lies below it
SWEEP = """
scene = "base.toml"
[axes]
"balls.rock.material" = ["coal", "sandstone"]
"plate.fmax" = [{fmax}]
"""


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory):
    """Two local workers. This module's modal bases go to a folder of its own (the session's
    folder is shared with pytest-xdist's other workers, which may add bases at any time);
    the compiled kernels stay the session's."""
    from tailbeam.cachedir import numba_cache_dir
    from tailbeam.study.sweep import local_cluster

    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("NUMBA_CACHE_DIR", str(numba_cache_dir()))
        mp.setenv("TAILBEAM_CACHE_DIR", str(tmp_path_factory.mktemp("sweep-cache")))
        cluster = local_cluster(2)
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        yield cluster.scheduler_address
        cluster.close()


def _run(tmp: Path, address: str, fmax: str, capsys):
    (tmp / "base.toml").write_text(BASE)
    (tmp / "sweep.toml").write_text(SWEEP.format(fmax=fmax))
    code = main(
        ["sweep", str(tmp / "sweep.toml"), "--out", str(tmp / "out"), "--scheduler", address]
    )
    return code, capsys.readouterr()


def _cache_files():
    return sorted(Path(os.environ["TAILBEAM_CACHE_DIR"]).glob("modes-*.npz"))


def test_sweep_records_failures_resumes_and_appends(tmp_path, scheduler, capsys):
    before = _cache_files()
    code, io = _run(tmp_path, scheduler, "1.0, 3000.0", capsys)
    assert code == 1  # some cases failed
    assert "4 cases, 0 already done, 4 run (2 ok, 2 failed," in io.out
    out = tmp_path / "out"
    cases = pd.read_csv(out / "cases.csv")
    assert sorted(cases["status"]) == ["failed", "failed", "ok", "ok"]
    failed = cases[cases["status"] == "failed"]
    assert (failed["plate.fmax"] == 1.0).all()
    assert failed["error"].str.contains("no mode lies below 1.0 Hz").all()
    assert len(_cache_files()) == len(before) + 1  # one basis (3 kHz) for both good cases

    ds = xr.open_zarr(out / "dataset.zarr")
    assert ds["acceleration"].dims == ("case", "sensor", "time")
    assert ds["acceleration"].dtype == np.float32
    assert ds["acceleration"].attrs["units"] == "m/s^2"
    assert ds.attrs["sample_rate_hz"] == 8000.0
    assert list(ds["sensor"].values) == ["S1", "S2"]
    assert sorted(ds["label"].values) == ["coal", "gangue"]
    assert set(ds["gangue_fraction"].values) == {0.0, 1.0}
    np.testing.assert_allclose(ds["sensor_x"].values, [[0.1, -0.2], [0.1, -0.2]])
    impacts = pd.read_parquet(out / "impacts.parquet")
    assert set(impacts["case"]) == set(ds["case"].values)
    for cid in ds["case"].values:
        one = ds.sel(case=cid)
        toml = ds.attrs["case_scenes"][str(one["case_hash"].values)]
        direct = solve(loads_scene(toml))  # the case simulated here, outside Dask
        for k, name in enumerate(["S1", "S2"]):
            expected = direct.sensor_signals[name][1].astype(np.float32)
            np.testing.assert_array_equal(one["acceleration"].values[k], expected)
        rows = impacts[impacts["case"] == cid]
        assert (
            len(rows) == len(direct.impacts) == int(one["n_coal_impacts"] + one["n_gangue_impacts"])
        )
        np.testing.assert_allclose(rows["v_in"], [i.v_in for i in direct.impacts])
    ids = dict(zip(cases["case_hash"], cases["case"], strict=True))

    # rerun: the finished cases are skipped, the failed ones retried (and fail again)
    code, io = _run(tmp_path, scheduler, "1.0, 3000.0", capsys)
    assert "4 cases, 2 already done, 2 run (0 ok, 2 failed," in io.out
    assert xr.open_zarr(out / "dataset.zarr").sizes["case"] == 2

    # grown sweep without the failing value: only the new cases run, appended, ids kept
    code, io = _run(tmp_path, scheduler, "3000.0, 2500.0", capsys)
    assert code == 0 and "4 cases, 2 already done, 2 run (2 ok, 0 failed," in io.out
    ds = xr.open_zarr(out / "dataset.zarr")
    assert ds.sizes["case"] == 4 and len(set(ds["case"].values)) == 4
    cases = pd.read_csv(out / "cases.csv")
    assert all(
        ids[h] == c for h, c in zip(cases["case_hash"], cases["case"], strict=True) if h in ids
    )
    assert len(ds.attrs["case_scenes"]) == 4
    assert sorted(pd.read_parquet(out / "impacts.parquet")["case"].unique()) == sorted(
        ds["case"].values
    )


def test_progress_lines_show_failures(monkeypatch, capsys):
    from tailbeam import progress

    monkeypatch.setattr(progress, "DELAY_S", 0.0)
    with progress.task("sweep of 3 cases", total=3, unit="cases") as bar:
        bar.update(1)
        bar.set_postfix("1 failed")
        bar.update(2)
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[0].startswith("tailbeam: sweep of 3 cases: 1/3 cases, ")
    assert "left" in lines[0]  # time left
    assert lines[-1].startswith("tailbeam: sweep of 3 cases: 3/3 cases (1 failed), ")


def test_a_case_prints_nothing_and_restores_progress(capsys):
    """Cases run silently (the sweep's bar is the progress; per-case notes from workers
    would flood the user's terminal) and leave the process's progress setting as it was."""
    from tailbeam.progress import is_quiet
    from tailbeam.study.case import run_case

    assert not is_quiet()
    out = run_case(BASE)
    assert out["status"] == "ok", out["error"]
    assert capsys.readouterr().err == ""
    assert not is_quiet()


def test_local_sweep_through_the_in_process_client_matches_the_tcp_one(tmp_path, scheduler, capsys):
    """`--workers 1` starts a local cluster whose client talks to the scheduler in-process
    (inproc://, no TCP); its dataset equals the one the same cases give through TCP
    (``--scheduler``), signal for signal, and the pause before the last gather ends with
    the last case (the sweep's batches hold every case)."""
    from tailbeam.study.sweep import close_client, connect

    client = connect(workers=1)
    try:
        assert client.scheduler.address.startswith("inproc://")
        assert client.run(os.getpid).keys()  # its worker answers through the same link
    finally:
        close_client(client)
    (tmp_path / "base.toml").write_text(BASE)
    (tmp_path / "sweep.toml").write_text(SWEEP.format(fmax="3000.0, 2500.0"))
    sets = {}
    for name, extra in (("inproc", ["--workers", "1"]), ("tcp", ["--scheduler", scheduler])):
        args = ["sweep", str(tmp_path / "sweep.toml"), "--out", str(tmp_path / name), *extra]
        assert main(args) == 0
        assert "4 cases, 0 already done, 4 run (4 ok, 0 failed," in capsys.readouterr().out
        ds = xr.open_zarr(tmp_path / name / "dataset.zarr").load()
        sets[name] = ds.sortby("case_hash").drop_vars("case")
    xr.testing.assert_identical(sets["inproc"], sets["tcp"])


def test_pause_sleeps_while_many_cases_are_left_and_waits_for_the_last_ones(monkeypatch):
    """Between gathers the client sleeps GATHER_INTERVAL_S while the cases left take longer
    than two intervals at the rate so far; near the end it waits on the cases left, at most
    GATHER_INTERVAL_S (a timeout is not an error), so no sleep outlasts the last case."""
    import dask.distributed

    from tailbeam.study import sweep

    calls = []
    monkeypatch.setattr(sweep.time, "sleep", lambda s: calls.append(("sleep", s)))

    def wait(futures, timeout):
        calls.append(("wait", len(futures), timeout))
        raise TimeoutError

    monkeypatch.setattr(dask.distributed, "wait", wait)
    interval = sweep.GATHER_INTERVAL_S
    rate = 10.0  # cases/s: 2 intervals hold 2 * interval * rate cases
    n_edge = int(2 * interval * rate)
    sweep._pause(dict.fromkeys(range(n_edge + 1)), rate)
    sweep._pause(dict.fromkeys(range(n_edge)), rate)
    assert calls == [("sleep", interval), ("wait", n_edge, interval)]
