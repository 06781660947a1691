"""Certified row crossings of an active set in one DOP853 step (the event search).

Every watched row (pairs: contact, full damping, clamp; balls: the 4 edges) is certified in
three tiers: the bound B on how far each state component moves in the step (``prepare``,
``_quick``: O(1) for far pairs and balls far from the edges), else the 15 Chebyshev values of
the row (the ball's dense output there, ``step.ensure_ball``), else the first-crossing search
(``tailbeam.solvers.numerics.chebyshev``). Rows that are no polynomial on the step (the clamp
indicator, the law's delta with residual flexibility) are sampled at the 15 points and closed by
Illinois (``_sampled_crossing``). ``detect`` returns the earliest crossing of all rows.
"""

import math

import numpy as np

from tailbeam.physics.contact_law import LAW_C, LAW_CLAMP, LAW_D
from tailbeam.solvers.numerics.chebyshev import (
    certified,
    cheb_coefficients,
    first_crossing,
    illinois_point,
    illinois_update,
)
from tailbeam.solvers.numerics.jit import helper_njit
from tailbeam.solvers.stream.active.compiled.pairs import (
    INTEGRATED,
    L_CRES,
    R_CLAMP,
    R_CONTACT,
    R_EDGE,
    R_FULL,
    pair_state,
    plate_row_value,
    row_value,
    row_value_arrays,
)
from tailbeam.solvers.stream.active.compiled.step import EPS, dense_state, ensure_ball, ensure_plate


@helper_njit
def is_fresh(kind, idx, fresh, nfresh):
    for f in range(nfresh):
        if fresh[f, 0] == kind and fresh[f, 1] == idx:
            return True
    return False


@helper_njit
def _sampled_crossing(kind, idx, vals, fresh, y, coef, pts, model, pstate, tmp):
    """First s where a sampled (non-polynomial) row leaves its side: a node on the wrong side
    right after one on the right side, closed by Illinois on the dense output. A fresh row
    may start on the wrong side by round-off: only a right-to-wrong change counts for it."""
    if not fresh and vals[0] <= 0.0:
        return 0.0
    for q in range(1, pts.shape[0]):
        if vals[q - 1] > 0.0 and vals[q] <= 0.0:
            lo, glo, hi, ghi = pts[q - 1], vals[q - 1], pts[q], vals[q]
            side = np.int64(0)  # (not a literal: one compiled signature)
            for _ in range(200):
                if hi - lo <= 4.0 * EPS:
                    break
                sm = illinois_point(lo, glo, hi, ghi)
                dense_state(coef, y, sm, tmp)
                gm = row_value(kind, idx, tmp, model, pstate)
                lo, glo, hi, ghi, side = illinois_update(lo, glo, hi, ghi, side, sm, gm)
            return 0.5 * (lo + hi)
    return math.inf


@helper_njit
def prepare(dense):
    """Start of a step's event work: no ball evaluated at the Chebyshev points yet, and the
    bound B[q] = sum_i |coef[i, q]| >= |y_q(s) - y_q(0)| on the whole step (every factor of
    the dense output's nested form lies in [0, 1])."""
    Y15, have, coef, y, B, W15, have_w, proj = dense
    for b in range(have.shape[0]):
        have[b] = False
    for p in range(have_w.shape[0]):
        have_w[p] = False
    for q in range(y.shape[0]):
        acc = 0.0
        for i in range(7):
            acc += abs(coef[i, q])
        B[q] = acc


@helper_njit
def _reach(B, b):
    """Bound in m on how far ball b's centre moves from its start during the step."""
    return math.sqrt(B[3 * b] ** 2 + B[3 * b + 1] ** 2 + B[3 * b + 2] ** 2)


