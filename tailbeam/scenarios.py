"""Moved to ``tailbeam.paper.scenarios`` (issue 7); this old path was shown to users."""

import sys

from tailbeam.paper import scenarios

sys.modules[__name__] = scenarios  # the same module object under both names
