"""`tailbeam learn DATASET --target label|gangue_fraction`: a cross-validated scikit-learn
baseline (grouped by case) on DATASET/features.parquet (computed with default windows if
missing). Writes learn.json, importances.csv, and confusion.png (label) and importances.png
into --out (default DATASET/learn)."""

import json
from pathlib import Path

from tailbeam.errors import InputError


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
        "--out", default=None, metavar="DIR", help="output folder (default: DATASET/learn)"
    )


def run(args) -> int:
    from tailbeam.study import require_study_dependencies

    require_study_dependencies()
    import pandas as pd

    from tailbeam.study.learn import confusion_figure, importance_figure, learn
    from tailbeam.study.windows import feature_table, open_dataset

    if args.folds < 2:
        raise InputError("--folds", f"must be >= 2, got {args.folds}")
    _ds, folder = open_dataset(args.dataset)
    path = folder / "features.parquet"
    table = pd.read_parquet(path) if path.is_file() else feature_table(args.dataset)
    sensors = args.sensors.split(",") if args.sensors else None
    scores = learn(table, args.target, folds=args.folds, sensors=sensors)
    out = Path(args.out) if args.out else folder / "learn"
    out.mkdir(parents=True, exist_ok=True)
    (out / "learn.json").write_text(json.dumps(scores, indent=2) + "\n")
    pd.Series(scores["importances"], name="importance").rename_axis("feature").to_csv(
        out / "importances.csv"
    )
    importance_figure(scores, out / "importances.png")
    if "accuracy" in scores:
        confusion_figure(scores, out / "confusion.png")
        line = f"accuracy {scores['accuracy']:.3f}, F1 {scores['f1_macro']:.3f}"
        floor = f"majority class {scores['dummy']['accuracy']:.3f}"
    else:
        line = f"MAE {scores['mae']:.4f}, R^2 {scores['r2']:.3f}"
        floor = f"mean predictor MAE {scores['dummy']['mae']:.4f}"
    print(
        f"{args.dataset}: {args.target}: {line} ({floor}); {scores['n_rows']} windows, "
        f"{scores['n_cases']} cases, {args.folds}-fold grouped by case -> {out}"
    )
    return 0
