"""`tailbeam import FILES... --labels LABELS.csv --out DIR`: measured recordings (WAV, CSV, UFF
58, TDMS, MAT, HDF5) into DIR/dataset.zarr, impacts.parquet and cases.csv, the layout of a
sweep (tailbeam.study.recordings), so `features` and `learn` run on them."""

import shlex
import sys

from tailbeam.errors import InputError
from tailbeam.progress import note


def add_arguments(parser):
    parser.add_argument("files", nargs="+", metavar="FILES", help="recordings to import")
    parser.add_argument(
        "--labels", required=True, metavar="LABELS.csv", help="one row per file: file, label, ..."
    )
    parser.add_argument("--out", required=True, metavar="DIR", help="output folder (the dataset)")
    parser.add_argument(
        "--sample-rate", type=float, default=None, metavar="HZ",
        help="common rate, Hz (default: the lowest file rate)",
    )  # fmt: skip
    parser.add_argument(
        "--cut",
        default="file",
        choices=("file", "fixed", "impacts"),
        help="one case per file, fixed windows, or a window per detected impact onset",
    )
    parser.add_argument(
        "--length", type=float, default=None, metavar="S",
        help="case length, s (default: required with fixed, 0.1 with impacts)",
    )  # fmt: skip
    parser.add_argument(
        "--pre", type=float, default=0.005, metavar="S",
        help="impact cases start this long before the onset, s",
    )  # fmt: skip
    parser.add_argument(
        "--threshold", type=float, default=8.0, metavar="X",
        help="onset: envelope over noise floor to exceed",
    )  # fmt: skip
    parser.add_argument(
        "--dead-time", type=float, default=0.05, metavar="S",
        help="onset: shortest time between onsets, s",
    )  # fmt: skip
    parser.add_argument(
        "--smooth", type=float, default=0.0005, metavar="S",
        help="onset: envelope time constant, s",
    )  # fmt: skip
    parser.add_argument(
        "--floor-window", type=float, default=1.0, metavar="S",
        help="onset: noise floor = envelope median over frames this long, s",
    )  # fmt: skip


def run(args) -> int:
    from tailbeam.study import require_study_dependencies

    require_study_dependencies()
    from tailbeam.study.recordings.driver import CHANNEL_RULE, check_out, run_import
    from tailbeam.study.recordings.onsets import OnsetOptions
    from tailbeam.study.recordings.plan import build_plan

    if args.length is not None and not args.length > 0:
        raise InputError("--length", f"must be > 0 s, got {args.length}")
    if not args.pre >= 0:
        raise InputError("--pre", f"must be >= 0 s, got {args.pre}")
    check_out(args.out)
    onsets = OnsetOptions(args.threshold, args.dead_time, args.smooth, args.floor_window)
    plan = build_plan(args.files, args.labels, sample_rate=args.sample_rate, cut=args.cut,
                      length=args.length, pre=args.pre, onsets=onsets)  # fmt: skip
    print(f"sensors: {', '.join(plan.sensors)} (the files' channel names; rule: {CHANNEL_RULE})")
    for line in plan.notes:
        note(line)
    command = shlex.join(["tailbeam", *getattr(args, "argv", sys.argv[1:])])
    done = run_import(plan, args.out, command, list(args.files))
    extra = f", {done['dropped']} onsets too near an end left out" if done["dropped"] else ""
    print(
        f"{args.out}: {done['cases']} cases x {len(plan.sensors)} sensors x {plan.n_time} "
        f"samples at {plan.fs:g} Hz (cut {plan.cut}), {done['impacts']} onsets{extra} "
        f"-> {args.out}/dataset.zarr"
    )
    return 0
