"""Baselines of how separable the classes are: a model scored on windows of a dataset.

The model (tailbeam.study.models: a random forest on the feature table, or MiniRocket on the
raw windows) is scored by cross-validation grouped by case (``GroupKFold``): windows of one
case never sit in training and test at once, so repeated impacts of one ball cannot leak.
Beside it, a majority-class (or mean) dummy is scored on the same folds as the floor to
compare with. With ``test``, the model fitted on every row of the training data is also
scored on another dataset (e.g. another plate), beside the dummy fitted on the same rows.
The forest's feature importances are its impurity decrease, from that fit on all rows.
"""

from dataclasses import dataclass, field

import numpy as np

from tailbeam.errors import InputError
from tailbeam.study import models

TARGETS = ("label", "gangue_fraction")


@dataclass
class Samples:
    """Windows of one dataset: ``table`` (one row per window: case, labels, features) and, for
    MiniRocket, the raw ``windows`` (rows, sensor, samples) in m/s^2 of ``sensors`` at
    ``sample_rate`` (Hz); ``name`` says where they come from in messages."""

    table: object
    windows: np.ndarray | None = None
    sensors: list = field(default_factory=list)
    sample_rate: float = 0.0
    name: str = "TRAIN"


def learn(
    data, target="label", *, folds=5, seed=0, sensors=None, model="forest", normalise=False,
    test=None, groups="case", trees=None,
) -> dict:  # fmt: skip
    """Cross-validated scores of ``model`` and the dummy on ``data`` (Samples, or a feature
    table for the forest), and with ``test`` (Samples, or a list of them) the scores on it of
    both fitted on all of ``data``. ``groups`` names the column whose values never sit on both
    sides of a fold: ``case`` by default; ``source_file`` for cases cut from one recording.
    ``trees``: the forest's number of trees (``models.TREES`` if None; the forest only).

    Returns a dict: model, normalise, target, n_rows, n_cases, folds, sensors, features, and
    for a label "accuracy", "f1_macro", "classes", "confusion" (rows true, columns
    predicted), or for gangue_fraction "mae", "r2", "mae_se" (standard error of the MAE,
    cases as the units); "dummy" holds the dummy's scores; "importances" feature ->
    importance (forest; empty for MiniRocket); "test" the same scores on ``test`` (with its
    dataset, n_rows, n_cases; a list of them for a list)."""
    from sklearn.model_selection import GroupKFold, cross_val_predict

    data = data if isinstance(data, Samples) else Samples(data)
    if model not in models.MODELS:
        raise InputError("--model", f"must be one of {models.MODELS}, got {model!r}")
    trees = check_trees(trees, model)
    _check_target(data, target)
    inputs = _Inputs(model, data, sensors, normalise)
    tests = [] if test is None else test if isinstance(test, list | tuple) else [test]
    for other in tests:
        _check_target(other, target, "--test")
        inputs.check(other)
    keep = data.table[target].notna().to_numpy()
    x, y = inputs.x(data, keep), data.table[target].to_numpy()[keep]
    if groups not in data.table.columns:
        raise InputError("--groups", f"the feature table has no column {groups!r}")
    group_of = data.table[groups].to_numpy()[keep]
    n_groups = len(np.unique(group_of))
    if n_groups < folds:
        raise InputError("--folds", f"needs at least {folds} {groups} values, found {n_groups}")
    n_cases = len(np.unique(data.table["case"].to_numpy()[keep]))
    classify = target == "label"
    if classify and len(np.unique(y)) < 2:
        raise InputError("--target", f"needs two classes or more, found only {np.unique(y)}")
    cv = GroupKFold(n_splits=folds)
    pred = cross_val_predict(
        models.make(model, classify, seed, trees), x, y, groups=group_of, cv=cv
    )
    floor = cross_val_predict(models.dummy(classify), x, y, groups=group_of, cv=cv)
    out = {
        "model": model,
        **({"trees": trees} if model == "forest" else {}),
        "normalise": bool(normalise),
        "target": target,
        "n_rows": len(y),
        "n_cases": n_cases,
        "folds": folds,
        "groups": groups,
        "sensors": inputs.sensors,
        "features": inputs.names,
        **_scores(classify, y, pred, floor, data.table["case"].to_numpy()[keep]),
        "importances": {},
    }
    if model == "forest" or tests:
        fitted = models.make(model, classify, seed, trees).fit(x, y)
        if model == "forest":
            out["importances"] = _importances(fitted[-1], inputs.names)
        scored = [_test_scores(t, target, inputs, fitted, x, y, classify) for t in tests]
        if scored:
            out["test"] = scored if isinstance(test, list | tuple) else scored[0]
    return out


def check_trees(trees, model) -> int:
    """The forest's number of trees: ``models.TREES`` if None; InputError (``--trees``) for
    anything but a positive integer, or for trees asked of another model."""
    if trees is None:
        return models.TREES
    if model != "forest":
        raise InputError("--trees", f"applies to --model forest only, not {model!r}")
    if isinstance(trees, bool) or not isinstance(trees, int | np.integer) or trees < 1:
        raise InputError("--trees", f"must be >= 1 (a whole number), got {trees!r}")
    return int(trees)


