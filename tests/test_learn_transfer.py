"""`tailbeam learn --test OTHER`, `--normalise` and `--model minirocket` on small datasets
(written without Dask): the score on another dataset against a direct scikit-learn fit, a
gain error of 2 and what normalising recovers, the refusals, and the raw windows MiniRocket
reads against the feature table's."""

import json
import shutil

import numpy as np
import pytest

pytest.importorskip("sklearn")
pytest.importorskip("xarray")

from tailbeam.cli import main  # noqa: E402
from tailbeam.errors import InputError  # noqa: E402
from tailbeam.study.case import run_case  # noqa: E402
from tailbeam.study.dataset import DatasetStore  # noqa: E402
from tailbeam.study.design import expand, parse_sweep  # noqa: E402
from tailbeam.study.features import SCALE_FEATURES, all_features  # noqa: E402
from tailbeam.study.learn import Samples, learn  # noqa: E402
from tailbeam.study.windows import feature_table, window_table  # noqa: E402


def _scene(sensors):
    return {
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
        "sensors": [
            {"name": name, "position": list(pos), "sample_rate": 8000.0} for name, pos in sensors
        ],
    }


def _dataset(folder, sensors, samples, seed=0):
    """Coal or sandstone balls (same size and speed) anywhere along x; its folder."""
    x = {"distribution": "uniform", "low": -0.2, "high": 0.2, "samples": samples}
    axes = {"balls.rock.material": ["coal", "sandstone"], "balls.rock.position[0]": x}
    spec = parse_sweep({"scene": _scene(sensors), "seed": seed, "axes": axes})
    DatasetStore(folder).record([(c, run_case(c.toml)) for c in expand(spec)])
    return folder


@pytest.fixture(scope="module")
def sets(tmp_path_factory):
    """TRAIN (2 sensors, 12 cases), its copy with every signal doubled (a gain error of 2),
    and OTHER with one sensor of another name (2 cases)."""
    root = tmp_path_factory.mktemp("transfer")
    train = _dataset(root / "train", [("S1", (0.1, 0.1)), ("S2", (-0.12, 0.05))], 6)
    gain = root / "gain2"
    shutil.copytree(train, gain)
    import zarr

    acc = zarr.open_group(str(gain / "dataset.zarr"), mode="r+")["acceleration"]
    acc[:] = 2 * acc[:]  # exact in binary floating point
    other = _dataset(root / "other", [("S9", (0.1, 0.1))], 1, seed=3)
    return {"train": train, "gain": gain, "other": other}


def _run(*argv):
    assert main(["learn", *map(str, argv), "--folds", "3"]) == 0


def test_test_on_itself_is_the_fit_on_all_rows(sets, tmp_path):
    """--test TRAIN scores the model fitted on every row on those rows: a direct
    scikit-learn fit-predict on the same columns (built here, of the --trees asked), and not
    below the CV score."""
    from sklearn.ensemble import RandomForestClassifier
    from sklearn.impute import SimpleImputer
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    train = sets["train"]
    _run(train, "--test", train, "--out", tmp_path, "--trees", 7)
    scores = json.loads((tmp_path / "learn.json").read_text())
    assert scores["trees"] == 7
    table = feature_table(train)
    cols = [c for c in table.columns if c.startswith(("S1.", "S2."))]
    assert scores["features"] == cols
    x = table[cols].to_numpy(float)
    x = np.where(np.isfinite(x), x, np.nan)
    direct = make_pipeline(
        SimpleImputer(strategy="median"),
        StandardScaler(),
        RandomForestClassifier(n_estimators=7, random_state=0, n_jobs=1),
    ).fit(x, table["label"])
    expected = np.mean(direct.predict(x) == table["label"].to_numpy())
    assert scores["test"]["accuracy"] == pytest.approx(expected, abs=1e-12)
    assert scores["test"]["accuracy"] >= scores["accuracy"]
    majority = table["label"].value_counts().max() / len(table)
    assert scores["test"]["dummy"]["accuracy"] == pytest.approx(majority)
    assert scores["test"]["n_rows"] == scores["n_rows"] == len(table)


def test_a_gain_error_of_two_drops_the_score_and_normalise_recovers_it(sets, tmp_path):
    train, gain = sets["train"], sets["gain"]
    _run(train, "--test", train, "--out", tmp_path / "self")
    _run(train, "--test", gain, "--out", tmp_path / "gain")
    _run(train, "--test", gain, "--normalise", "--out", tmp_path / "gain_norm")
    _run(train, "--test", train, "--normalise", "--out", tmp_path / "self_norm")
    s = {k: json.loads((tmp_path / k / "learn.json").read_text()) for k in
         ("self", "gain", "gain_norm", "self_norm")}  # fmt: skip
    assert s["self"]["trees"] == 200  # the default forest
    assert s["gain"]["test"]["accuracy"] < s["self"]["test"]["accuracy"] - 0.2
    # scale-free features of a doubled signal are the same numbers: same predictions
    assert s["gain_norm"]["test"]["confusion"] == s["self_norm"]["test"]["confusion"]
    assert s["gain_norm"]["test"]["accuracy"] > s["gain"]["test"]["accuracy"] + 0.2
    assert not set(s["gain_norm"]["features"]) & {f"S1.{n}" for n in SCALE_FEATURES}


