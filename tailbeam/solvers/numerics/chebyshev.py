"""Compiled (numba) twin of ``step_events``: certified first crossings inside one step.

A watched function g of one DOP853 step (a polynomial of degree <= 14 in the step fraction s:
a squared distance, a plate gap, an edge distance) is given by its values at the 15
Chebyshev points ``STEP_POINTS`` of the step. Its Chebyshev coefficients c (``VINV`` @ values)
satisfy |g - c0| <= sum_k>=1 |c_k| on the interval, so c0 > sum |c_k| certifies g > 0 there.
A row that is not certified is searched for its FIRST downward crossing by subdivision:

* the first node value <= 0 (index j) brackets a crossing in [s_(j-1), s_j]; the part left of
  it, [a, s_(j-1)], is searched first (re-interpolated at its own 15 points and certified or
  subdivided), so a dip between earlier nodes is not passed over;
* an interval with no node <= 0 that is not certified is skipped if its derivative is
  certified of one sign (monotone: both ends > 0, so positive throughout: the common case of
  a row that starts near 0 right after its event and moves away), else halved (left half
  first) down to a width of ``MIN_WIDTH`` of the step (a graze shallower than that is below
  the dead bands);
* a bracket is closed by the Illinois method on the interpolant (Clenshaw), to 4 ulp of s.

Same result as ``step_events.first_downward_crossing`` (numpy's ``chebroots``), without
eigenvalues; tested against it in tests/test_active_set.py.
"""

import math

import numpy as np

from tailbeam.solvers.numerics.jit import helper_njit
from tailbeam.solvers.numerics.step_events import _VINV, NODES, STEP_POINTS

VINV = np.ascontiguousarray(_VINV)
FRESH_S = 1e-10  # as step_events.FRESH_S: roots this close to a restart are the restart's
MIN_WIDTH = 1e-13  # smallest interval (fraction of the step) the subdivision examines
_STACK = 256


@helper_njit
def clenshaw(c, u):
    """Chebyshev series c at u in [-1, 1]."""
    b1 = 0.0
    b2 = 0.0
    for k in range(c.shape[0] - 1, 0, -1):
        b1, b2 = 2.0 * u * b1 - b2 + c[k], b1
    return u * b1 - b2 + c[0]


@helper_njit
def cheb_coefficients(values, vinv, out):
    """out = vinv @ values: Chebyshev coefficients of the interpolant through ``values``."""
    n = values.shape[0]
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += vinv[i, j] * values[j]
        out[i] = acc


@helper_njit
def certified(c):
    """Whether the series c is > 0 on its whole interval (c0 > sum |c_k|, with margin)."""
    s = 0.0
    for k in range(1, c.shape[0]):
        s += abs(c[k])
    return c[0] > s * (1.0 + 1e-12)


@helper_njit
def derivative(c, out):
    """Chebyshev series of dc/du into out[: n - 1] (numpy's chebder); out[n - 1] = 0."""
    n = c.shape[0]
    for q in range(n):
        out[q] = 0.0
    for j in range(n - 1, 0, -1):
        out[j - 1] = 2.0 * j * c[j] + (out[j + 1] if j + 1 < n - 1 else 0.0)
    out[0] *= 0.5


@helper_njit
def monotone(c, wd):
    """Whether the derivative of series c is certified of one sign (c monotone)."""
    derivative(c, wd)
    s = 0.0
    for k in range(1, wd.shape[0]):
        s += abs(wd[k])
    return abs(wd[0]) > s * (1.0 + 1e-12)


@helper_njit
def _g(c, s):
    return clenshaw(c, 2.0 * s - 1.0)


@helper_njit
def illinois_point(lo, glo, hi, ghi):
    """Next point of the Illinois (modified regula falsi) method in (lo, hi); the midpoint if
    the secant falls outside."""
    sm = (lo * ghi - hi * glo) / (ghi - glo)
    return sm if lo < sm < hi else 0.5 * (lo + hi)


@helper_njit
def illinois_update(lo, glo, hi, ghi, side, sm, gm):
    """The bracket (lo, glo, hi, ghi, side) after the value gm at sm (g(lo) > 0 >= g(hi));
    the end kept twice in a row has its value halved (Illinois)."""
    if gm > 0.0:
        if side == -1:
            ghi *= 0.5
        return sm, gm, hi, ghi, -1
    if side == 1:
        glo *= 0.5
    return lo, glo, sm, gm, 1


