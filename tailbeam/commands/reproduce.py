"""`tailbeam reproduce` (not yet implemented)."""

from tailbeam.errors import InputError


def add_arguments(parser):
    parser.add_argument("--out", default="out/reproduce", help="output directory")


def run(args) -> int:
    raise InputError("command", "'reproduce' is not implemented yet")
