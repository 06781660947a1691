"""How many BLAS threads the plate's linear algebra may use.

The basis builds (assembly, the eigen-solves, the Ritz tail's Krylov space) run their dense
products and sparse solves under one BLAS thread by default: the sparse solves are
single-threaded anyway, and the products are small enough (tens of columns) that a second
OpenBLAS thread only spins while it waits for a core. ``$TAILBEAM_BLAS_THREADS`` (or a
function's ``blas_threads`` keyword) sets another limit.
"""

import os

from threadpoolctl import threadpool_limits


def blas_threads(requested=None) -> int:
    """The BLAS thread limit: ``requested`` if given, else ``$TAILBEAM_BLAS_THREADS``, else 1."""
    if requested is not None:
        return int(requested)
    env = os.environ.get("TAILBEAM_BLAS_THREADS")
    return int(env) if env else 1


def limited(requested=None):
    """A context manager holding BLAS to ``blas_threads(requested)`` threads (threadpoolctl)."""
    return threadpool_limits(limits=blas_threads(requested))
