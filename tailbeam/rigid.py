"""Moved to ``tailbeam.solvers.rigid`` (issue 7); this old path was shown to users."""

from tailbeam.solvers.rigid import *  # noqa: F403
from tailbeam.solvers.rigid import __all__  # noqa: F401
