"""The ``tailbeam`` command and its sub-commands.

Each sub-command is a module of ``tailbeam.cli`` with ``add_arguments(parser)`` and
``run(args) -> int``. Errors a user can fix (InputError, WorkLimitError, unreadable files, bad
arguments) become one line on stderr and exit code 2; no traceback. Progress and automatic
choices go to stderr (tailbeam.progress); ``--quiet`` silences them.
"""

import argparse
import sys

from tailbeam._version import __version__
from tailbeam.cli import export, features, import_, learn, modes, reproduce, simulate, sweep
from tailbeam.errors import InputError, WorkLimitError
from tailbeam.progress import set_quiet

COMMANDS = {
    "reproduce": (
        reproduce,
        "reproduce the paper's rigid-plate scenarios (4.1-4.3) and check its claims",
    ),
    "simulate": (simulate, "simulate a scene file (TOML) and write impacts.csv and time series"),
    "modes": (modes, "compute the plate's natural frequencies and mode shapes"),
    "sweep": (sweep, "run a parameter sweep on Dask and write a labelled dataset (Zarr, Parquet)"),
    "features": (features, "compute signal features of a sweep dataset into features.parquet"),
    "learn": (learn, "cross-validated scikit-learn baseline: how separable coal and gangue are"),
    "export": (export, "write a dataset's signals as UFF 58 files (one per case) and labels.csv"),
    "import": (import_, "measured recordings (WAV, CSV, UFF, TDMS, MAT, HDF5) into a dataset"),
}


DESCRIPTION = (
    "Simulate coal and gangue striking the tail beam of a mining support, and the "
    "vibration its sensors measure."
)


class HelpFormatter(argparse.HelpFormatter):
    """Every option's help ends with its default, as ``(default: X)``, or ``(required)``,
    unless the help text already gives it or there is none (a flag, an option without a
    value); choices show as ``{a,b,c}`` (argparse)."""

    def _get_help_string(self, action):
        text = action.help or ""
        default = action.default
        if "(default" in text or "(required)" in text or not action.option_strings:
            return text
        if action.required:
            return f"{text} (required)"
        if default is None or default is False or default is argparse.SUPPRESS:
            return text
        if isinstance(default, (list, tuple)):
            default = " ".join(str(v) for v in default)
        return f"{text} (default: {str(default).replace('%', '%%')})"


class UsageError(Exception):
    """A command-line argument error, reported as one line (exit 2)."""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``tailbeam simulate: error: ... (see --help)``."""

    def error(self, message):
        raise UsageError(f"{self.prog}: error: {message} (see '{self.prog} --help')")


def _common_options() -> argparse.ArgumentParser:
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument(
        "-q", "--quiet", action="store_true", help="no progress or notes on stderr (errors stay)"
    )
    return common


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="tailbeam", description=DESCRIPTION, formatter_class=HelpFormatter)
    parser.add_argument("--version", action="version", version=f"tailbeam {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    common = _common_options()
    for name, (module, help_text) in COMMANDS.items():
        p = sub.add_parser(
            name,
            help=help_text,
            description=help_text,
            parents=[common],
            formatter_class=HelpFormatter,
        )
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
    return parser


def _parse(argv):
    """Parsed arguments, or (None, exit code) after printing one line."""
    try:
        return build_parser().parse_args(argv), 0
    except UsageError as err:
        print(err, file=sys.stderr)
        return None, 2


def _cli_field(args, err: InputError) -> str:
    """The error's line, naming the option the user typed when the field is one
    (``--bc`` rather than the library's ``boundary``; a command lists them in CLI_FIELDS)."""
    fields = getattr(COMMANDS[args.command][0], "CLI_FIELDS", {})
    head, _, rest = err.field.partition(".")
    if head in fields:
        return f"{fields[head]}{'.' + rest if rest else ''}: {err.rule}"
    return str(err)


def main(argv=None) -> int:
    args, code = _parse(argv)
    if args is None:
        return code
    set_quiet(getattr(args, "quiet", False))
    args.argv = list(sys.argv[1:] if argv is None else argv)  # the command, for provenance
    try:
        return int(args._run(args) or 0)
    except InputError as err:
        print(f"tailbeam {args.command}: error: {_cli_field(args, err)}", file=sys.stderr)
        return 2
    except WorkLimitError as err:
        print(f"tailbeam {args.command}: error: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        where = f": {err.filename}" if err.filename else ""
        print(f"tailbeam {args.command}: error: {err.strerror or err}{where}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"tailbeam {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
