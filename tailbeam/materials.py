"""Moved to ``tailbeam.physics.materials`` (issue 7); this old path was shown to users."""

import sys

from tailbeam.physics import materials

sys.modules[__name__] = materials  # the same module object under both names
