"""`tailbeam export DATASET [--format uff58] [--out DIR]`: a dataset's signals as UFF 58 files
(one per case) and labels.csv, for modal and vibration software (tailbeam.study.export; needs
``tailbeam[study]``). Also the ``--export`` option of `simulate` and `sweep`, and the export of
one simulation run (DIR/uff/<scene>.uff and DIR/uff/labels.csv).
"""

import argparse
from pathlib import Path

FORMATS = ("uff58",)
CLI_FIELDS = {"format": "--format"}


def formats(text: str) -> list:
    """argparse type of ``--export``: one format or a comma list of them."""
    names = [t.strip() for t in text.split(",") if t.strip()]
    bad = [n for n in names if n not in FORMATS]
    if bad or not names:
        raise argparse.ArgumentTypeError(
            f"unknown format {(bad or [text])[0]!r}; choose from {', '.join(FORMATS)}"
        )
    return names


def add_export_option(parser, what: str) -> None:
    """The ``--export FORMAT[,FORMAT]`` option (repeatable) of a command writing ``what``."""
    parser.add_argument(
        "--export",
        type=formats,
        action="append",
        default=[],
        metavar="FORMAT",
        help=f"also write {what} as FORMAT: {', '.join(FORMATS)} (repeatable or a comma list)",
    )


def chosen(args) -> list:
    """The formats of ``--export``, each once, in the order given."""
    return list(dict.fromkeys(f for group in args.export for f in group))


def check_run_export(scene, field: str = "--export") -> None:
    """Refuse, before the work, to export a scene that records no sensor signals."""
    from tailbeam.errors import InputError

    if not scene.sensors or scene.plate_model != "modal":
        raise InputError(
            field,
            'needs sensor records: [[sensors]] on a modal plate (plate.model = "modal")',
        )


def write_run_uff(out_dir: Path, scene_path, scene, result) -> list:
    """DIR/uff/<scene stem>.uff (one dataset 58 per sensor) and DIR/uff/labels.csv (``file``,
    ``label`` and the scene's other labels: tailbeam.study.labels.case_labels)."""
    from tailbeam.io.output import describe
    from tailbeam.io.uff import UNIT, note_interval, write_labels_csv, write_uff58
    from tailbeam.study.labels import case_labels

    folder = Path(out_dir) / "uff"
    folder.mkdir()
    stem = Path(scene_path).stem
    labels = case_labels(scene)
    outputs = result.sensor_outputs
    rates = {name: out.chain.sample_rate for name, out in outputs.items()}
    for rate in sorted(set(rates.values())):
        note_interval(rate)
    path = write_uff58(
        folder / f"{stem}.uff",
        {name: out.acceleration for name, out in outputs.items()},
        rates,
        case=stem,
        label=labels["label"],
    )
    describe(path, units={"t": "s", "acceleration": UNIT}, sample_rate_hz=rates)
    row = {"file": path.name, **labels}
    return [path, write_labels_csv(folder / "labels.csv", [row])]


def add_arguments(parser):
    parser.add_argument("dataset", help="a dataset folder (it holds dataset.zarr)")
    parser.add_argument("--format", default="uff58", choices=FORMATS, help="file format")
    parser.add_argument("--out", default=None, help="export folder (default: DATASET/uff)")


def run(args) -> int:
    from tailbeam.study import require_study_dependencies
    from tailbeam.study.export import check_format, export_dataset, zarr_path

    check_format(args.format)
    require_study_dependencies()
    zarr_path(args.dataset)
    out = args.out or str(Path(args.dataset) / "uff")
    s = export_dataset(args.dataset, out, args.format, command=f"tailbeam export {args.dataset}")
    print(f"{args.dataset}: {s['cases']} cases written as UFF 58 files and labels.csv to {out}")
    return 0
