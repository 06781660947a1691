"""UFF 58 export, read back with pyuff's own reader: the writer alone, `tailbeam simulate
--export uff58` (two sensors, checked against sensors.csv), `tailbeam sweep --export uff58` and
`tailbeam export` (checked against dataset.zarr and cases.csv); SEP005 channels; bad input."""

import csv
from pathlib import Path

import numpy as np
import pytest

pyuff = pytest.importorskip("pyuff")

from tailbeam._version import __version__  # noqa: E402
from tailbeam.cli import main  # noqa: E402
from tailbeam.errors import InputError  # noqa: E402
from tailbeam.io.uff import interval_as_written, write_uff58  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

# a plate basis other study tests share (fmax 3 kHz); two sensors with exact UFF intervals
SCENE = """
duration = 0.01
[plate]
model = "modal"
fmax = 3000.0
[[balls]]
name = "rock"
material = "sandstone"
radius = 0.02
position = [0.0, 0.0, 0.0205]
velocity = [0.0, 0.0, -2.0]
[[sensors]]
name = "S1"
position = [0.1, 0.1]
sample_rate = 8000.0
[[sensors]]
name = "edge_2"
position = [-0.2, 0.05]
sample_rate = 25600.0
"""


def read_uff(path) -> list:
    sets = pyuff.UFF(str(path)).read_sets()
    return sets if isinstance(sets, list) else [sets]


def read_csv(path) -> list:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def one_line_error(code, err, field):
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert field in err, err


# -- the writer ---------------------------------------------------------------------------------


def test_writer_reads_back_with_pyuff(tmp_path):
    rng = np.random.default_rng(3)
    a = (rng.normal(size=1001) * 10.0 ** rng.uniform(-9, 4, size=1001)).astype(np.float32)
    b = np.sin(np.arange(517) * 0.1) * 3.2e2  # float64: written as its float32 values
    path = write_uff58(
        tmp_path / "x.uff",
        {"acc_a": a, "acc b": b},
        {"acc_a": 25600.0, "acc b": 51200.0},
        case="case_0007",
        label="gangue",
    )
    sets = read_uff(path)
    assert [s["type"] for s in sets] == [58, 58]
    for k, (name, x) in enumerate([("acc_a", a), ("acc b", b)]):
        s = sets[k]
        np.testing.assert_array_equal(s["data"].astype(np.float32), np.float32(x))
        assert (s["id1"], s["id2"], s["id3"], s["id4"]) == (
            f"tailbeam {__version__}",
            "case_0007",
            name,
            "gangue",
        )
        assert (s["func_type"], s["rsp_node"], s["rsp_dir"], s["ref_node"], s["ref_dir"]) == (
            1,
            k + 1,
            3,
            0,
            0,
        )
        assert s["ordinate_spec_data_type"] == 12 and s["ordinate_axis_units_lab"] == "m/s^2"
        assert s["abscissa_spec_data_type"] == 17 and s["abscissa_axis_units_lab"] == "s"
        assert s["num_pts"] == len(x) and s["abscissa_min"] == 0.0
    # E13.5 in the header: 1/25600 s = 3.90625e-05 s fits 6 digits, 1/51200 s does not
    assert sets[0]["abscissa_inc"] == 1 / 25600.0
    assert sets[1]["abscissa_inc"] == 1.95313e-05 == interval_as_written(51200.0)
    later = write_uff58(tmp_path / "t0.uff", {"s": a[:8]}, 8000.0, case="c", t0=0.25)
    (s,) = read_uff(later)
    assert (s["abscissa_min"], s["abscissa_inc"], s["id4"]) == (0.25, 1.25e-4, "")


def test_writer_refuses_what_a_uff_line_cannot_hold(tmp_path):
    with pytest.raises(InputError, match="case"):
        write_uff58(tmp_path / "x.uff", {"s": np.zeros(4)}, 8000.0, case="c" * 81)
    with pytest.raises(InputError, match=r"sensors\[s\]"):
        write_uff58(tmp_path / "x.uff", {"s": np.zeros(1)}, 8000.0, case="c")
    assert not (tmp_path / "x.uff").exists()


# -- simulate ---------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("sim")
    (tmp / "tiny.toml").write_text(SCENE)
    argv = ["simulate", str(tmp / "tiny.toml"), "--out", str(tmp / "out"), "--export", "uff58"]
    assert main(argv) == 0
    return tmp


@pytest.mark.slow
def test_simulate_export_equals_sensors_csv(simulated):
    out = simulated / "out"
    sensors = read_csv(out / "sensors.csv")  # t_S1, S1, t_edge_2, edge_2 (rates differ)
    labels = read_csv(out / "uff" / "labels.csv")
    assert labels == [
        {"file": "tiny.uff", "label": "gangue", "gangue_fraction": "1.0", "n_coal": "0",
         "n_gangue": "1"}
    ]  # fmt: skip
    sets = read_uff(out / "uff" / "tiny.uff")
    assert [s["id3"] for s in sets] == ["S1", "edge_2"]
    for s, fs in zip(sets, (8000.0, 25600.0), strict=True):
        name = s["id3"]
        expected = np.array([float(r[name]) for r in sensors if r[name] != "nan"])
        np.testing.assert_array_equal(s["data"].astype(np.float32), expected.astype(np.float32))
        assert s["abscissa_inc"] == 1.0 / fs and s["abscissa_min"] == 0.0
        assert (s["id2"], s["id4"]) == ("tiny", "gangue")
        assert np.max(np.abs(expected)) > 0  # the ball hit the plate
    manifest = (out / "manifest.json").read_text()
    assert '"uff/tiny.uff"' in manifest and '"uff/labels.csv"' in manifest


