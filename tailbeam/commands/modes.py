"""`tailbeam modes` (not yet implemented)."""

from tailbeam.errors import InputError


def add_arguments(parser):
    parser.add_argument("--out", default="out/modes", help="output directory")


def run(args) -> int:
    raise InputError("command", "'modes' is not implemented yet")
