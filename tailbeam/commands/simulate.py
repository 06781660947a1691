"""`tailbeam simulate` (not yet implemented)."""

from tailbeam.errors import InputError


def add_arguments(parser):
    parser.add_argument("--out", default="out/simulate", help="output directory")


def run(args) -> int:
    raise InputError("command", "'simulate' is not implemented yet")
