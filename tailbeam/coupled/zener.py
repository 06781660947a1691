"""Moved to ``tailbeam.solvers.coupled.zener`` (issue 7); this old path was shown to users."""

import sys

from tailbeam.solvers.coupled import zener

sys.modules[__name__] = zener  # the same module object under both names
