"""A simulated sweep, exported as UFF 58 and imported back as if it were measured: the same
signals to float32 precision, the same labels exactly, and the same learning score.

The independent truth is the sweep's own dataset: export (``tailbeam export``) and import
(``tailbeam import``) are separate code paths that meet only in the UFF 58 files and the
labels file.
"""

import json

import numpy as np
import pytest

pytest.importorskip("pyuff")
xr = pytest.importorskip("xarray")
pytest.importorskip("dask.distributed")

from tailbeam.cli import main  # noqa: E402

SCENE = """
duration = 0.012
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
"""

SWEEP = """
scene = "base.toml"
seed = 3
[labels]
coal = ["coal"]
[axes]
"balls.rock.material" = ["coal", "sandstone"]
"balls.rock.radius" = { distribution = "uniform", low = 0.01, high = 0.04, samples = 6 }
"balls.rock.position[2]" = { follow = "balls.rock.radius", offset = 0.0005 }
"balls.rock.position[0]" = { distribution = "uniform", low = -0.2, high = 0.2, samples = 6 }
"""


@pytest.fixture(scope="module")
def round_trip(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("roundtrip")
    (tmp / "base.toml").write_text(SCENE)
    (tmp / "sweep.toml").write_text(SWEEP)
    swept, imported = tmp / "swept", tmp / "imported"
    code = main(["sweep", str(tmp / "sweep.toml"), "--out", str(swept), "--workers", "1"])
    assert code == 0
    assert main(["export", str(swept), "--out", str(tmp / "uff"), "--quiet"]) == 0
    files = sorted(str(p) for p in (tmp / "uff").glob("*.uff"))
    labels = str(tmp / "uff" / "labels.csv")
    assert main(["import", *files, "--labels", labels, "--out", str(imported), "--quiet"]) == 0
    return swept, imported


@pytest.mark.slow
def test_import_of_the_export_gives_back_the_sweep(round_trip):
    swept, imported = round_trip
    with xr.open_zarr(swept / "dataset.zarr") as a, xr.open_zarr(imported / "dataset.zarr") as b:
        assert a.sizes["case"] == b.sizes["case"] == 12
        order = [int(np.flatnonzero(b["case_hash"].values == h)[0]) for h in a["case_hash"].values]
        b = b.isel(case=order)
        assert list(b["sensor"].values) == list(a["sensor"].values)
        assert a.attrs["sample_rate_hz"] == b.attrs["sample_rate_hz"]
        np.testing.assert_array_equal(b["acceleration"].values, a["acceleration"].values)
        for name in ("label", "gangue_fraction", "n_coal", "n_gangue"):
            assert list(b[name].values) == list(a[name].values), name


@pytest.mark.slow
def test_learn_scores_the_same_on_both(round_trip, tmp_path):
    """Whole-record windows on both (per-impact windows would compare the sweep's exact
    impact times with the import's detected onsets, another question)."""
    scores = []
    for dataset in round_trip:
        out = tmp_path / dataset.name
        window = ["--window", "fixed", "--length", "0.012"]
        assert main(["features", str(dataset), *window, "--quiet"]) == 0
        assert main(["learn", str(dataset), "--folds", "3", "--out", str(out), "--quiet"]) == 0
        scores.append(json.loads((out / "learn.json").read_text()))
    assert scores[0]["n_rows"] == scores[1]["n_rows"] > 0
    assert scores[0]["accuracy"] == scores[1]["accuracy"]
    assert scores[0]["f1_macro"] == scores[1]["f1_macro"]
