"""The package version, read by ``tailbeam.__version__``, the CLI and the basis cache."""

__version__ = "0.3.0"
