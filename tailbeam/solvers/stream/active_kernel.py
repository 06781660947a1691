"""Compiled (numba) DOP853 integrator of an active set of balls, with certified events.

One call advances the state from t until the first structural event or t_stop (see
``advance``). Per step: 12 + 3 right-hand-side evaluations (O(balls + touching pairs) each)
and every watched row (pairs and edges: O(pairs watched + balls)) certified in three tiers:
the bound B on how far each state component moves in the step (``_prepare``, ``_quick``:
O(1) for far pairs and balls far from the edges), else the 15 Chebyshev values of the row
(the ball's dense output there, evaluated once per ball and step: ``_ensure``), else the
first-crossing search (``cheb_events``). Helpers take arrays one by one and are compiled
without reference counting (``tailbeam.solvers.stream.jit``); only ``advance`` allocates.

With the optional modal plate (m modes after the balls in the state, ``active_pairs``) the
plate's deflection under a plate pair at the 15 points and at the force-row nodes comes from
the modes projected on that pair's phi first (``_project``, ``_ensure_plate``: O(m) per pair
and step); the far-pair bound adds sum |phi_k| B_k; the error norm is taken per block (balls,
modes). Without modes every operation and result is the rigid plate's, bit for bit. With
residual flexibility at a plate pair (``active_pairs.plate_force_with_residual``) its
full-damping row, like the clamp row, is sampled at the 15 points and closed by Illinois
(the law's delta is no polynomial on the step); the contact row stays the polynomial gap.

Event handling is the reference's (``stream_reference``): a step in which a row crosses is
discarded and redone to end exactly at the crossing, and the redone step is checked again
(an earlier root wins). At the end of the redone step the event is applied if its row is
within its dead band of the crossing. Kinks (full damping d crossed, clamp on/off) are
applied inside (logged) and integration goes on in the new region; contact start / end,
leave, settle return to the caller. Events within ``SAME_TIME`` of a step of a pending one
are taken after it, one after the other at the same time (a symmetric 3-ball cluster).
"""

import math

import numpy as np
from numba import njit

from tailbeam.solvers.records import EventKind
from tailbeam.solvers.stream.active_pairs import (
    L_C,
    L_CLAMP,
    L_CRES,
    L_D,
    R_CLAMP,
    R_CONTACT,
    R_EDGE,
    R_FULL,
    first_contact_step,
    pair_force,
    pair_state,
    plate_force,
    plate_row_value,
    rhs,
    rhs_arrays,
    row_band,
    row_value,
    row_value_arrays,
    settle_excess,
)
from tailbeam.solvers.stream.cheb_events import (
    certified,
    cheb_coefficients,
    first_crossing,
    illinois_point,
    illinois_update,
    interpolant_max,
)
from tailbeam.solvers.stream.jit import helper_njit

# return status of ``advance``
ST_STOP, ST_START, ST_END, ST_LEAVE, ST_SETTLE, ST_BUFFER, ST_STEP_LIMIT, ST_STEP_TINY = range(8)
STATUS_NAMES = (
    "t_stop", "contact_start", "contact_end", "leave", "settle", "buffer_full", "step_limit",
    "step_too_small",
)  # fmt: skip
# kinds in the event log
LOG_FULL, LOG_CLAMP_ON, LOG_CLAMP_OFF = range(3)
LOG_NAMES = (EventKind.FULL_DAMPING, EventKind.CLAMP_ON, EventKind.CLAMP_OFF)
# integer outputs (iout)
IO_STATUS, IO_INDEX, IO_EDGE, IO_STEPS, IO_ATTEMPTS, IO_NFEV, IO_ROWS, IO_LOG = range(8)

SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0
SAME_TIME = 1e-9  # fraction of a step: events closer than this to a pending one wait for it
EPS = 2.220446049250313e-16
MAX_FRESH = 16


