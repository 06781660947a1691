"""Baselines of how separable the classes are: scikit-learn on the feature table.

The model is a pipeline of a median imputer (for features undefined on a window, e.g. the
decay rate of a window whose loudest frame is its last), a standard scaler and a random forest
(classifier for ``label``, regressor for ``gangue_fraction``), scored by cross-validation
grouped by case (``GroupKFold``): windows of one case never sit in training and test at once, so
repeated impacts of one ball cannot leak. Beside the model, a majority-class (or mean) dummy
is scored on the same folds as the floor to compare with. Feature importances are the
forest's impurity decrease, from a fit on all rows.
"""

import numpy as np

from tailbeam.errors import InputError
from tailbeam.study.features import is_feature_name

TARGETS = ("label", "gangue_fraction")


def feature_columns(table, sensors=None) -> list:
    """Signal-feature columns (``<sensor>.<feature>``), optionally of some sensors only."""
    cols = []
    for c in table.columns:
        sensor, _, name = c.partition(".")
        if is_feature_name(name) and (sensors is None or sensor in sensors):
            cols.append(c)
    return cols


def _model(classify: bool, seed: int):
    from sklearn.ensemble import RandomForestClassifier, RandomForestRegressor
    from sklearn.impute import SimpleImputer
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    forest = RandomForestClassifier if classify else RandomForestRegressor
    return make_pipeline(
        SimpleImputer(strategy="median"),
        StandardScaler(),
        forest(n_estimators=200, random_state=seed, n_jobs=1),
    )


def _dummy(classify: bool):
    from sklearn.dummy import DummyClassifier, DummyRegressor

    return DummyClassifier(strategy="most_frequent") if classify else DummyRegressor()


def learn(table, target="label", *, folds=5, seed=0, sensors=None) -> dict:
    """Cross-validated scores of the model and the dummy on ``table`` (a feature table).

    Returns a dict: target, n_rows, n_cases, folds, features, and for a label "accuracy",
    "f1_macro", "classes", "confusion" (rows true, columns predicted), or for gangue_fraction
    "mae", "r2", "mae_se" (standard error of the MAE, cases as the units); "dummy" holds the
    dummy's scores; "importances" feature -> importance."""
    from sklearn import metrics
    from sklearn.model_selection import GroupKFold, cross_val_predict

    if target not in TARGETS:
        raise InputError("--target", f"must be one of {TARGETS}, got {target!r}")
    if target not in table.columns:
        raise InputError("--target", f"the feature table has no column {target!r}")
    cols = feature_columns(table, sensors)
    # an undefined feature (e.g. no decay after the peak) is imputed, never a dropped row
    table = table.replace([np.inf, -np.inf], np.nan).dropna(subset=[target])
    groups = table["case"].to_numpy()
    n_cases = len(np.unique(groups))
    if n_cases < folds:
        raise InputError("--folds", f"needs at least {folds} cases, the dataset has {n_cases}")
    x = table[cols].to_numpy(float)
    y = table[target].to_numpy()
    classify = target == "label"
    if classify and len(np.unique(y)) < 2:
        raise InputError("--target", f"needs two classes or more, found only {np.unique(y)}")
    cv = GroupKFold(n_splits=folds)
    pred = cross_val_predict(_model(classify, seed), x, y, groups=groups, cv=cv)
    floor = cross_val_predict(_dummy(classify), x, y, groups=groups, cv=cv)
    out = {
        "target": target,
        "n_rows": len(y),
        "n_cases": n_cases,
        "folds": folds,
        "features": cols,
    }
    if classify:
        classes = sorted(np.unique(y))
        out.update(_class_scores(metrics, y, pred, classes))
        out["dummy"] = _class_scores(metrics, y, floor, classes)
        out["dummy"].pop("confusion")
    else:
        out.update(_reg_scores(metrics, y, pred), mae_se=_case_se(np.abs(pred - y), groups))
        out["dummy"] = _reg_scores(metrics, y, floor)
        out["dummy"]["mae_se"] = _case_se(np.abs(floor - y), groups)
    forest = _model(classify, seed).fit(x, y)[-1]
    order = np.argsort(forest.feature_importances_)[::-1]
    out["importances"] = {cols[i]: float(forest.feature_importances_[i]) for i in order}
    return out


def _class_scores(metrics, y, pred, classes) -> dict:
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


def _reg_scores(metrics, y, pred) -> dict:
    return {
        "mae": float(metrics.mean_absolute_error(y, pred)),
        "r2": float(metrics.r2_score(y, pred)),
    }


def confusion_figure(scores: dict, path, title: str = ""):
    """Confusion matrix (counts and row fractions) of a classification result, as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cm = np.asarray(scores["confusion"], dtype=float)
    frac = cm / np.maximum(cm.sum(axis=1, keepdims=True), 1)
    fig, ax = plt.subplots(figsize=(4.2, 3.8), constrained_layout=True)
    ax.imshow(frac, cmap="Blues", vmin=0, vmax=1)
    for i in range(cm.shape[0]):
        for j in range(cm.shape[1]):
            colour = "white" if frac[i, j] > 0.6 else "black"
            ax.text(j, i, f"{cm[i, j]:.0f}\n{frac[i, j]:.0%}", ha="center", va="center",
                    color=colour)  # fmt: skip
    ticks = range(len(scores["classes"]))
    ax.set_xticks(ticks, scores["classes"])
    ax.set_yticks(ticks, scores["classes"])
    ax.set_xlabel("predicted")
    ax.set_ylabel("true")
    ax.set_title(
        title
        or f"accuracy {scores['accuracy']:.1%}, F1 {scores['f1_macro']:.2f}\n"
        f"({scores['n_rows']} windows, {scores['n_cases']} cases, grouped {scores['folds']}-fold)",
        fontsize=9,
    )
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def importance_figure(scores: dict, path, top: int = 15):
    """Bar chart of the ``top`` feature importances, as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    items = list(scores["importances"].items())[:top][::-1]
    fig, ax = plt.subplots(figsize=(5.5, 0.25 * len(items) + 1.2), constrained_layout=True)
    ax.barh([k for k, _ in items], [v for _, v in items], color="tab:blue")
    ax.set_xlabel("importance (mean impurity decrease; all features sum to 1)")
    ax.set_title(
        f"random forest, target {scores['target']} (band_, wp_: energy fractions)", fontsize=9
    )
    ax.tick_params(axis="y", labelsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
