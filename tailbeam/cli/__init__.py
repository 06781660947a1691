"""The ``tailbeam`` command line: ``main`` (the entry point) and one module per command."""

from tailbeam.cli.main import build_parser, main

__all__ = ["build_parser", "main"]
