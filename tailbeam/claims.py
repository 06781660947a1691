"""Moved to ``tailbeam.paper.claims`` (issue 7); this old path was shown to users."""

import sys

from tailbeam.paper import claims

sys.modules[__name__] = claims  # the same module object under both names