@helper_njit
def _quick(kind, idx, y, B, n, half, pi, pj, law, rsum, touching, ramp, phi):
    """Whether row (kind, idx) is certified positive on the step by the bound B alone:
    edges and centre distances move at most B from their start values (no 15-point
    evaluation needed: far-apart pairs and balls far from the edges cost O(1))."""
    if kind == R_CLAMP:
        return False
    if kind == R_EDGE:
        b, e = idx // 4, idx % 4
        c = y[3 * b + e // 2]
        f = c + half[e // 2] if e % 2 == 0 else half[e // 2] - c
        return f + 1e-13 - B[3 * b + e // 2] > 0.0  # (EDGE_BAND)
    i, j, rs = pi[idx], pj[idx], rsum[idx]
    if kind == R_FULL and j < 0 and law[idx, L_CRES] > 0.0:
        return False  # (the law's delta lags the gap by C F: no bound from the gap alone)
    if j < 0:
        dist0, reach = y[3 * i + 2], B[3 * i + 2]
        nm = phi.shape[1]
        for k in range(nm):  # the deflection phi . q moves by at most sum |phi_k| B_k
            dist0 -= phi[idx, k] * y[6 * n + k]
            reach += abs(phi[idx, k]) * B[6 * n + k]
    else:
        dist0 = rs - pair_state(y, n, i, j, rs, phi, idx)[0]
        reach = _reach(B, i) + _reach(B, j)
    lo, hi = dist0 - reach, dist0 + reach  # the distance stays within [lo, hi]
    margin = 1e-12 * rs
    if kind == R_CONTACT:
        return hi < rs - margin and lo > 0.0 if touching[idx] else lo > rs + margin
    r_full = rs - law[idx, LAW_D]
    return lo > r_full + margin if ramp[idx] else (hi < r_full - margin and lo > 0.0)


@helper_njit
def _row_crossing(kind, idx, fr, Y15, have, coef, y, B, pts, vinv, n, half, pi, pj, law,
                  rsum, touching, ramp, clamped, vals, wc, wv, wc2, wd, stack, tmp, model,
                  pstate, W15, have_w, proj):  # fmt: skip
    """First crossing (fraction of the step, inf if none) of row (kind, idx): the bound B,
    else the 15-point certificate, else the search (``tailbeam.solvers.numerics.chebyshev``)."""
    phi = model[12]
    if _quick(kind, idx, y, B, n, half, pi, pj, law, rsum, touching, ramp, phi):
        return math.inf
    if kind == R_EDGE:
        ensure_ball(Y15, have, coef, y, pts, idx // 4)
    else:
        ensure_ball(Y15, have, coef, y, pts, pi[idx])
        ensure_ball(Y15, have, coef, y, pts, pj[idx])
    if kind != R_EDGE and pj[idx] < 0:
        ensure_plate(W15, have_w, coef, y, pts, model, idx, proj)
        i = pi[idx]
        for q in range(pts.shape[0]):
            vals[q] = plate_row_value(kind, idx, Y15[q, 3 * i + 2], Y15[q, 3 * n + 3 * i + 2],
                                      W15[q, idx, 0], W15[q, idx, 1], W15[q, idx, 2],
                                      W15[q, idx, 3], law, rsum, touching, ramp,
                                      clamped)  # fmt: skip
    else:
        for q in range(pts.shape[0]):
            vals[q] = row_value_arrays(
                kind, idx, Y15[q], n, half, pi, pj, law, rsum, touching, ramp, clamped, phi
            )
    if kind == R_CLAMP or (kind == R_FULL and pj[idx] < 0 and law[idx, L_CRES] > 0.0):
        # (not polynomials on the step: the clamp indicator; the law's delta with residual)
        return _sampled_crossing(kind, idx, vals, fr, y, coef, pts, model, pstate, tmp)
    cheb_coefficients(vals, vinv, wc)
    if certified(wc):
        return math.inf
    return first_crossing(wc, vals, fr, pts, vinv, wv, wc2, wd, stack)


@helper_njit
def detect(dense, fresh, nfresh, pts, vinv, model, pstate, ws):
    """Earliest (s, kind, idx) of a row crossing in the step; kind -1 if none. (The tuples
    are unpacked once here: the helpers take arrays, see ``rhs_arrays``.)"""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    touching, ramp, clamped = pstate[0], pstate[1], pstate[2]
    Y15, have, coef, y, B, W15, have_w, proj = dense
    vals, wc, wv, wc2, wd, stack, tmp = ws
    n = mass.shape[0]
    best_s, best_k, best_i = math.inf, -1, -1
    for p in range(pi.shape[0]):
        if not alive[pi[p]] or (pj[p] >= 0 and not alive[pj[p]]):
            continue
        for kind in range(3):
            if kind > 0 and (not touching[p] or law[p, LAW_C] <= 0.0):
                break
            if kind == R_CLAMP and law[p, LAW_CLAMP] <= 0.0:
                break
            fr = is_fresh(kind, p, fresh, nfresh)
            s = _row_crossing(kind, p, fr, Y15, have, coef, y, B, pts, vinv, n, half, pi, pj,
                              law, rsum, touching, ramp, clamped, vals, wc, wv, wc2, wd, stack,
                              tmp, model, pstate, W15, have_w, proj)  # fmt: skip
            if s < best_s:
                best_s, best_k, best_i = s, kind, p
    kind_edge = np.int64(R_EDGE)  # (typed like the pair kinds: one compiled signature)
    for b in range(n):
        if alive[b] != INTEGRATED:  # (gone, or a FIXED obstacle: it does not move)
            continue
        for e in range(4):
            fr = is_fresh(kind_edge, 4 * b + e, fresh, nfresh)  # (False: LEAVE returns)
            s = _row_crossing(kind_edge, 4 * b + e, fr, Y15, have, coef, y, B, pts, vinv, n,
                              half, pi, pj, law, rsum, touching, ramp, clamped, vals, wc, wv,
                              wc2, wd, stack, tmp, model, pstate, W15, have_w,
                              proj)  # fmt: skip
            if s < best_s:
                best_s, best_k, best_i = s, R_EDGE, 4 * b + e
    return best_s, best_k, best_i
