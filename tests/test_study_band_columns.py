"""The band columns of a sweep's dataset (band_hz, band_force_error): on the modal plate they
are the direct run's result.info["band"]; a rigid case has none; a store written before they
existed still takes new cases (appended without them)."""

import math

import numpy as np
import pytest

pytest.importorskip("xarray")
pytest.importorskip("zarr")

import xarray as xr  # noqa: E402

from tailbeam.errors import InputError  # noqa: E402
from tailbeam.io.scene_file import loads_scene  # noqa: E402
from tailbeam.simulation import simulate as solve  # noqa: E402
from tailbeam.study import dataset  # noqa: E402
from tailbeam.study.case import run_case  # noqa: E402
from tailbeam.study.design import expand, parse_sweep  # noqa: E402

RIGID = """
duration = 0.01
[plate]
model = "rigid"
[[balls]]
name = "rock"
material = "coal"
radius = 0.02
position = [0.05, -0.05, 0.0205]
velocity = [0.0, 0.0, -2.0]
"""
SCENE = {
    "duration": 0.01,
    "plate": {"model": "rigid"},
    "balls": [{"name": "rock", "material": "coal", "radius": 0.02,
               "position": [0.05, -0.05, 0.0205], "velocity": [0.0, 0.0, -2.0]}],
}  # fmt: skip


def _cases(model: str):
    scene = {**SCENE, "plate": {"model": model, "fmax": 3000.0} if model == "modal" else {}}
    if model == "modal":
        scene["sensors"] = [{"name": "S1", "position": [0.1, 0.1], "sample_rate": 8000.0}]
    spec = {"scene": scene, "axes": {"balls.rock.material": ["coal", "sandstone"]}}
    return expand(parse_sweep(spec))


def test_modal_case_records_its_band_and_the_rigid_none():
    case = _cases("modal")[0]
    out = run_case(case.toml)
    band = solve(loads_scene(case.toml)).info["band"]
    assert out["status"] == "ok" and out["band_hz"] == band["fmax_hz"] == 3000.0
    assert out["band_force_error"] == band["truncation_force_error"] > 0.0
    rigid = run_case(RIGID)  # (a sweep needs sensors, so the modal plate; a case alone not)
    assert rigid["status"] == "ok" and "band_hz" not in rigid


def test_a_rigid_sweep_is_refused_by_its_rule_not_a_crash():
    with pytest.raises(InputError, match="sensor"):
        _cases("rigid")


def test_a_store_without_band_columns_takes_new_cases(tmp_path, monkeypatch):
    cases = _cases("modal")
    results = [run_case(c.toml) for c in cases]
    monkeypatch.setattr(dataset, "BAND_COLUMNS", ())  # as a store of an older tailbeam
    dataset.DatasetStore(tmp_path).record([(cases[0], results[0])])
    monkeypatch.undo()
    dataset.DatasetStore(tmp_path).record([(cases[1], results[1])])
    ds = xr.open_zarr(tmp_path / "dataset.zarr")
    assert ds.sizes["case"] == 2 and "band_hz" not in ds.coords
    ledger = dataset.DatasetStore(tmp_path).ledger
    assert math.isnan(ledger["band_hz"].iloc[0]) and ledger["band_hz"].iloc[1] == 3000.0
    fresh = tmp_path / "fresh"
    dataset.DatasetStore(fresh).record(list(zip(cases, results, strict=True)))
    np.testing.assert_array_equal(xr.open_zarr(fresh / "dataset.zarr")["band_hz"], [3e3, 3e3])
