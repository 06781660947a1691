"""The decorator of the compiled kernels' helpers: ``njit(cache=True, _nrt=False)``.

Numba's runtime (NRT) reference-counts arrays atomically: every array handed to a compiled
function that is not inlined, and every array unpacked from a tuple, costs an atomic
increment and decrement (~50 cycles). The active-set kernel calls small helpers (the
right-hand side, the event rows) hundreds of times per step with 10-25 arrays each, so with
the counting the kernel spent most of its time on it. The rigid kernel's parts
(``rigid.kernel``, ``rigid.step``, ``numerics.dop853``) are helpers too.

``_nrt=False`` compiles a function without the runtime: no reference counting. It is safe for
functions that never allocate, return or store an array (they only read and write the
arrays they are given, which the caller keeps alive; no slice assignment ``a[:] = b``
either, which needs the runtime): every helper decorated here. The functions that allocate
(``active_kernel.advance`` and ``_workspaces``, ``rigid.kernel.integrate_contact``, the
coupled kernel's ``run`` and ``solve_step`` and what they call with tuples) keep plain ``njit``;
a helper compiled here cannot call one that allocates (numba compiles the callee with the
caller's flags). The parts of ``solve_step`` that allocate are inlined into it
(``njit(inline="always")``, numba's own inlining: no call). Handing tuples of arrays to
a plain ``njit`` helper in a per-step loop cost the coupled kernel 10 % (their members are
counted one by one), so its loop calls such helpers only when there is an event to locate.

``_nrt`` is a numba target option since 0.19 (listed in ``numba.core.cpu``'s options, not in
the user documentation: numba/numba#1204 and #2350 on its tracker). If a numba release
dropped it, ``HELPER_OPTIONS`` falls back to plain ``njit`` (slower, same results).
"""

from tailbeam.jit import njit

try:
    from numba.core.options import DefaultOptions

    HELPER_OPTIONS = {"cache": True, "_nrt": False} if hasattr(DefaultOptions, "_nrt") else {}
except ImportError:  # (numba reorganised: use the default runtime)
    HELPER_OPTIONS = {}
HELPER_OPTIONS.setdefault("cache", True)


def helper_njit(function):
    """``njit`` for helpers that never allocate, return or store arrays (see above)."""
    return njit(**HELPER_OPTIONS)(function)
