"""`tailbeam learn DATASET --target label|gangue_fraction [--model forest|minirocket]
[--test OTHER] [--normalise]`: a scikit-learn baseline cross-validated by case on DATASET's
windows (features.parquet, computed with default windows if missing; MiniRocket: the raw
windows of the same settings), and with --test its score on another dataset. Writes
learn.json, and confusion.png (label), importances.csv and importances.png (forest) into
--out (default DATASET/learn)."""

import json
from pathlib import Path

from tailbeam.errors import InputError

DEFAULT_WINDOWS = {"window": "impact", "length": 0.02, "pre": 0.0005}


def add_arguments(parser):
    parser.add_argument("dataset", help="a sweep's output folder (with dataset.zarr)")
    parser.add_argument(
        "--target",
        default="label",
        choices=("label", "gangue_fraction"),
        help="label (classes) or gangue_fraction (regression)",
    )
    parser.add_argument(
        "--folds", type=int, default=5, metavar="K", help="cross-validation folds, grouped by case"
    )
    parser.add_argument(
        "--sensors",
        default=None,
        metavar="S1,S2",
        help="comma-separated sensor names to use (default: every sensor)",
    )
    parser.add_argument(
        "--groups",
        default="case",
        metavar="COLUMN",
        help="a column whose values never sit on both sides of a fold (source_file: cases cut "
        "from one recording)",
    )
    parser.add_argument(
        "--model",
        default="forest",
        choices=("forest", "minirocket"),
        help="a random forest on the features, or MiniRocket and ridge on the raw windows",
    )
    parser.add_argument(
        "--trees",
        type=int,
        default=None,
        metavar="N",
        help="the random forest's number of trees (default: 200; --model forest only)",
    )
    parser.add_argument(
        "--test",
        default=None,
        metavar="OTHER",
        help="another dataset to score the model on (default: none)",
    )
    parser.add_argument(
        "--normalise", action="store_true", help="blind to gain: scale-free input only"
    )
    parser.add_argument(
        "--out", default=None, metavar="DIR", help="output folder (default: DATASET/learn)"
    )


def run(args) -> int:
    from tailbeam.study import require_study_dependencies
    from tailbeam.study.models import MODELS

    require_study_dependencies()
    if args.folds < 2:
        raise InputError("--folds", f"must be >= 2, got {args.folds}")
    if args.model not in MODELS:
        raise InputError("--model", f"must be one of {MODELS}, got {args.model!r}")
    from tailbeam.study.learn import check_trees, learn
    from tailbeam.study.windows import open_dataset

    check_trees(args.trees, args.model)  # (before any dataset is read)
    if args.model == "minirocket":
        _require_sktime()

    ds, folder = open_dataset(args.dataset)
    sensors = args.sensors.split(",") if args.sensors else None
    if args.test:  # before any window is cut: OTHER records every sensor the model reads
        other = {str(s) for s in open_dataset(args.test)[0]["sensor"].values}
        needed = sensors or [str(s) for s in ds["sensor"].values]
        missing = [s for s in needed if s not in other]
        if missing:
            raise InputError("--test", f"{args.test} has no sensor {missing[0]!r} (TRAIN's)")
    train, settings = _samples(args.dataset, args.model, None, "TRAIN")
    test = _samples(args.test, args.model, settings, args.test)[0] if args.test else None
    scores = learn(
        train, args.target, folds=args.folds, sensors=sensors, model=args.model,
        normalise=args.normalise, test=test, groups=args.groups, trees=args.trees,
    )  # fmt: skip
    scores["windows"] = settings
    out = Path(args.out) if args.out else folder / "learn"
    _write(scores, out)
    print(_summary(args, scores, out))
    return 0


def _require_sktime():
    import importlib.util

    if importlib.util.find_spec("sktime") is None:
        raise InputError(
            "--model", "minirocket needs sktime; install it with pip install 'tailbeam[study]'"
        )


def _samples(path, model, settings, name):
    """(Samples of the dataset at ``path``, its window settings): features.parquet when it
    exists (and, for another dataset, was cut with ``settings``), else cut afresh."""
    import pandas as pd

    from tailbeam.progress import note
    from tailbeam.study.learn import Samples
    from tailbeam.study.windows import feature_table, open_dataset, window_table

    _ds, folder = open_dataset(path)
    stored = folder / "features.parquet"
    table = pd.read_parquet(stored) if stored.is_file() else None
    own = table.attrs.get("windows") if table is not None else None
    if settings is None:
        settings = own or dict(DEFAULT_WINDOWS)
        if table is not None and own is None:
            note(f"{stored} does not say its windows; taken as {DEFAULT_WINDOWS}")
    if model == "minirocket":
        meta, windows, sensors, fs = window_table(path, **settings)
        return Samples(meta, windows, sensors, fs, name), settings
    if table is None or (own is not None and own != settings):
        if table is not None:
            note(f"{stored} was cut with other windows; {name}'s features computed afresh")
        table = feature_table(path, **settings)
    return Samples(table, name=name), settings


def _write(scores: dict, out: Path) -> None:
    import pandas as pd

    from tailbeam.study.learn_figures import confusion_figure, importance_figure

    out.mkdir(parents=True, exist_ok=True)
    (out / "learn.json").write_text(json.dumps(scores, indent=2) + "\n")
    if scores["importances"]:
        pd.Series(scores["importances"], name="importance").rename_axis("feature").to_csv(
            out / "importances.csv"
        )
        importance_figure(scores, out / "importances.png")
    if "accuracy" in scores:
        confusion_figure(scores, out / "confusion.png")


def _score_text(s: dict) -> str:
    if "accuracy" in s:
        return (
            f"accuracy {s['accuracy']:.3f}, F1 {s['f1_macro']:.3f} "
            f"(majority class {s['dummy']['accuracy']:.3f})"
        )
    return f"MAE {s['mae']:.4f}, R^2 {s['r2']:.3f} (mean predictor MAE {s['dummy']['mae']:.4f})"


def _summary(args, scores: dict, out: Path) -> str:
    line = (
        f"{args.dataset}: {args.model}, {args.target}: {_score_text(scores)}; "
        f"{scores['n_rows']} windows, {scores['n_cases']} cases, {args.folds}-fold grouped by case"
    )
    if "test" in scores:
        t = scores["test"]
        line += (
            f"; on {args.test} (fitted on all of {args.dataset}): {_score_text(t)}; "
            f"{t['n_rows']} windows, {t['n_cases']} cases"
        )
    return f"{line} -> {out}"
