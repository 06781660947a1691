"""Results several test modules compare against (e.g. the full-FE references of
tests/test_coupled_fe.py, which tests/test_coupled_ritz_tail.py reads too), computed once per
test session.

A result is kept in the session's cache folder (``TAILBEAM_TEST_CACHE_DIR``, set by
tests/conftest.py) under its name and a hash of its inputs (pickled) and of the package's
sources, so pytest-xdist's workers share it and a folder kept across sessions never serves a
result of other inputs or other code. A process asking for a result another one is computing
waits for it (a lock file) instead of computing it again.
"""

import hashlib
import os
import pickle
from pathlib import Path

from tailbeam.cachedir import source_fingerprint

try:
    import fcntl
except ImportError:  # (no fcntl on Windows: each process computes what it has not found)
    fcntl = None


def shared(name: str, inputs, compute):
    """``compute()``, or the value it gave for the same ``name``, ``inputs`` and package
    sources earlier in the session (in this or another process)."""
    key = hashlib.sha256(pickle.dumps(inputs) + source_fingerprint().encode()).hexdigest()
    folder = Path(os.environ["TAILBEAM_TEST_CACHE_DIR"]) / "shared-results"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}-{key[:16]}.pickle"
    with open(path.with_suffix(".lock"), "w") as lock:
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)
        if path.exists():
            return pickle.loads(path.read_bytes())
        value = compute()
        partial = path.with_suffix(f".{os.getpid()}.part")
        partial.write_bytes(pickle.dumps(value))
        os.replace(partial, path)
        return value
