"""`tailbeam sweep` of a stream scene on a real Dask scheduler and worker (127.0.0.1): the
dataset's labels agree with the scene and with a direct simulation of each case (gangue
fraction = the swept value, particle counts = the scene's particles, coal and gangue plate
impacts = impacts_table's rows), the signals are the direct simulation's, repeats draw
independent particles, and the fixed-window features of study 2 and the impact windows (plate
rows only) exist."""

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
from tailbeam.study.windows import feature_table  # noqa: E402

BASE = """
duration = 0.3
[contact]
damping = 300.0
penetration = 1e-4
[plate]
model = "modal"
inclination = 20.0
fmax = 3000.0
tail = "quasi-static"  # the band check then has something to say (tails see to 12 kHz)
[[streams]]
name = "cave"
rate = 40.0
start = 0.0
stop = 0.3
gangue_fraction = 0.3
radius = [0.01, 0.03]
area = [[-0.2, 0.0], [-0.15, 0.15]]
height = [0.01, 0.05]
seed = 1
[[sensors]]
name = "S1"
position = [0.1, 0.05]
sample_rate = 8000.0
"""

SWEEP = """
scene = "base.toml"
repeats = {repeats}
[axes]
"streams.{stream}.gangue_fraction" = [0.0, 0.5, 1.0]
"""


@pytest.fixture(scope="module")
def scheduler():
    from tailbeam.study.sweep import local_cluster

    cluster = local_cluster(1)
    yield cluster.scheduler_address
    cluster.close()


def _sweep(tmp: Path, address: str, capsys, stream="cave", repeats=1):
    (tmp / "base.toml").write_text(BASE)
    (tmp / "sweep.toml").write_text(SWEEP.format(stream=stream, repeats=repeats))
    args = ["sweep", str(tmp / "sweep.toml"), "--out", str(tmp / "out"), "--scheduler", address]
    return main(args), capsys.readouterr()


def _check_case(one, rows, toml):
    """Labels and signals of one stored case against the direct simulation of its scene."""
    scene = loads_scene(toml)
    direct = solve(scene)
    table = direct.impacts_table()
    plate = table["partner"] == "plate"
    assert int(one["n_gangue_impacts"]) == int(np.sum(plate & (table["label"] == "gangue")))
    assert int(one["n_coal_impacts"]) == int(np.sum(plate & (table["label"] == "coal")))
    assert int(one["n_ball_contacts"]) == int(np.sum(~plate)) // 2
    labels = [p.label for p in scene.particles]
    assert int(one["n_gangue"]) == labels.count("gangue")
    assert int(one["n_coal"]) == labels.count("coal")
    assert int(one["n_particles"]) == len(labels) > 0
    # the band it ran with and the band check's estimate, as the direct run reports them
    band = direct.info["band"]
    assert float(one["band_hz"]) == band["fmax_hz"] == 3000.0
    assert float(one["band_force_error"]) == band["truncation_force_error"] > band["accuracy"]
    assert len(rows) == len(table["ball"])
    np.testing.assert_array_equal(rows["ball"], table["ball"])
    np.testing.assert_array_equal(rows["label"], table["label"])
    np.testing.assert_array_equal(rows["class"], table["label"])
    np.testing.assert_allclose(rows["t_start"], table["t_start"])
    expected = direct.sensor_signals["S1"][1].astype(np.float32)
    np.testing.assert_array_equal(one["acceleration"].values[0], expected)


def test_stream_sweep_labels_match_the_scene(tmp_path, scheduler, capsys):
    code, io = _sweep(tmp_path, scheduler, capsys)
    assert code == 0, io.err
    assert "3 cases, 0 already done, 3 run (3 ok, 0 failed," in io.out
    # the band check of the one basis, said once (the cases themselves run quietly)
    assert io.err.count("would need") == 1 and "[first case of its basis]" in io.err
    out = tmp_path / "out"
    ds = xr.open_zarr(out / "dataset.zarr")
    swept = ds["streams.cave.gangue_fraction"].values
    np.testing.assert_array_equal(ds["gangue_fraction"].values, swept)
    assert sorted(swept) == [0.0, 0.5, 1.0]
    impacts = pd.read_parquet(out / "impacts.parquet")
    assert {"partner", "label", "stream", "end", "x", "y", "radius"} <= set(impacts.columns)
    for cid in ds["case"].values:
        one = ds.sel(case=cid)
        toml = ds.attrs["case_scenes"][str(one["case_hash"].values)]
        _check_case(one, impacts[impacts["case"] == cid], toml)
        fraction = float(one["gangue_fraction"])
        if fraction == 0.0:  # the closed forms of the ends: no gangue, no coal
            assert int(one["n_gangue"]) == int(one["n_gangue_impacts"]) == 0
            assert str(one["label"].values) == "coal"
        if fraction == 1.0:
            assert int(one["n_coal"]) == int(one["n_coal_impacts"]) == 0
            assert float(one["gangue_mass_fraction"]) == 1.0
    assert ds["n_coal_impacts"].sum() > 0 and ds["n_gangue_impacts"].sum() > 0

    feats = feature_table(out, window="fixed", length=0.1)
    assert len(feats) == 3 * ds.sizes["case"]  # three 0.1 s windows per 0.3 s case
    assert np.isfinite(feats["S1.rms"]).all() and (feats["S1.rms"] > 0).all()
    np.testing.assert_array_equal(feats["gangue_fraction"], feats["streams.cave.gangue_fraction"])
    # impact windows: one per plate row whose 20 ms window (from 0.5 ms before) fits the record
    per_impact = feature_table(out, window="impact", length=0.02, pre=0.0005)
    plate = impacts[impacts["partner"] == "plate"]
    start = np.clip(np.round((plate["t_start"] - 0.0005) * 8000.0), 0, None)
    assert len(per_impact) == int(np.sum(start + 160 <= ds.sizes["time"])) > 0
    assert set(per_impact["label"]) == {"coal", "gangue"}


def test_stream_repeats_draw_independent_particles(tmp_path):
    from tailbeam.study.design import expand, load_sweep

    (tmp_path / "base.toml").write_text(BASE)
    (tmp_path / "sweep.toml").write_text(SWEEP.format(stream="cave", repeats=2))
    cases = expand(load_sweep(tmp_path / "sweep.toml"))
    assert len(cases) == 6 and len({c.hash for c in cases}) == 6
    seeds = [loads_scene(c.toml).streams[0].seed for c in cases]
    assert len(set(seeds)) == 6  # every case its own stream seed, from the case seed


def test_unknown_stream_axis_is_one_line(tmp_path, capsys):
    (tmp_path / "base.toml").write_text(BASE)
    (tmp_path / "sweep.toml").write_text(SWEEP.format(stream="main", repeats=1))
    code = main(["sweep", str(tmp_path / "sweep.toml"), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    assert 'axes."streams.main.gangue_fraction"' in err and "no entry named 'main'" in err
    assert not (tmp_path / "out").exists()


def test_a_stream_with_contact_tails_has_its_own_basis_signature():
    from tailbeam.study.case import basis_signature

    static = loads_scene(BASE)
    tails = loads_scene(BASE.replace('tail = "quasi-static"', 'tail = "auto"'))
    assert basis_signature(static) != basis_signature(tails)  # its warm-up builds both bases
    assert "12000.0" in basis_signature(tails)
