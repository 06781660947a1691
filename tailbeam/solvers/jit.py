"""The decorator of the compiled kernels' helpers: ``njit(cache=True, _nrt=False)``.

Numba's runtime (NRT) reference-counts arrays atomically: every array handed to a compiled
function that is not inlined, and every array unpacked from a tuple, costs an atomic
increment and decrement (~50 cycles). The active-set kernel calls small helpers (the
right-hand side, the event rows) hundreds of times per step with 10-25 arrays each, so the
counting dominated: 11 us per step for one ball, against 0.9 us for the rigid kernel. The
rigid kernel's parts (``rigid.kernel``, ``rigid.dop853``) are helpers too: as plain ``njit``
functions they made the kernel 40 % slower (measured with ``benchmarks/time_revisions.py``).

``_nrt=False`` compiles a function without the runtime: no reference counting. It is safe for
functions that never allocate, return or store an array (they only read and write the
arrays they are given, which the caller keeps alive; no slice assignment ``a[:] = b``
either, which needs the runtime): every helper decorated here. The functions that allocate
(``active_kernel.advance`` and ``_workspaces``, ``rigid.kernel.integrate_contact``) keep
plain ``njit``; helpers that allocate small arrays (the coupled kernel's) are inlined into
their caller instead (``njit(inline="always")``, numba's own inlining: no call, no counting).
Measured: a step of one ball 2.5 us (from 11), of eight balls 9 us (from 50), results
bit-identical.

``_nrt`` is a numba target option since 0.19 (listed in ``numba.core.cpu``'s options, not in
the user documentation: see numba issues 1204, 2350). If a numba release dropped it,
``HELPER_OPTIONS`` falls back to plain ``njit`` (slower, same results).
"""

from numba import njit

try:
    from numba.core.options import DefaultOptions

    HELPER_OPTIONS = {"cache": True, "_nrt": False} if hasattr(DefaultOptions, "_nrt") else {}
except ImportError:  # (numba reorganised: use the default runtime)
    HELPER_OPTIONS = {}
HELPER_OPTIONS.setdefault("cache", True)


def helper_njit(function):
    """``njit`` for helpers that never allocate, return or store arrays (see above)."""
    return njit(**HELPER_OPTIONS)(function)
