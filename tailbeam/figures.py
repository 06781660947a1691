"""Moved to ``tailbeam.paper.figures`` (issue 7); this old path was shown to users."""

import sys

from tailbeam.paper import figures

sys.modules[__name__] = figures  # the same module object under both names
