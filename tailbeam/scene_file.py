"""Moved to ``tailbeam.io.scene_file`` (issue 7); this old path was shown to users."""

import sys

from tailbeam.io import scene_file

sys.modules[__name__] = scene_file  # the same module object under both names
