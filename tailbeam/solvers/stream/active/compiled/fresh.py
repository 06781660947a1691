"""Rows of an active set whose events were just applied ("fresh"), carried across returns.

An event the active-set kernel (``kernel``) applies leaves its row's function on 0 at that
instant. The kernel keeps such rows in a small table (kind, index), at most MAX_FRESH, searched
from ``tailbeam.solvers.numerics.chebyshev.FRESH_S`` of the next step on, and hands the rows
applied at the instant it returns at to the next call that starts there
(``set.ActiveSet.advance``), so a START or END it returned is not found again at once (a grazing
contact would stall).
"""

from tailbeam.solvers.numerics.chebyshev import FRESH_S
from tailbeam.solvers.numerics.jit import helper_njit
from tailbeam.solvers.stream.active.compiled.events import is_fresh
from tailbeam.solvers.stream.active.compiled.pairs import row_value
from tailbeam.solvers.stream.active.compiled.step import EPS, dense_state

MAX_FRESH = 16  # rows a fresh table holds


@helper_njit
def mark(k, i, fresh, nfresh):
    """Remember row (k, i) as fresh (up to MAX_FRESH rows); returns the new count."""
    if nfresh < MAX_FRESH:
        fresh[nfresh, 0], fresh[nfresh, 1] = k, i
        nfresh += 1
    return nfresh


@helper_njit
def found_again(k, i, s, h, t, t0, carried, ncarried, fresh, nfresh, dense, model, pstate,
                 tmp):  # fmt: skip
    """Whether the crossing of row (k, i) at fraction s of the step of h (s) from t (s) is the
    event the previous call applied and returned at t0 = t (``carried``) found again: at
    the restart instant (where it would be applied there), not yet marked fresh in this
    call, and back on its side at ``FRESH_S`` of the step (it sat on 0; a row still on the
    wrong side there crosses now, genuinely: applied at the restart as without markers)."""
    if ncarried == 0 or t != t0 or not (t + s * h <= t + 4.0 * EPS * abs(t) or s == 0.0):
        return False
    if not is_fresh(k, i, carried, ncarried) or is_fresh(k, i, fresh, nfresh):
        return False
    dense_state(dense[2], dense[3], FRESH_S, tmp)
    return row_value(k, i, tmp, model, pstate) > 0.0


@helper_njit
def hand_back(carried, ncarried, fresh, nfresh, same_instant):
    """The rows applied at the instant ``advance`` returns at, into ``carried``: this call's
    fresh rows, and those carried in when time did not move. Returns their count."""
    n = ncarried if same_instant else 0
    for q in range(nfresh):
        if not is_fresh(fresh[q, 0], fresh[q, 1], carried, n):
            n = mark(fresh[q, 0], fresh[q, 1], carried, n)
    return n
