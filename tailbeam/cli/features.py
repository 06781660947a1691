"""`tailbeam features DATASET [--window impact|fixed] [--length S]`: signal features of a sweep
dataset (tailbeam.study.windows) written to DATASET/features.parquet."""

from pathlib import Path

from tailbeam.errors import InputError


def add_arguments(parser):
    parser.add_argument("dataset", help="a sweep's output folder (with dataset.zarr)")
    parser.add_argument(
        "--window",
        default="impact",
        choices=("impact", "fixed"),
        help="impact: one window per plate impact; fixed: consecutive windows",
    )
    parser.add_argument("--length", type=float, default=0.02, metavar="S", help="window length, s")
    parser.add_argument(
        "--pre",
        type=float,
        default=0.0005,
        metavar="S",
        help="impact windows start this long before the impact, s",
    )
    parser.add_argument(
        "--out",
        default=None,
        metavar="FILE",
        help="feature table, Parquet (default: DATASET/features.parquet)",
    )


def run(args) -> int:
    from tailbeam.study import require_study_dependencies

    require_study_dependencies()
    from tailbeam.study.windows import feature_table, open_dataset

    if not args.length > 0:
        raise InputError("--length", f"must be > 0 s, got {args.length}")
    if not args.pre >= 0:
        raise InputError("--pre", f"must be >= 0 s, got {args.pre}")
    _ds, folder = open_dataset(args.dataset)
    table = feature_table(args.dataset, window=args.window, length=args.length, pre=args.pre)
    out = Path(args.out) if args.out else folder / "features.parquet"
    table.to_parquet(out)
    print(f"{args.dataset}: {len(table)} {args.window} windows x {table.shape[1]} columns -> {out}")
    return 0
