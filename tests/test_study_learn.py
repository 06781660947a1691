"""`tailbeam features` and `tailbeam learn` on a small dataset (written without Dask), and the
grouping of the cross-validation: windows of one case never sit in train and test at once."""

import json

import numpy as np
import pandas as pd
import pytest

pytest.importorskip("sklearn")
pytest.importorskip("xarray")

from tailbeam.cli import main  # noqa: E402
from tailbeam.study.case import run_case  # noqa: E402
from tailbeam.study.dataset import DatasetStore  # noqa: E402
from tailbeam.study.design import expand, parse_sweep  # noqa: E402
from tailbeam.study.learn import learn  # noqa: E402

BASE = {
    "duration": 0.03,
    "plate": {"model": "modal", "fmax": 3000.0},
    "balls": [
        {
            "name": "rock",
            "material": "coal",
            "radius": 0.02,
            "position": [0.0, 0.0, 0.0205],
            "velocity": [0.0, 0.0, -2.0],
        }
    ],
    "sensors": [{"name": "S1", "position": [0.1, 0.1], "sample_rate": 8000.0}],
}


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    spec = parse_sweep(
        {
            "scene": BASE,
            "axes": {
                "balls.rock.material": ["coal", "sandstone"],
                "balls.rock.position[0]": {
                    "distribution": "uniform",
                    "low": -0.2,
                    "high": 0.2,
                    "samples": 6,
                },
            },
        }
    )
    out = tmp_path_factory.mktemp("learn") / "out"
    store = DatasetStore(out)
    store.record([(c, run_case(c.toml)) for c in expand(spec)])  # (Case, result) pairs
    return out


def test_features_and_learn_commands(dataset, capsys):
    assert main(["features", str(dataset)]) == 0
    table = pd.read_parquet(dataset / "features.parquet")
    assert {"case", "label", "S1.rms", "S1.wp_7", "S1.kurtosis"} <= set(table.columns)
    assert set(table["label"]) == {"coal", "gangue"}
    assert main(["learn", str(dataset), "--folds", "3"]) == 0
    scores = json.loads((dataset / "learn" / "learn.json").read_text())
    assert scores["n_cases"] == 12
    assert np.sum(scores["confusion"]) == scores["n_rows"] == len(table)
    # same size and speed, sandstone is 1.8x denser and 2.5x stiffer than coal: separable
    assert scores["accuracy"] > scores["dummy"]["accuracy"] + 0.2
    assert (dataset / "learn" / "confusion.png").stat().st_size > 1000
    assert "accuracy" in capsys.readouterr().out


def test_learn_gangue_fraction_regression(dataset, capsys):
    assert main(["features", str(dataset), "--window", "fixed", "--length", "0.01"]) == 0
    assert main(["learn", str(dataset), "--target", "gangue_fraction", "--folds", "3"]) == 0
    scores = json.loads((dataset / "learn" / "learn.json").read_text())
    assert scores["n_rows"] == 12 * 3 and {"mae", "r2"} <= set(scores)


def test_cross_validation_is_grouped_by_case():
    # every case has 10 identical windows and a random label: a model that saw one of a
    # case's windows would recognise the others; grouped folds leave only chance
    rng = np.random.default_rng(0)
    n_cases, per = 40, 10
    x = np.repeat(rng.standard_normal((n_cases, 3)), per, axis=0)
    labels = np.repeat(rng.choice(["coal", "gangue"], n_cases), per)
    table = pd.DataFrame(x, columns=["S1.rms", "S1.peak", "S1.kurtosis"])
    table["case"] = np.repeat(np.arange(n_cases), per)
    table["label"] = labels
    scores = learn(table, "label", folds=5)
    assert scores["accuracy"] < 0.75  # near 0.5; ungrouped folds would give ~1.0


def test_cross_validation_groups_by_the_column_asked():
    # 40 cases, each cut from one of 8 recordings whose label and features it shares: folds
    # grouped by case see every recording in training and score ~1; grouped by recording,
    # only chance is left
    rng = np.random.default_rng(1)
    source = np.repeat(np.arange(8), 5)
    x = rng.standard_normal((8, 3))[source] + 1e-3 * rng.standard_normal((40, 3))
    table = pd.DataFrame(x, columns=["S1.rms", "S1.peak", "S1.kurtosis"])
    table["case"] = np.arange(40)
    table["source_file"] = [f"r{k}.wav" for k in source]
    table["label"] = np.array(["coal", "gangue"] * 4)[source]
    assert learn(table, "label", folds=4)["accuracy"] > 0.9
    scores = learn(table, "label", folds=4, groups="source_file")
    assert scores["accuracy"] < 0.75 and scores["groups"] == "source_file"


def test_undefined_features_are_imputed_not_dropped():
    rng = np.random.default_rng(1)
    table = pd.DataFrame(rng.standard_normal((30, 2)), columns=["S1.rms", "S1.decay_rate"])
    table.loc[::4, "S1.decay_rate"] = np.nan
    table["case"] = np.arange(30)
    table["label"] = np.where(table["S1.rms"] > 0, "gangue", "coal")
    scores = learn(table, "label", folds=3)
    assert scores["n_rows"] == 30 and np.sum(scores["confusion"]) == 30


def test_mae_standard_error_counts_cases_not_windows():
    from tailbeam.study.learn import _case_se

    # two windows per case; per-case means 1 and 3: std sqrt(2), over sqrt(2 cases) = 1
    assert _case_se(np.array([1.0, 1.0, 3.0, 3.0]), np.array([0, 0, 1, 1])) == pytest.approx(1.0)
