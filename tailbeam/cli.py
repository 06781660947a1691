"""The ``tailbeam`` command: ``reproduce``, ``simulate``, ``modes``.

Each sub-command lives in ``tailbeam.commands.<name>`` with ``add_arguments(parser)`` and
``run(args) -> int``. Errors a user can fix (InputError, WorkLimitError, unreadable files) become
one line on stderr and exit code 2; no traceback.
"""

import argparse
import importlib
import sys

from tailbeam.errors import InputError, WorkLimitError

COMMANDS = {
    "reproduce": "reproduce the paper's rigid-plate scenarios (4.1-4.3) and check its claims",
    "simulate": "simulate a scene file (TOML) and write impacts.csv and time series",
    "modes": "compute the plate's natural frequencies and mode shapes",
    "sweep": "run a parameter sweep on Dask and write a labelled dataset (Zarr, Parquet)",
    "features": "compute signal features of a sweep dataset into features.parquet",
    "learn": "cross-validated scikit-learn baseline: how separable coal and gangue are",
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="tailbeam", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, help_text in COMMANDS.items():
        module = importlib.import_module(f"tailbeam.commands.{name}")
        p = sub.add_parser(name, help=help_text, description=help_text)
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args._run(args) or 0)
    except (InputError, WorkLimitError) as err:
        print(f"tailbeam {args.command}: error: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        print(
            f"tailbeam {args.command}: error: {err.strerror or err}: {err.filename}",
            file=sys.stderr,
        )
        return 2
    except KeyboardInterrupt:
        print(f"tailbeam {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
