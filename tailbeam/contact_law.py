"""Moved to ``tailbeam.physics.contact_law`` (issue 7); this old path was shown to users."""

import sys

from tailbeam.physics import contact_law

sys.modules[__name__] = contact_law  # the same module object under both names