@helper_njit
def _stages(K, A, first, stop, y, h, model, pstate, tmp):
    """Runge-Kutta stages first..stop-1 into K (rows: stages)."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    touching, ramp, clamped = pstate[0], pstate[1], pstate[2]
    n = y.shape[0]
    for s in range(first, stop):
        for q in range(n):
            acc = 0.0
            for j in range(s):
                acc += A[s, j] * K[j, q]
            tmp[q] = y[q] + h * acc
        rhs_arrays(tmp, mass, g, pi, pj, law, rsum, touching, ramp, clamped, alive, omega, zeta,
                   phi, fdead, K[s])  # fmt: skip


@helper_njit
def _step(y, h, K, tab, rtol, atol, model, pstate, ynew, tmp):
    """One DOP853 step of size h from y (K[0] = f(y) given): ynew, K[12] = f(ynew); returns
    scipy's error norm (NaN or > 1: reject), taken separately over the balls and the modal
    block (the larger: many modes do not dilute the balls' error). atol (N,) per component."""
    A, B = tab[0], tab[1]
    n = y.shape[0]
    nb6 = 6 * model[0].shape[0]  # balls' positions and velocities, then the modal block
    _stages(K, A, np.int64(1), np.int64(12), y, h, model, pstate, tmp)
    for q in range(n):
        acc = 0.0
        for j in range(12):
            acc += B[j] * K[j, q]
        ynew[q] = y[q] + h * acc
    rhs(ynew, model, pstate, K[12])
    err = _block_error(y, ynew, h, K, tab, rtol, atol, np.int64(0), nb6)
    if n > nb6 and err == err:
        err_modes = _block_error(y, ynew, h, K, tab, rtol, atol, nb6, n)
        if not err_modes <= err:
            err = err_modes
    return err


@helper_njit
def _block_error(y, ynew, h, K, tab, rtol, atol, lo, hi):
    """scipy's DOP853 error norm over the components lo..hi-1."""
    E3, E5 = tab[2], tab[3]
    err5 = 0.0
    err3 = 0.0
    for q in range(lo, hi):
        e5 = 0.0
        e3 = 0.0
        for j in range(13):
            e5 += E5[j] * K[j, q]
            e3 += E3[j] * K[j, q]
        sc = atol[q] + rtol * max(abs(y[q]), abs(ynew[q]))
        err5 += (e5 / sc) ** 2
        err3 += (e3 / sc) ** 2
    if err5 == 0.0 and err3 == 0.0:
        return 0.0
    return h * err5 / math.sqrt((err5 + 0.01 * err3) * (hi - lo))


@helper_njit
def _dense_coef(y, ynew, h, K, tab, model, pstate, coef, tmp):
    """The 3 extra stages and the 7 rows of DOP853's dense output (scipy's F)."""
    A, D = tab[0], tab[4]
    _stages(K, A, np.int64(13), np.int64(16), y, h, model, pstate, tmp)
    for q in range(y.shape[0]):
        dy = ynew[q] - y[q]
        coef[0, q] = dy
        coef[1, q] = h * K[0, q] - dy
        coef[2, q] = 2.0 * dy - h * (K[12, q] + K[0, q])
        for i in range(4):
            acc = 0.0
            for j in range(16):
                acc += D[i, j] * K[j, q]
            coef[3 + i, q] = h * acc


@helper_njit
def _dense1(coef, y, s, q):
    """Component q of the dense output at fraction s of the step."""
    a = 0.0
    for i in range(6, -1, -1):
        a += coef[i, q]
        a *= s if (6 - i) % 2 == 0 else 1.0 - s
    return y[q] + a


@helper_njit
def _dense(coef, y, s, out):
    for q in range(y.shape[0]):
        out[q] = _dense1(coef, y, s, q)


@helper_njit
def _is_fresh(kind, idx, fresh, nfresh):
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
                _dense(coef, y, sm, tmp)
                gm = row_value(kind, idx, tmp, model, pstate)
                lo, glo, hi, ghi, side = illinois_update(lo, glo, hi, ghi, side, sm, gm)
            return 0.5 * (lo + hi)
    return math.inf


@helper_njit
def _prepare(dense):
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
def _ensure(Y15, have, coef, y, pts, b):
    """Ball b's 6 state components at the 15 Chebyshev points of the step (once per step)."""
    if b < 0 or have[b]:
        return
    have[b] = True
    n = have.shape[0]
    for q in range(pts.shape[0]):
        for k in range(3):
            Y15[q, 3 * b + k] = _dense1(coef, y, pts[q], 3 * b + k)
            Y15[q, 3 * n + 3 * b + k] = _dense1(coef, y, pts[q], 3 * n + 3 * b + k)


@helper_njit
def _project(coef, y, phi, p, off, out):
    """The dense output of phi[p] . y[off : off + m] (m modes): its 7 coefficients out[:7] and
    its value at the step start out[7] (the dense output is linear in coef and y)."""
    nm = phi.shape[1]
    for i in range(8):
        out[i] = 0.0
    for k in range(nm):
        c = phi[p, k]
        for i in range(7):
            out[i] += c * coef[i, off + k]
        out[7] += c * y[off + k]


@helper_njit
def _dense_projected(c8, s):
    """A projected dense output (``_project``) at fraction s of the step (as ``_dense1``)."""
    a = 0.0
    for i in range(6, -1, -1):
        a += c8[i]
        a *= s if (6 - i) % 2 == 0 else 1.0 - s
    return c8[7] + a


@helper_njit
def _ensure_plate(W15, have_w, coef, y, pts, model, p, proj):
    """The plate's deflection, velocity and free acceleration (``_project_plate``) under plate
    pair p at the 15 Chebyshev points of the step, and kappa (once per step)."""
    if have_w[p]:
        return
    have_w[p] = True
    kappa = _project_plate(coef, y, model, p, proj)
    for q in range(pts.shape[0]):
        W15[q, p, 0] = _dense_projected(proj[0], pts[q])
        W15[q, p, 1] = _dense_projected(proj[1], pts[q])
        W15[q, p, 2] = _dense_projected(proj[2], pts[q])
        W15[q, p, 3] = kappa


@helper_njit
def _project_plate(coef, y, model, p, proj):
    """The dense outputs (``_project``) of the plate under plate pair p of the step: w, w' and
    acc0 = -g_z + phi[p] . (f_dead - 2 zeta omega q' - omega^2 q) (``plate_free_acceleration``)
    into proj[0..2]; returns kappa = 1/m + phi[p] . phi[p] (1/kg). The modes projected on
    phi[p] first: O(modes) per step, not per point."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    n = mass.shape[0]
    nm = phi.shape[1]
    off = 6 * n
    _project(coef, y, phi, p, off, proj[0])
    _project(coef, y, phi, p, off + nm, proj[1])
    acc = proj[2]
    for i in range(8):
        acc[i] = 0.0
    acc[7] = -g[2]
    kappa = 1.0 / mass[pi[p]]
    for k in range(nm):
        c = phi[p, k]
        a, b = -c * omega[k] * omega[k], -2.0 * c * zeta[k] * omega[k]
        for i in range(7):
            acc[i] += a * coef[i, off + k] + b * coef[i, off + nm + k]
        acc[7] += a * y[off + k] + b * y[off + nm + k] + c * fdead[k]
        kappa += c * c
    return kappa


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
    r_full = rs - law[idx, L_D]
    return lo > r_full + margin if ramp[idx] else (hi < r_full - margin and lo > 0.0)


@helper_njit
def _row_crossing(kind, idx, fr, Y15, have, coef, y, B, pts, vinv, n, half, pi, pj, law,
                  rsum, touching, ramp, clamped, vals, wc, wv, wc2, wd, stack, tmp, model,
                  pstate, W15, have_w, proj):  # fmt: skip
    """First crossing (fraction of the step, inf if none) of row (kind, idx): the bound B,
    else the 15-point certificate, else the search (``cheb_events``)."""
    phi = model[12]
    if _quick(kind, idx, y, B, n, half, pi, pj, law, rsum, touching, ramp, phi):
        return math.inf
    if kind == R_EDGE:
        _ensure(Y15, have, coef, y, pts, idx // 4)
    else:
        _ensure(Y15, have, coef, y, pts, pi[idx])
        _ensure(Y15, have, coef, y, pts, pj[idx])
    if kind != R_EDGE and pj[idx] < 0:
        _ensure_plate(W15, have_w, coef, y, pts, model, idx, proj)
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
def _detect(dense, fresh, nfresh, pts, vinv, model, pstate, ws):
    """Earliest (s, kind, idx) of a row crossing in the step; kind -1 if none. (The tuples
    are unpacked once here: the helpers take arrays, see ``rhs_arrays``.)"""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    touching, ramp, clamped = pstate[0], pstate[1], pstate[2]
    Y15, have, coef, y, B, W15, have_w, proj = dense
    vals, wc, wv, wc2, wd, stack, tmp = ws
    n = mass.shape[0]
    best_s, best_k, best_i = math.inf, -1, -1
    for p in range(pi.shape[0]):
        if not alive[pi[p]] or (pj[p] >= 0 and not alive[pj[p]]):
            continue
        for kind in range(3):
            if kind > 0 and (not touching[p] or law[p, L_C] <= 0.0):
                break
            if kind == R_CLAMP and law[p, L_CLAMP] <= 0.0:
                break
            fr = _is_fresh(kind, p, fresh, nfresh)
            s = _row_crossing(kind, p, fr, Y15, have, coef, y, B, pts, vinv, n, half, pi, pj,
                              law, rsum, touching, ramp, clamped, vals, wc, wv, wc2, wd, stack,
                              tmp, model, pstate, W15, have_w, proj)  # fmt: skip
            if s < best_s:
                best_s, best_k, best_i = s, kind, p
    kind_edge = np.int64(R_EDGE)  # (typed like the pair kinds: one compiled signature)
    for b in range(n):
        if not alive[b]:
            continue
        for e in range(4):
            fr = _is_fresh(kind_edge, 4 * b + e, fresh, nfresh)  # (False: LEAVE returns)
            s = _row_crossing(kind_edge, 4 * b + e, fr, Y15, have, coef, y, B, pts, vinv, n,
                              half, pi, pj, law, rsum, touching, ramp, clamped, vals, wc, wv,
                              wc2, wd, stack, tmp, model, pstate, W15, have_w,
                              proj)  # fmt: skip
            if s < best_s:
                best_s, best_k, best_i = s, R_EDGE, 4 * b + e
    return best_s, best_k, best_i


@helper_njit
def _write_row(rows, iout, t, p, f):
    r = iout[IO_ROWS]
    rows[r, 0] = t
    rows[r, 1] = p
    rows[r, 2] = f
    iout[IO_ROWS] = r + 1


@helper_njit
def _accept(t, h, ynew, dense, nodes, pts, vinv, model, pstate, rows, iout, ws):
    """Peak force / max penetration of the touching pairs on the accepted step (maximum of
    their Chebyshev interpolant, refined where the nodes come within 1 % of the record), and
    the plate force rows at ``nodes`` interior points and the step end."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    touching, ramp, clamped, peak, t_peak, pen = pstate
    vals, wc, wv, wc2, wd, stack, tmp = ws
    Y15, have, coef, y, B, W15, have_w, proj = dense
    for p in range(pi.shape[0]):
        if not touching[p]:
            continue
        _pair_values(p, dense, pts, model, pstate, vals, wv)
        fmax = -math.inf
        for q in range(pts.shape[0]):
            fmax = max(fmax, vals[q])
        if fmax >= 0.99 * peak[p]:
            s, fm = interpolant_max(vals, vinv, wc, wc2)
            if fm > peak[p]:
                peak[p], t_peak[p] = fm, t + s * h
        dmax = -math.inf
        for q in range(pts.shape[0]):
            dmax = max(dmax, wv[q])
        if dmax >= 0.99 * pen[p]:
            for q in range(pts.shape[0]):
                vals[q] = wv[q]
            pen[p] = max(pen[p], interpolant_max(vals, vinv, wc, wc2)[1])
        if pj[p] >= 0:
            continue
        _node_rows(t, h, p, nodes, coef, y, ynew, model, pstate, rows, iout, proj)


@helper_njit
def _pair_values(p, dense, pts, model, pstate, forces, deltas):
    """Force (N) and penetration (m) of touching pair p at the 15 Chebyshev points."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    ramp, clamped = pstate[1], pstate[2]
    Y15, have, coef, y, B, W15, have_w, proj = dense
    n = mass.shape[0]
    i, j = pi[p], pj[p]
    _ensure(Y15, have, coef, y, pts, i)
    if j >= 0:
        _ensure(Y15, have, coef, y, pts, j)
        for q in range(pts.shape[0]):
            f, delta, _, _, _ = pair_force(Y15[q], n, p, pi, pj, law, rsum, ramp, clamped, phi,
                                           mass, g, omega, zeta, fdead)  # fmt: skip
            forces[q], deltas[q] = f, delta
        return
    _ensure_plate(W15, have_w, coef, y, pts, model, p, proj)
    for q in range(pts.shape[0]):
        forces[q], deltas[q] = plate_force(p, Y15[q, 3 * i + 2], Y15[q, 3 * n + 3 * i + 2],
                                           W15[q, p, 0], W15[q, p, 1], W15[q, p, 2],
                                           W15[q, p, 3], law, rsum, ramp, clamped)  # fmt: skip


@helper_njit
def _node_rows(t, h, p, nodes, coef, y, ynew, model, pstate, rows, iout, proj):
    """Force rows of plate pair p at ``nodes`` interior points of the step and its end (the
    plate deflection under the ball from its projected dense output, ``_project``)."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    ramp, clamped = pstate[1], pstate[2]
    n = mass.shape[0]
    i = pi[p]
    kappa = _project_plate(coef, y, model, p, proj)
    wq, wv, wa = proj[0], proj[1], proj[2]
    for k in range(1, nodes + 1):
        s = k / (nodes + 1.0)
        z = _dense1(coef, y, s, 3 * i + 2)
        vz = _dense1(coef, y, s, 3 * n + 3 * i + 2)
        f = plate_force(p, z, vz, _dense_projected(wq, s), _dense_projected(wv, s),
                        _dense_projected(wa, s), kappa, law, rsum, ramp, clamped)[0]  # fmt: skip
        _write_row(rows, iout, t + s * h, p, f)
    f = pair_force(ynew, n, p, pi, pj, law, rsum, ramp, clamped, phi, mass, g, omega, zeta,
                   fdead)[0]  # fmt: skip
    _write_row(rows, iout, t + h, p, f)


@helper_njit
def _apply(kind, idx, t, y, model, pstate, rows, log, iout):
    """Apply the event of row (kind, idx) at time t, state y; returns the status to return
    with (ST_START, ST_END, ST_LEAVE) or -1 for a kink handled here (logged)."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    touching, ramp, clamped, peak, t_peak, pen = pstate
    n = mass.shape[0]
    if kind == R_EDGE:
        iout[IO_INDEX] = idx // 4
        iout[IO_EDGE] = idx % 4
        return ST_LEAVE
    iout[IO_INDEX] = idx
    if kind == R_CONTACT:
        f = pair_force(y, n, idx, pi, pj, law, rsum, ramp, clamped, phi, mass, g, omega, zeta,
                       fdead)[0]  # fmt: skip
        if touching[idx]:
            if pj[idx] < 0:
                _write_row(rows, iout, t, idx, f)
            touching[idx] = False
            return ST_END
        touching[idx], ramp[idx], clamped[idx] = True, True, False
        delta = pair_state(y, n, pi[idx], pj[idx], rsum[idx], phi, idx)[0]
        peak[idx], t_peak[idx], pen[idx] = 0.0, math.nan, max(0.0, delta)
        if pj[idx] < 0:
            f = pair_force(y, n, idx, pi, pj, law, rsum, ramp, clamped, phi, mass, g, omega,
                           zeta, fdead)[0]  # fmt: skip
            _write_row(rows, iout, t, idx, f)
        return ST_START
    r = iout[IO_LOG]
    if kind == R_FULL:
        ramp[idx] = not ramp[idx]
        log[r, 1] = LOG_FULL
    else:
        clamped[idx] = not clamped[idx]
        log[r, 1] = LOG_CLAMP_ON if clamped[idx] else LOG_CLAMP_OFF
    log[r, 0] = t
    log[r, 2] = idx
    iout[IO_LOG] = r + 1
    return -1


@helper_njit
def _apply_here(k, i, t, y, model, pstate, rows, log, iout, fresh, nfresh, f0):
    """Apply the event of row (k, i) at (t, y), remember the row as fresh (its function sits
    on 0 at the restart) and, after a kink handled here, recompute f0 = f(y) in the new
    region. Returns (status or -1, nfresh)."""
    status = _apply(k, i, t, y, model, pstate, rows, log, iout)
    if nfresh < MAX_FRESH:
        fresh[nfresh, 0], fresh[nfresh, 1] = k, i
        nfresh += 1
    if status < 0:
        rhs(y, model, pstate, f0)
        iout[IO_NFEV] += 1
    return status, nfresh


@helper_njit
def _settle(y, model, pstate, count, plate_pair):
    """First ball whose only touching pair is the plate and whose excess energy
    (``settle_excess``) is below its settle energy; -1 if none. Checked at step ends."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    touching = pstate[0]
    n = mass.shape[0]
    for b in range(n):
        count[b] = 0
        plate_pair[b] = -1
    for p in range(pi.shape[0]):
        if touching[p]:
            count[pi[p]] += 1
            if pj[p] >= 0:
                count[pj[p]] += 1
            else:
                plate_pair[pi[p]] = p
    for b in range(n):
        if e_settle[b] > 0.0 and alive[b] and count[b] == 1 and plate_pair[b] >= 0:
            if settle_excess(y, model, plate_pair[b], b) < e_settle[b]:
                return b
    return -1


@helper_njit
def _rows_needed(model, pstate, nodes):
    """Force rows one more step (and its events) may write: (nodes + 1) per touching plate
    pair, plus a start and an end row."""
    pi, pj = model[4], model[5]
    touching = pstate[0]
    m = 0
    for p in range(pi.shape[0]):
        if touching[p] and pj[p] < 0:
            m += 1
    return (nodes + 1) * m + 2


@njit(cache=True)
def advance(tio, y, t_stop, rtol, atol, max_steps, nodes, model, pstate, tab, pts, vinv, rows,
            log, iout):  # fmt: skip
    """Advance the active set from tio[0] with first step tio[1] until an event or t_stop.

    y (6 n + 2 m,) state in/out (m modes); atol (6 n + 2 m,) absolute tolerance per component.
    model = (mass, radius, g (3,), half (2,), pi, pj, law (P, 5), rsum, e_settle, alive,
    omega (m,), zeta (m,), phi (P, m), f_dead (m,)), pstate = (touching, ramp, clamped, peak,
    t_peak, pen): per-pair in/out.
    tab = DOP853 (A, B, E3, E5, D). rows (R, 3) force rows (t, pair, F) and log (L, 3) kinks
    (t, kind, pair) are appended from iout[IO_ROWS], iout[IO_LOG]. On return: tio = [t, next
    step], iout[IO_STATUS] (ST_*), iout[IO_INDEX] (pair or ball), iout[IO_EDGE], work counts.
    """
    nst = y.shape[0]
    K = np.zeros((16, nst))
    ynew = np.zeros(nst)
    tmp = np.zeros(nst)
    coef = np.zeros((7, nst))
    npts = pts.shape[0]
    nb = model[0].shape[0]
    npairs = model[4].shape[0]
    dense = (np.zeros((npts, nst)), np.zeros(nb, dtype=np.bool_), coef, np.zeros(nst),
             np.zeros(nst), np.zeros((npts, npairs, 4)), np.zeros(npairs, dtype=np.bool_),
             np.zeros((3, 8)))  # fmt: skip
    ws = (np.zeros(npts), np.zeros(npts), np.zeros(npts), np.zeros(npts), np.zeros(npts),
          np.zeros((256, 3)), np.zeros(nst))  # fmt: skip
    count = np.zeros(nb, dtype=np.int64)
    plate_pair = np.zeros(nb, dtype=np.int64)
    fresh = np.zeros((MAX_FRESH, 2), dtype=np.int64)
    nfresh = np.int64(0)  # (typed int64, not a literal: one compiled signature per helper)
    t, h = tio[0], tio[1]
    rhs(y, model, pstate, K[0])
    iout[IO_NFEV] += 1
    f0 = K[0].copy()
    pend_k, pend_i, pend_t = np.int64(-1), np.int64(-1), 0.0  # the pending event
    rejected = False
    attempts = 0
    status = -1
    while True:
        t_bound = pend_t if pend_k >= 0 else t_stop
        if t >= t_bound:
            if pend_k < 0:
                status = ST_STOP
                break
            k, i = pend_k, pend_i
            pend_k = np.int64(-1)
            if row_value(k, i, y, model, pstate) <= 2.0 * row_band(k, i, model[7]):
                status, nfresh = _apply_here(k, i, t, y, model, pstate, rows, log, iout, fresh,
                                             nfresh, f0)  # fmt: skip
                if status >= 0:
                    break
            continue
        if attempts >= max_steps:
            status = ST_STEP_LIMIT
            break
        if iout[IO_ROWS] + _rows_needed(model, pstate, nodes) > rows.shape[0] or (
            iout[IO_LOG] + 2 > log.shape[0]
        ):
            status = ST_BUFFER
            break
        hh = h
        last = False
        if hh >= t_bound - t:
            hh = t_bound - t
            last = True
        if hh <= 4.0 * EPS * abs(t):
            if last:  # the bound is within round-off of t: snap to it
                t = t_bound
                continue
            status = ST_STEP_TINY
            break
        attempts += 1
        K[0, :] = f0
        err = _step(y, hh, K, tab, rtol, atol, model, pstate, ynew, tmp)
        iout[IO_NFEV] += 12
        if not err <= 1.0:
            h = hh * (max(MIN_FACTOR, SAFETY * err ** (-1.0 / 8.0)) if err > 1.0 else MIN_FACTOR)
            rejected = True
            continue
        _dense_coef(y, ynew, hh, K, tab, model, pstate, coef, tmp)
        iout[IO_NFEV] += 3
        dense[3][:] = y
        _prepare(dense)
        s, k, i = _detect(dense, fresh, nfresh, pts, vinv, model, pstate, ws)
        if k >= 0 and pend_k >= 0 and t + s * hh >= pend_t - SAME_TIME * hh:
            k = -1  # (about) simultaneous with the pending event: taken after it
        factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err ** (-1.0 / 8.0))
        if rejected:
            factor = min(1.0, factor)
        rejected = False
        if k < 0:
            _accept(t, hh, ynew, dense, nodes, pts, vinv, model, pstate, rows, iout, ws)
            t = t_bound if last else t + hh
            y[:] = ynew
            f0[:] = K[12]
            nfresh = np.int64(0)  # (typed int64, not a literal: one compiled signature per helper)
            h = hh * factor
            iout[IO_STEPS] += 1
            b = _settle(y, model, pstate, count, plate_pair)
            if b >= 0:
                iout[IO_INDEX] = b
                status = ST_SETTLE
                break
            continue
        t_e = t + s * hh
        if t_e <= t + 4.0 * EPS * abs(t) or s == 0.0:  # at the restart: apply there
            status, nfresh = _apply_here(k, i, t, y, model, pstate, rows, log, iout, fresh, nfresh,
                                         f0)  # fmt: skip
            if status >= 0:
                break
            continue
        pend_k, pend_i, pend_t = k, i, t_e  # redo the step to end exactly at the event
        h = t_e - t
    if status == ST_START:
        h = min(h, first_contact_step(y, model, iout[IO_INDEX], rtol))
    tio[0] = t
    tio[1] = h
    iout[IO_STATUS] = status
    iout[IO_ATTEMPTS] += attempts
