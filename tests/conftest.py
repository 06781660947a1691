"""Test-suite setup: the modal-basis cache lives in a fresh folder per test session, so results
never come from (or go to) a user's ~/.cache/tailbeam and every run measures cold work."""

import os
import tempfile

_CACHE = tempfile.mkdtemp(prefix="tailbeam-test-cache-")
os.environ["TAILBEAM_CACHE_DIR"] = _CACHE
