"""`tailbeam sweep SWEEP.toml --out DIR [--workers N | --scheduler ADDRESS]`: run a parameter
sweep on Dask and write a labelled dataset (tailbeam.study; needs ``tailbeam[study]``).

The sweep file and every case's scene are validated before any work (one-line errors, exit
code 2). Writes DIR/dataset.zarr, DIR/impacts.parquet and DIR/cases.csv; running it again
skips finished cases and retries failed ones. --export uff58 then writes every finished case
as DIR/uff/case_<id>.uff with DIR/uff/labels.csv (tailbeam.study.export).
"""

from pathlib import Path

from tailbeam.cli import export
from tailbeam.errors import InputError


def add_arguments(parser):
    parser.add_argument("sweep", help="sweep file (TOML): scene, [axes], repeats, seed")
    parser.add_argument("--out", default="out/sweep", metavar="DIR", help="dataset folder")
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help="local Dask worker processes (default: one per core)",
    )
    where.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="address of a running Dask scheduler, tcp://host:port (default: a local cluster)",
    )
    export.add_export_option(parser, "every finished case (DIR/uff/)")
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
    if export.chosen(args):
        from tailbeam.io.output import check_output_dir

        check_output_dir(Path(args.out) / "uff", field="--export")
    if args.strict:
        _refuse_invalid(cases, spec.band_accuracy)
    s = run_sweep(spec, args.out, workers=args.workers, scheduler=args.scheduler, cases=cases)
    ran = s["ok"] + s["failed"]
    print(
        f"{args.sweep}: {s['cases']} cases, {s['skipped']} already done, {ran} run "
        f"({s['ok']} ok, {s['failed']} failed, {s.get('invalid', 0)} flagged invalid); dataset "
        f"in {args.out}"
    )
    for fmt in export.chosen(args):
        _export(args, fmt)
    return 1 if s["failed"] else 0


def _export(args, fmt: str) -> None:
    from tailbeam.progress import note
    from tailbeam.study.export import export_dataset

    if not (Path(args.out) / "dataset.zarr").is_dir():
        note(f"sweep: no finished case, nothing to export as {fmt}")
        return
    out = Path(args.out) / "uff"
    e = export_dataset(args.out, out, fmt, command=f"tailbeam sweep {args.sweep} --export {fmt}")
    print(f"{args.sweep}: {e['cases']} finished cases written as UFF 58 files to {out}")


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
