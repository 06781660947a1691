"""Test-suite setup: the modal-basis and compiled-kernel cache lives in a fresh folder per test
session, so results never come from (or go to) a user's ~/.cache/tailbeam and every run
measures cold work. pytest-xdist's workers inherit the folder from the process that starts
them (``TAILBEAM_TEST_CACHE_DIR``), so a kernel or a basis one worker has made is not made
again by the other (both are written atomically). ``TAILBEAM_TEST_CACHE_DIR=FOLDER`` makes a
session use (and keep) FOLDER instead.

Under ``python -m pytest -n 2`` (pyproject.toml's addopts: ``--dist loadfile
--no-loadscope-reorder``) each test file runs whole on one worker, the files handed out in
the order ``pytest_collection_modifyitems`` sets: FIRST, then the rest as collected. FIRST
starts with the files that compile the largest numba kernels, each on its own worker, so no
kernel is compiled by both workers at once (the cache only helps once a compile is done):
test_active_set the rigid and the stream kernels, test_learn_transfer the coupled kernel and
sktime's MiniRocket; the files that need those kernels come after, the longest first, so the
two workers finish together."""

import os
import sys
import tempfile

import pytest

_CACHE = os.environ.get("TAILBEAM_TEST_CACHE_DIR") or tempfile.mkdtemp(
    prefix="tailbeam-test-cache-"
)
os.environ["TAILBEAM_TEST_CACHE_DIR"] = _CACHE
os.environ["TAILBEAM_CACHE_DIR"] = _CACHE

# One BLAS thread per process, and in the processes the tests start (they inherit it): with
# OpenBLAS's default of a thread per core, two xdist workers oversubscribe the cores and the
# waiting threads burn CPU (as in the eigen-solves, which run on one: docs/plate-modes.md).
for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")
if "numpy" in sys.modules:  # (loaded before this file: the variables came too late)
    from threadpoolctl import threadpool_limits

    threadpool_limits(int(os.environ["OPENBLAS_NUM_THREADS"]), user_api="blas")

# CPU seconds on a fresh cache, measured: ~50 each for the first two, then 80 down to ~8
FIRST = [
    "test_active_set.py",
    "test_learn_transfer.py",
    "test_study_examples.py",
    "test_cli.py",
    "test_coupled_fe.py",
    "test_stream_solver.py",
    "test_stream_reference_modal.py",
    "test_active_set_modal.py",
    "test_study_sweep.py",
    "test_study_learn.py",
    "test_friction_modal.py",
    "test_stream_reference.py",
    "test_friction_fast.py",
    "test_stream_convergence.py",
    "test_coupled_numerics.py",
    "test_recordings_roundtrip.py",
    "test_solid_scene.py",
    "test_coupled_ritz_tail.py",
    "test_figures.py",
    "test_study_structure_sweep.py",
    "test_plate_ssss.py",
    "test_friction_reference.py",
    "test_mode_labels.py",
    "test_coupled_contact_solve.py",
    "test_claims.py",
]


def pytest_collection_modifyitems(items):
    """The files of FIRST first, in that order; every file's own tests in their order."""
    rank = {name: i for i, name in enumerate(FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(FIRST)))  # (a stable sort)


@pytest.fixture(autouse=True)
def _progress_not_quiet():
    """Every test starts with tailbeam.progress speaking: an in-process CLI call with -q sets
    it quiet for the process, which made later progress tests depend on how pytest-xdist
    split the suite."""
    from tailbeam.progress import set_quiet

    set_quiet(False)
    yield
    set_quiet(False)
