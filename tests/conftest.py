"""Test-suite setup: the modal-basis and compiled-kernel cache lives in a fresh folder per test
session, so results never come from (or go to) a user's ~/.cache/tailbeam and every run
measures cold work. pytest-xdist's workers inherit the folder from the process that starts
them (``TAILBEAM_TEST_CACHE_DIR``), so a kernel or a basis one worker has made is not made
again by the other (both are written atomically). ``TAILBEAM_TEST_CACHE_DIR=FOLDER`` makes a
session use (and keep) FOLDER instead."""

import os
import tempfile

import pytest

_CACHE = os.environ.get("TAILBEAM_TEST_CACHE_DIR") or tempfile.mkdtemp(
    prefix="tailbeam-test-cache-"
)
os.environ["TAILBEAM_TEST_CACHE_DIR"] = _CACHE
os.environ["TAILBEAM_CACHE_DIR"] = _CACHE


@pytest.fixture(autouse=True)
def _progress_not_quiet():
    """Every test starts with tailbeam.progress speaking: an in-process CLI call with -q sets
    it quiet for the process, which made later progress tests depend on how pytest-xdist
    split the suite."""
    from tailbeam.progress import set_quiet

    set_quiet(False)
    yield
    set_quiet(False)
