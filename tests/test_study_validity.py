"""A sweep flags the cases whose band check estimates a peak-force error above the sweep's
``band_accuracy`` (``valid`` / ``invalid_reason`` in cases.csv and the dataset), and
``tailbeam sweep --strict`` refuses them before any case runs."""

import math

import pytest

pytest.importorskip("xarray")
pytest.importorskip("zarr")

import tomli_w  # noqa: E402
import xarray as xr  # noqa: E402

from tailbeam.cli.main import main  # noqa: E402
from tailbeam.errors import InputError  # noqa: E402
from tailbeam.io.scene_file import loads_scene  # noqa: E402
from tailbeam.solvers.modal_setup.band import BAND_ACCURACY  # noqa: E402
from tailbeam.study.case import band_estimate, run_case, validity  # noqa: E402
from tailbeam.study.dataset import DatasetStore  # noqa: E402
from tailbeam.study.design import expand, parse_sweep  # noqa: E402

SCENE = {
    "duration": 0.01,
    "plate": {"model": "modal", "boundary": "SSSS", "fmax": 3000.0},
    "balls": [{"name": "rock", "material": "coal", "radius": 0.02,
               "position": [0.05, -0.05, 0.0205], "velocity": [0.0, 0.0, -2.0]}],
    "sensors": [{"name": "S1", "position": [0.1, 0.1], "sample_rate": 8000.0}],
}  # fmt: skip
AXES = {"balls.rock.radius": [0.012, 0.08],
        "balls.rock.position[2]": {"follow": "balls.rock.radius", "offset": 0.0005}}  # fmt: skip


def _spec(**keys):
    return parse_sweep({"scene": SCENE, "axes": AXES, **keys})


def test_default_accuracy_is_the_band_checks_own():
    assert _spec().band_accuracy == BAND_ACCURACY == 0.005
    assert _spec(band_accuracy=0.2).band_accuracy == 0.2


@pytest.mark.parametrize("bad", [0, -0.1, "1%", True, math.inf])
def test_bad_band_accuracy_names_the_key(bad):
    with pytest.raises(InputError) as err:
        _spec(band_accuracy=bad)
    assert err.value.field == "band_accuracy"


def test_up_front_estimate_is_the_runs_and_flags_the_case(tmp_path):
    cases = expand(_spec())
    small, large = (band_estimate(loads_scene(c.toml)) for c in cases)
    # the 12 mm ball's contact is far shorter: its estimate is the larger
    assert small["band_force_error"] > large["band_force_error"] > 0.0
    accuracy = 1.5 * large["band_force_error"]  # between the two
    assert small["band_force_error"] > accuracy
    result = run_case(cases[0].toml)  # the run records the estimate made up front
    assert result["status"] == "ok" and result["band_hz"] == small["band_hz"] == 3000.0
    assert result["band_force_error"] == small["band_force_error"]
    # the other case's record: the same signals with its own (up-front) band columns
    results = [result, {**result, **large}]
    store = DatasetStore(tmp_path, band_accuracy=accuracy)
    store.record(list(zip(cases, results, strict=True)))
    ledger = DatasetStore(tmp_path).ledger
    assert list(ledger["valid"]) == [False, True]
    assert ledger["invalid_reason"].iloc[0].startswith("band_force_error ")
    assert "plate.fmax" in ledger["invalid_reason"].iloc[0]
    ds = xr.open_zarr(tmp_path / "dataset.zarr")
    assert list(ds["valid"].values) == [False, True]
    assert ds.isel(case=ds["valid"].values).sizes["case"] == 1  # what a user filters on


def test_validity_rule():
    assert validity({}, 0.01)["valid"]  # rigid plate: no estimate
    assert validity({"band_force_error": 0.01, "band_hz": 5e3}, 0.01)["valid"]
    assert not validity({"band_force_error": math.inf, "band_hz": 5e3}, 0.01)["valid"]
    assert not validity({"band_force_error": 0.0101, "band_hz": 5e3}, 0.01)["valid"]


def test_strict_refuses_before_any_case_runs(tmp_path, capsys):
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(tomli_w.dumps({"scene": SCENE, "axes": AXES}))
    out = tmp_path / "out"
    assert main(["sweep", str(sweep), "--out", str(out), "--strict"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("tailbeam sweep: error: --strict: 2 of 2 cases exceed")
    assert "case 1 (balls.rock.radius = 0.012" in err[-1] and not out.exists()