def test_scale_features_are_the_ones_that_change_with_gain():
    rng = np.random.default_rng(4)
    t = np.arange(400) / 8000.0
    x = np.exp(-60 * t) * np.sin(2 * np.pi * 700 * t) + 0.05 * rng.standard_normal((3, 400))
    a, b = all_features(x, 8000.0), all_features(3.7 * x, 8000.0)
    changed = {k for k in a if not np.allclose(a[k], b[k], rtol=1e-9, atol=0)}
    assert changed == set(SCALE_FEATURES)


def test_refuses_another_dataset_without_the_sensors(sets, tmp_path, capsys):
    out = tmp_path / "never"
    code = main(["learn", str(sets["train"]), "--test", str(sets["other"]), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--test" in err[0] and "'S1'" in err[0]
    assert not out.exists()
    table = feature_table(sets["train"])
    with pytest.raises(InputError, match="--test.*'label'"):
        learn(table, folds=3, test=Samples(table.drop(columns="label"), name="OTHER"))
    with pytest.raises(InputError, match="--test.*'S2.kurtosis'"):
        learn(table, folds=3, test=Samples(table.drop(columns="S2.kurtosis"), name="OTHER"))


@pytest.mark.parametrize(
    "argv, rule",
    [
        (["--trees", "0"], "must be >= 1"),
        (["--trees", "5", "--model", "minirocket"], "forest only"),
    ],
)
def test_refuses_trees_it_cannot_grow(sets, tmp_path, capsys, argv, rule):
    out = tmp_path / "never"
    code = main(["learn", str(sets["train"]), "--out", str(out), *argv])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--trees" in err[0] and rule in err[0], err
    assert not out.exists()
    with pytest.raises(InputError, match="--trees"):
        learn(feature_table(sets["train"]), folds=3, trees=2.5)


def test_minirocket_reads_the_windows_the_features_are_computed_of(sets):
    table = feature_table(sets["train"])
    meta, windows, sensors, fs = window_table(sets["train"], **table.attrs["windows"])
    assert sensors == ["S1", "S2"] and fs == 8000.0 and windows.shape == (len(table), 2, 160)
    assert np.array_equal(meta["t_start"], table["t_start"])
    rms = np.sqrt(np.mean(windows**2, axis=-1))
    assert np.allclose(rms, table[["S1.rms", "S2.rms"]].to_numpy(), rtol=1e-12)


@pytest.mark.slow
def test_minirocket_on_two_sensors_and_its_fit_on_all_rows(sets, tmp_path):
    """MiniRocket (channels S1 and S2) on TRAIN with --test TRAIN: the test score is a direct
    sktime + scikit-learn fit-predict of the same windows (built here), not below CV."""
    pytest.importorskip("sktime")
    from sklearn.linear_model import RidgeClassifierCV
    from sklearn.preprocessing import StandardScaler
    from sktime.transformations.panel.rocket import MiniRocketMultivariate

    train = sets["train"]
    _run(train, "--model", "minirocket", "--test", train, "--out", tmp_path)
    scores = json.loads((tmp_path / "learn.json").read_text())
    assert scores["model"] == "minirocket" and scores["sensors"] == ["S1", "S2"]
    meta, windows, _, _ = window_table(train)
    rocket = MiniRocketMultivariate(random_state=0, n_jobs=1).fit(windows)
    scaler = StandardScaler().fit(rocket.transform(windows).to_numpy())

    def features(w):
        return scaler.transform(rocket.transform(w).to_numpy())

    ridge = RidgeClassifierCV(alphas=np.logspace(-3, 3, 10)).fit(features(windows), meta["label"])
    expected = np.mean(ridge.predict(features(windows)) == meta["label"].to_numpy())
    assert scores["test"]["accuracy"] == pytest.approx(expected, abs=1e-12)
    assert scores["test"]["accuracy"] >= scores["accuracy"]
    assert scores["accuracy"] > scores["dummy"]["accuracy"] + 0.15
    assert not (tmp_path / "importances.png").exists()
    assert scores["windows"]["length"] == 0.02 and scores["windows"]["window"] == "impact"