@pytest.mark.slow
def test_sep005_channels_of_a_result(simulated):
    from tailbeam.io.scene_file import load_scene
    from tailbeam.io.sep005 import sep005_channels
    from tailbeam.simulation import simulate

    result = simulate(load_scene(simulated / "tiny.toml"))
    channels = sep005_channels(result, group="tiny")
    sensors = read_csv(simulated / "out" / "sensors.csv")
    assert [c["name"] for c in channels] == ["S1", "edge_2"]
    for c, fs in zip(channels, (8000.0, 25600.0), strict=True):
        assert set(c) == {"name", "data", "fs", "unit_str", "quantity", "group"}
        assert (c["fs"], c["unit_str"], c["quantity"], c["group"]) == (fs, "m/s^2", "a", "tiny")
        expected = [float(r[c["name"]]) for r in sensors if r[c["name"]] != "nan"]
        np.testing.assert_array_equal(c["data"], expected)  # sensors.csv holds repr floats
        assert c["data"].dtype == np.float64


def test_simulate_bad_export_is_one_line_and_writes_nothing(tmp_path, capsys):
    (tmp_path / "tiny.toml").write_text(SCENE)
    out = tmp_path / "out"
    code = main(["simulate", str(tmp_path / "tiny.toml"), "--out", str(out), "--export", "csv"])
    one_line_error(code, capsys.readouterr().err, "argument --export: unknown format 'csv'")
    assert not out.exists()
    rigid = ROOT / "examples" / "two_balls_rigid.toml"
    code = main(["simulate", str(rigid), "--out", str(out), "--export", "uff58"])
    err = capsys.readouterr().err
    one_line_error(code, err, "error: --export: needs sensor records")
    assert not out.exists()


# -- sweep and export ---------------------------------------------------------------------------

# plate.fmax = 1 Hz passes the scene check but fails at run time: no mode lies below it
SWEEP = """
scene = "base.toml"
[axes]
"balls.rock.material" = ["coal", "sandstone"]
"plate.fmax" = [1.0, 3000.0]
"""


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    pytest.importorskip("dask.distributed")
    pytest.importorskip("xarray")
    tmp = tmp_path_factory.mktemp("sweep")
    (tmp / "base.toml").write_text(SCENE.replace("25600.0", "8000.0"))  # one rate per dataset
    (tmp / "sweep.toml").write_text(SWEEP)
    argv = ["sweep", str(tmp / "sweep.toml"), "--out", str(tmp / "out"), "--workers", "1"]
    code = main([*argv, "--export", "uff58"])
    assert code == 1  # the two cases with fmax 1 Hz failed
    return tmp / "out"


@pytest.mark.slow
def test_sweep_export_holds_every_finished_case(swept):
    import pandas as pd
    import xarray as xr

    cases = pd.read_csv(swept / "cases.csv")
    ok = cases[cases["status"] == "ok"]
    labels = pd.read_csv(swept / "uff" / "labels.csv", float_precision="round_trip")
    assert len(ok) == 2 and len(labels) == 2
    assert list(labels.columns[:2]) == ["file", "label"]
    assert sorted(labels["case"]) == sorted(ok["case"])
    files = sorted(p.name for p in (swept / "uff").glob("*.uff"))
    assert files == sorted(labels["file"]) == sorted(f"case_{c:04d}.uff" for c in ok["case"])
    with xr.open_zarr(swept / "dataset.zarr") as ds:
        for row in labels.to_dict("records"):
            one = ds.sel(case=row["case"])
            for name in [c for c, v in ds.coords.items() if v.dims == ("case",)]:
                want = one[name].values.item()
                assert row[name] == want or (want != want and row[name] != row[name]), name
            sets = read_uff(swept / "uff" / row["file"])
            assert [s["id3"] for s in sets] == list(ds["sensor"].values)
            for k, s in enumerate(sets):
                np.testing.assert_array_equal(
                    s["data"].astype(np.float32), one["acceleration"].values[k]
                )
                assert s["abscissa_inc"] == 1 / ds.attrs["sample_rate_hz"]
                assert (s["id2"], s["id4"]) == (Path(row["file"]).stem, row["label"])


@pytest.mark.slow
def test_export_command_rewrites_the_same_files(swept, tmp_path, capsys):
    out = tmp_path / "again"
    assert main(["export", str(swept), "--format", "uff58", "--out", str(out)]) == 0
    first = {p.name: p.read_bytes() for p in (swept / "uff").iterdir() if p.suffix != ".json"}
    again = {p.name: p.read_bytes() for p in out.iterdir() if p.suffix != ".json"}
    assert again == first and len(first) == 3


def test_export_bad_input_is_one_line_and_writes_nothing(swept, tmp_path, capsys):
    out = tmp_path / "x"
    code = main(["export", str(swept), "--format", "uff", "--out", str(out)])
    one_line_error(code, capsys.readouterr().err, "argument --format: invalid choice: 'uff'")
    code = main(["export", str(tmp_path / "nope"), "--out", str(out)])
    one_line_error(code, capsys.readouterr().err, "error: DATASET: no dataset.zarr")
    code = main(["sweep", "s.toml", "--export", "uff58,sep"])
    one_line_error(code, capsys.readouterr().err, "argument --export: unknown format 'sep'")
    assert not out.exists()