@helper_njit
def illinois(c, lo, glo, hi, ghi):
    """Root of the series c (in s) in [lo, hi] with g(lo) > 0 >= g(hi); to 4 ulp of s."""
    side = np.int64(0)  # (not a literal: one compiled signature)
    for _ in range(200):
        if hi - lo <= 4.0 * 2.220446049250313e-16 * max(1.0, abs(hi)):
            break
        sm = illinois_point(lo, glo, hi, ghi)
        lo, glo, hi, ghi, side = illinois_update(lo, glo, hi, ghi, side, sm, _g(c, sm))
    return 0.5 * (lo + hi)


@helper_njit
def first_crossing(c, values, fresh, pts, vinv, wv, wc, wd, stack):
    """First fraction s in [0, 1] where the series c (values at ``pts``) becomes <= 0; inf
    if none. ``fresh``: g sat on zero at s = 0 (its own event's restart): the search starts at
    ``FRESH_S``. wv, wc, wd (15,) and stack (256, 3) are scratch."""
    a = 0.0
    if fresh:
        a = FRESH_S
        if _g(c, a) <= 0.0:
            return math.inf
    elif values[0] < 0.0:
        return 0.0
    top = 0
    stack[0, 0], stack[0, 1], stack[0, 2] = a, 1.0, 0.0
    top = 1
    n = pts.shape[0]
    while top > 0:
        top -= 1
        lo, hi, kind = stack[top, 0], stack[top, 1], stack[top, 2]
        if kind == 1.0:
            return illinois(c, lo, _g(c, lo), hi, _g(c, hi))
        for q in range(n):
            wv[q] = _g(c, lo + (hi - lo) * pts[q])
        if wv[0] <= 0.0:
            return lo
        cheb_coefficients(wv, vinv, wc)
        if certified(wc):
            continue
        j = -1
        for q in range(1, n):
            if wv[q] <= 0.0:
                j = q
                break
        if top + 2 > stack.shape[0]:
            return math.inf  # (cannot happen: depth <= log2(1 / MIN_WIDTH))
        if j < 0:
            if hi - lo < MIN_WIDTH or monotone(wc, wd):
                continue  # (monotone with both ends > 0: positive throughout)
            mid = 0.5 * (lo + hi)
            stack[top, 0], stack[top, 1], stack[top, 2] = mid, hi, 0.0
            stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2] = lo, mid, 0.0
            top += 2
            continue
        sl = lo + (hi - lo) * pts[j - 1]
        sr = lo + (hi - lo) * pts[j]
        if j == 1:
            return illinois(c, sl, wv[0], sr, wv[1])
        stack[top, 0], stack[top, 1], stack[top, 2] = sl, sr, 1.0
        stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2] = lo, sl, 0.0
        top += 2
    return math.inf


@helper_njit
def interpolant_max(values, vinv, wc, wd):
    """(s, value) of the maximum of the Chebyshev interpolant through ``values`` at
    ``STEP_POINTS``: the largest node, refined at the root of the derivative in the node
    intervals next to it (as ``step_events.interpolant_max``). wc, wd (15,) scratch."""
    n = values.shape[0]
    k = 0
    for q in range(1, n):
        if values[q] > values[k]:
            k = q
    cheb_coefficients(values, vinv, wc)
    derivative(wc, wd)
    best_s = 0.5 * (1.0 - math.cos(math.pi * k / (n - 1)))
    best = values[k]
    for side in range(2):
        qa = k - 1 + side
        qb = qa + 1
        if qa < 0 or qb > n - 1:
            continue
        sa = 0.5 * (1.0 - math.cos(math.pi * qa / (n - 1)))
        sb = 0.5 * (1.0 - math.cos(math.pi * qb / (n - 1)))
        da = clenshaw(wd[: n - 1], 2.0 * sa - 1.0)
        db = clenshaw(wd[: n - 1], 2.0 * sb - 1.0)
        if da > 0.0 and db <= 0.0:
            s = illinois(wd[: n - 1], sa, da, sb, db)
            value = clenshaw(wc, 2.0 * s - 1.0)
            if value > best:
                best_s, best = s, value
    return best_s, best


def tables():
    """(pts, vinv): the 15 step fractions and the inverse Chebyshev-Vandermonde matrix."""
    assert NODES == 15
    return np.ascontiguousarray(STEP_POINTS), VINV