def _check_target(samples, target, field="--target"):
    if target not in TARGETS:
        raise InputError("--target", f"must be one of {TARGETS}, got {target!r}")
    if target not in samples.table.columns:
        where = "the feature table" if field == "--target" else f"{samples.name}"
        raise InputError(field, f"{where} has no column {target!r} (the target)")


class _Inputs:
    """What the model reads of a Samples: feature columns (forest) or sensor channels."""

    def __init__(self, model, data, sensors, normalise):
        self.model, self.normalise = model, normalise
        if model == "forest":
            self.names = models.feature_columns(data.table, sensors, scale_free=normalise)
            if not self.names:
                raise InputError("--sensors", f"no feature columns of sensors {sensors}")
            self.sensors = sorted({c.partition(".")[0] for c in self.names})
            return
        if data.windows is None:
            raise InputError("--model", "minirocket needs the raw windows (Samples.windows)")
        self.sensors = list(sensors) if sensors else list(data.sensors)
        missing = [s for s in self.sensors if s not in data.sensors]
        if missing:
            raise InputError("--sensors", f"{data.name} has no sensor {missing[0]!r}")
        self.names = list(self.sensors)
        self.samples, self.sample_rate = data.windows.shape[-1], data.sample_rate

    def check(self, other):
        """InputError naming what ``other`` lacks that the model reads."""
        if self.model == "forest":
            missing = [c for c in self.names if c not in other.table.columns]
            if missing:
                raise InputError("--test", f"{other.name} has no column {missing[0]!r} (TRAIN's)")
            return
        if other.windows is None:
            raise InputError("--test", f"{other.name}: minirocket needs its raw windows")
        missing = [s for s in self.sensors if s not in other.sensors]
        if missing:
            raise InputError("--test", f"{other.name} has no sensor {missing[0]!r} (TRAIN's)")
        same = (other.windows.shape[-1], other.sample_rate) == (self.samples, self.sample_rate)
        if not same:
            raise InputError(
                "--test",
                f"{other.name}'s windows are {other.windows.shape[-1]} samples at "
                f"{other.sample_rate:g} Hz, TRAIN's {self.samples} at {self.sample_rate:g} Hz",
            )

    def x(self, samples, keep):
        """The model's input of the rows ``keep`` of ``samples``."""
        if self.model == "forest":
            x = samples.table[self.names].to_numpy(float)[keep]
            # an undefined feature (e.g. no decay after the peak) is imputed, never a dropped row
            return np.where(np.isfinite(x), x, np.nan)
        idx = [samples.sensors.index(s) for s in self.sensors]
        w = samples.windows[keep][:, idx, :]
        return models.normalised(w) if self.normalise else np.asarray(w, dtype=float)


def _scores(classify, y, pred, floor, groups) -> dict:
    if classify:
        classes = sorted(np.unique(np.concatenate([y, pred])))
        out = _class_scores(y, pred, classes)
        out["dummy"] = _class_scores(y, floor, classes)
        out["dummy"].pop("confusion")
        return out
    out = {**_reg_scores(y, pred), "mae_se": _case_se(np.abs(pred - y), groups)}
    out["dummy"] = {**_reg_scores(y, floor), "mae_se": _case_se(np.abs(floor - y), groups)}
    return out


def _test_scores(test, target, inputs, fitted, x, y, classify) -> dict:
    keep = test.table[target].notna().to_numpy()
    x_test, y_test = inputs.x(test, keep), test.table[target].to_numpy()[keep]
    groups = test.table["case"].to_numpy()[keep]
    floor = models.dummy(classify).fit(x, y).predict(x_test)
    out = {"dataset": test.name, "n_rows": len(y_test), "n_cases": len(np.unique(groups))}
    return {**out, **_scores(classify, y_test, fitted.predict(x_test), floor, groups)}


def _importances(forest, names) -> dict:
    importances = forest.feature_importances_  # (a property: every read sums all the trees)
    order = np.argsort(importances)[::-1]
    return {names[i]: float(importances[i]) for i in order}


def _class_scores(y, pred, classes) -> dict:
    from sklearn import metrics

    return {
        "accuracy": float(metrics.accuracy_score(y, pred)),
        "f1_macro": float(metrics.f1_score(y, pred, average="macro")),
        "classes": [str(c) for c in classes],
        "confusion": metrics.confusion_matrix(y, pred, labels=classes).tolist(),
    }


def _case_se(errors, groups) -> float:
    """Standard error of the mean of ``errors`` with cases as the independent units: the
    standard deviation of the per-case means over sqrt(cases) (windows of a case are not
    independent)."""
    import pandas as pd

    per_case = pd.Series(errors).groupby(groups).mean()
    return float(per_case.std(ddof=1) / np.sqrt(len(per_case))) if len(per_case) > 1 else np.nan


def _reg_scores(y, pred) -> dict:
    from sklearn import metrics

    return {
        "mae": float(metrics.mean_absolute_error(y, pred)),
        "r2": float(metrics.r2_score(y, pred)) if len(y) > 1 else np.nan,
    }
