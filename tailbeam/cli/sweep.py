"""`tailbeam sweep SWEEP.toml --out DIR [--workers N | --scheduler ADDRESS]`: run a parameter
sweep on Dask and write a labelled dataset (tailbeam.study; needs ``tailbeam[study]``).

The sweep file and every case's scene are validated before any work (one-line errors, exit
code 2). Writes DIR/dataset.zarr, DIR/impacts.parquet and DIR/cases.csv; running it again
skips finished cases and retries failed ones.
"""

from tailbeam.errors import InputError


def add_arguments(parser):
    parser.add_argument("sweep", help="sweep file (TOML): scene, [axes], repeats, seed")
    parser.add_argument("--out", default="out/sweep", help="dataset folder (default out/sweep)")
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--workers", type=int, default=None, help="local Dask worker processes (default: cores)"
    )
    where.add_argument(
        "--scheduler", default=None, help="address of a running Dask scheduler (tcp://host:port)"
    )
    parser.add_argument(
        "--strict",
        action="store_true",
        help="refuse the sweep, before any case runs, if a case's band check estimates a "
        "peak-force error above the sweep file's band_accuracy",
    )


def run(args) -> int:
    from tailbeam.study import require_study_dependencies

    require_study_dependencies()
    if args.workers is not None and args.workers < 1:
        raise InputError("--workers", f"must be a whole number >= 1, got {args.workers}")
    from tailbeam.study.design import expand, load_sweep
    from tailbeam.study.sweep import run_sweep

    spec = load_sweep(args.sweep)
    cases = expand(spec)  # every case's scene validated before a worker starts
    if args.strict:
        _refuse_invalid(cases, spec.band_accuracy)
    s = run_sweep(spec, args.out, workers=args.workers, scheduler=args.scheduler, cases=cases)
    ran = s["ok"] + s["failed"]
    print(
        f"{args.sweep}: {s['cases']} cases, {s['skipped']} already done, {ran} run "
        f"({s['ok']} ok, {s['failed']} failed, {s.get('invalid', 0)} flagged invalid); dataset "
        f"in {args.out}"
    )
    return 1 if s["failed"] else 0


def _refuse_invalid(cases, accuracy: float) -> None:
    """--strict: InputError naming the first case whose band check exceeds ``accuracy``."""
    from tailbeam.study.sweep import invalid_up_front

    bad = invalid_up_front(cases, accuracy)
    if bad:
        number, case, columns = bad[0]
        shown = ", ".join(f"{k} = {v!r}" for k, v in case.params.items())
        raise InputError(
            "--strict",
            f"{len(bad)} of {len(cases)} cases exceed band_accuracy {accuracy:g}, first case "
            f"{number} ({shown}): band_force_error {columns['band_force_error']:.3g} at "
            f"{columns['band_hz'] / 1e3:g} kHz; raise plate.fmax in the base scene, narrow the "
            "axes, or raise band_accuracy in the sweep file",
        )
