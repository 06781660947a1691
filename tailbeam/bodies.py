"""Moved to ``tailbeam.physics.bodies`` (issue 7); this old path was shown to users."""

import sys

from tailbeam.physics import bodies

sys.modules[__name__] = bodies  # the same module object under both names
