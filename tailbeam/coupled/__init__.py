"""Moved to ``tailbeam.solvers.coupled`` (issue 7); this old path was shown to users."""

from tailbeam.solvers.coupled import *  # noqa: F403
from tailbeam.solvers.coupled import __all__  # noqa: F401
