"""Compiled (numba) DOP853 integrator of an active set of balls, with certified events.

One call advances the state from t until the first structural event or t_stop (see
``advance``). Per step: 12 + 3 right-hand-side evaluations (O(balls + touching pairs) each)
and every watched row (pairs and edges: O(pairs watched + balls)) certified in three tiers:
the bound B on how far each state component moves in the step, else the 15 Chebyshev values
of the row, else the first-crossing search (``events``). Helpers take arrays one by one
and are compiled without reference counting (``tailbeam.solvers.numerics.jit``); only
``advance`` and ``_workspaces`` allocate. Modules: the step and its dense output
(``step``), the event search (``events``), and here the loop and its
bookkeeping (peaks, force rows, applying events, settling).

With the optional modal plate (m modes after the balls in the state, ``pairs``) the
plate's deflection under a plate pair at the 15 points and at the force-row nodes comes from
the modes projected on that pair's phi first (``step.project``: O(m) per pair and
step); the far-pair bound adds sum |phi_k| B_k; the error norm is taken per block (balls,
modes). Without modes every operation and result is the rigid plate's, bit for bit. With
residual flexibility at a plate pair (``pairs.plate_force_with_residual``) its
full-damping row, like the clamp row, is sampled at the 15 points and closed by Illinois
(the law's delta is no polynomial on the step); the contact row stays the polynomial gap.

Event handling is the reference's (``tailbeam.solvers.stream.reference``): a step in which a row
crosses is discarded and redone to end exactly at the crossing, and the redone step is checked
again (an earlier root wins). At the end of the redone step the event is applied if its row is
within its dead band of the crossing. Kinks (full damping d crossed, clamp on/off) are applied
inside (logged by their ``EventCode``) and integration goes on in the new region; contact start
/ end, leave and a settled plate contact (``EventCode.REST``) return to the caller. Events
within ``SAME_TIME`` of a step of a pending one are taken after it, one after the other at the
same time (a symmetric 3-ball cluster). A row whose event was just applied sits on 0 at the
restart ("fresh": searched from ``tailbeam.solvers.numerics.chebyshev.FRESH_S`` on in the next
step); the fresh rows are handed back on return and carried into the next call that starts at
that instant (``set.ActiveSet.advance``; the stream driver carries them into a set rebuilt then,
``members``). A carried row whose crossing is found at the restart instant while it is back on
its side at FRESH_S is searched again as fresh (``fresh.found_again``): a START or END returned
to the caller is not applied again at once where its row sat on 0 (a grazing contact would stall
at one instant); a row still on its wrong side there, and a genuine new crossing later in the
step, are found as before.
"""

import math

import numpy as np

from tailbeam.jit import njit
from tailbeam.results.records import EventCode
from tailbeam.solvers.numerics.chebyshev import interpolant_max
from tailbeam.solvers.numerics.dop853 import growth, shrink
from tailbeam.solvers.numerics.jit import helper_njit
from tailbeam.solvers.stream.active.compiled.events import detect, prepare
from tailbeam.solvers.stream.active.compiled.fresh import MAX_FRESH, found_again, hand_back, mark
from tailbeam.solvers.stream.active.compiled.friction import (
    F_GRAD,
    F_LEVER,
    F_MOMENT,
    IMP_N,
    IMP_T,
    IMP_WORK,
    pair_friction,
    spin_offset,
)
from tailbeam.solvers.stream.active.compiled.pairs import (
    R_CONTACT,
    R_EDGE,
    R_FULL,
    first_contact_step,
    pair_force,
    pair_state,
    plate_force,
    rhs,
    row_band,
    row_value,
    settle_excess,
)
from tailbeam.solvers.stream.active.compiled.step import (
    EPS,
    dense_coef,
    dense_component,
    dense_projected,
    dop853_step,
    ensure_ball,
    ensure_plate,
    project_plate,
)

# What ``advance`` returns with (iout[IO_STATUS]): the ``EventCode`` of the event it stopped at
# (CONTACT_START, CONTACT_END, LEAVE; REST: a ball's plate contact settled; NONE: t_stop
# reached), or why it stopped early (private, never an event):
ST_BUFFER, ST_STEP_LIMIT, ST_STEP_TINY = 100, 101, 102  # a buffer is full, max_steps, h -> 0
# The kink log's kinds are the EventCode of each kink (FULL_DAMPING, CLAMP_ON, CLAMP_OFF).
# integer outputs (iout); IO_FRESH: the rows in ``fresh`` (in/out, see ``advance``);
# IO_AGAIN: events found again at the instant they were applied (searched again; counted)
IO_STATUS, IO_INDEX, IO_EDGE, IO_STEPS, IO_ATTEMPTS, IO_NFEV, IO_ROWS, IO_LOG = range(8)
IO_FRESH, IO_AGAIN = 8, 9
IO_SIZE = 10

SAME_TIME = 1e-9  # fraction of a step: events closer than this to a pending one wait for it


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
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    touching, ramp, clamped, peak, t_peak, pen, imp = pstate
    vals, wc, wv, wc2, wd, stack, tmp = ws
    Y15, have, coef, y, B, W15, have_w, proj = dense
    for p in range(pi.shape[0]):
        if not touching[p]:
            continue
        _pair_values(p, dense, pts, model, pstate, vals, wv)
        if fric.shape[1] > 0:
            _impulses(h, p, dense, pts, vinv, model, vals, imp, tmp)
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
        _node_rows(t, h, p, nodes, coef, y, ynew, model, pstate, rows, iout, proj, tmp)


@helper_njit
def _impulses(h, p, dense, pts, vinv, model, forces, imp, tmp):
    """Add touching pair p's impulses and friction work on the accepted step of h (s) to
    ``imp`` (``friction.IMP_*``): its normal ``forces`` (N) and friction at the 15 Chebyshev
    points integrated by the Clenshaw-Curtis rule of their interpolant (``cc_weight``); the
    balls' states there from the dense output (into ``tmp``)."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    coef, y0 = dense[2], dense[3]
    n = mass.shape[0]
    nm = omega.shape[0]
    off = spin_offset(n, nm)
    i, j = pi[p], pj[p]
    for q in range(pts.shape[0]):
        s = pts[q]
        for b in (i, j):
            if b < 0:
                continue
            for k in range(3):
                for base in (3 * b, 3 * n + 3 * b, off + 3 * b):
                    tmp[base + k] = dense_component(coef, y0, s, base + k)
        if j < 0 and fric.shape[1] > F_GRAD and fric[p, F_LEVER] != 0.0:
            for k in range(6 * n + nm, 6 * n + 2 * nm):  # the modal rates (surface velocity)
                tmp[k] = dense_component(coef, y0, s, k)
        _, _, nx, ny, nz = pair_state(tmp, n, i, j, rsum[p], phi, p)
        r = pair_friction(tmp, n, off, i, j, p, nx, ny, nz, forces[q], fric)
        wq = cc_weight(vinv, q) * h
        imp[p, IMP_N] += wq * forces[q]
        for k in range(3):
            imp[p, IMP_T + k] += wq * r[k]
        imp[p, IMP_WORK] += wq * r[9]


@helper_njit
def cc_weight(vinv, q):
    """Clenshaw-Curtis weight on [0, 1] of Chebyshev point q: the integral of the
    interpolant, c = vinv @ values and int_-1^1 T_k = 2 / (1 - k^2) for even k (halved)."""
    w = 0.0
    for k in range(0, vinv.shape[0], 2):
        w += vinv[k, q] / (1.0 - k * k)
    return w


@helper_njit
def _pair_values(p, dense, pts, model, pstate, forces, deltas):
    """Force (N) and penetration (m) of touching pair p at the 15 Chebyshev points."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    ramp, clamped = pstate[1], pstate[2]
    Y15, have, coef, y, B, W15, have_w, proj = dense
    n = mass.shape[0]
    i, j = pi[p], pj[p]
    ensure_ball(Y15, have, coef, y, pts, i)
    if j >= 0:
        ensure_ball(Y15, have, coef, y, pts, j)
        for q in range(pts.shape[0]):
            f, delta, _, _, _ = pair_force(Y15[q], n, p, pi, pj, law, rsum, ramp, clamped, phi,
                                           mass, g, omega, zeta, fdead)  # fmt: skip
            forces[q], deltas[q] = f, delta
        return
    ensure_plate(W15, have_w, coef, y, pts, model, p, proj)
    for q in range(pts.shape[0]):
        forces[q], deltas[q] = plate_force(p, Y15[q, 3 * i + 2], Y15[q, 3 * n + 3 * i + 2],
                                           W15[q, p, 0], W15[q, p, 1], W15[q, p, 2],
                                           W15[q, p, 3], law, rsum, ramp, clamped)  # fmt: skip


@helper_njit
def _node_rows(t, h, p, nodes, coef, y, ynew, model, pstate, rows, iout, proj, tmp):
    """Force rows of plate pair p at ``nodes`` interior points of the step and its end (the
    plate deflection under the ball from its projected dense output, ``project``); with
    friction's moment on the modal plate also its friction force's rows (``_friction_rows``;
    the state there from the dense output into ``tmp``)."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    ramp, clamped = pstate[1], pstate[2]
    n = mass.shape[0]
    i = pi[p]
    kappa = project_plate(coef, y, model, p, proj)
    wq, wv, wa = proj[0], proj[1], proj[2]
    for k in range(1, nodes + 1):
        s = k / (nodes + 1.0)
        z = dense_component(coef, y, s, 3 * i + 2)
        vz = dense_component(coef, y, s, 3 * n + 3 * i + 2)
        f = plate_force(p, z, vz, dense_projected(wq, s), dense_projected(wv, s),
                        dense_projected(wa, s), kappa, law, rsum, ramp, clamped)[0]  # fmt: skip
        _write_row(rows, iout, t + s * h, p, f)
        if _moment_rows(fric, p):
            _dense_plate_pair(coef, y, s, n, i, omega.shape[0], tmp)
            _friction_rows(rows, iout, t + s * h, tmp, n, p, i, f, model)
    f = pair_force(ynew, n, p, pi, pj, law, rsum, ramp, clamped, phi, mass, g, omega, zeta,
                   fdead)[0]  # fmt: skip
    _write_row(rows, iout, t + h, p, f)
    if _moment_rows(fric, p):
        _friction_rows(rows, iout, t + h, ynew, n, p, i, f, model)


@helper_njit
def _moment_rows(fric, p):
    """Whether plate pair p's friction force drives the modal plate (rows for the sensors)."""
    return fric.shape[1] > F_GRAD and fric[p, F_MOMENT] != 0.0


@helper_njit
def _dense_plate_pair(coef, y, s, n, i, nm, out):
    """Ball i's position, velocity and angular velocity and the modal rates at fraction s of
    the step (dense output) into ``out`` (a state-sized array)."""
    off = spin_offset(n, nm)
    for k in range(3):
        for base in (3 * i, 3 * n + 3 * i, off + 3 * i):
            out[base + k] = dense_component(coef, y, s, base + k)
    for k in range(6 * n + nm, 6 * n + 2 * nm):
        out[k] = dense_component(coef, y, s, k)


@helper_njit
def _friction_rows(rows, iout, t, y, n, p, i, f, model):
    """Rows (t, p + P, F_x) and (t, p + 2 P, F_y) of plate pair p's friction force on its
    ball (N) at state y and normal force f (N): P the number of pairs (the plate takes
    -F_t on its top surface, ``forces.PlateForces``)."""
    fric, omega, pi = model[14], model[10], model[4]
    npairs = pi.shape[0]
    r = pair_friction(y, n, spin_offset(n, omega.shape[0]), i, -1, p, 0.0, 0.0, 1.0, f, fric)
    _write_row(rows, iout, t, p + npairs, r[0])
    _write_row(rows, iout, t, p + 2 * npairs, r[1])


@helper_njit
def _apply(kind, idx, t, y, model, pstate, rows, log, iout):
    """Apply the event of row (kind, idx) at time t, state y; returns the status to return
    with (EventCode.CONTACT_START, CONTACT_END, LEAVE) or EventCode.NONE for a kink handled
    here (logged)."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    touching, ramp, clamped, peak, t_peak, pen, imp = pstate
    n = mass.shape[0]
    if kind == R_EDGE:
        iout[IO_INDEX] = idx // 4
        iout[IO_EDGE] = idx % 4
        return EventCode.LEAVE
    iout[IO_INDEX] = idx
    if kind == R_CONTACT:
        f = pair_force(y, n, idx, pi, pj, law, rsum, ramp, clamped, phi, mass, g, omega, zeta,
                       fdead)[0]  # fmt: skip
        if touching[idx]:
            if pj[idx] < 0:
                _write_row(rows, iout, t, idx, f)
            touching[idx] = False
            return EventCode.CONTACT_END
        touching[idx], ramp[idx], clamped[idx] = True, True, False
        delta = pair_state(y, n, pi[idx], pj[idx], rsum[idx], phi, idx)[0]
        peak[idx], t_peak[idx], pen[idx] = 0.0, math.nan, max(0.0, delta)
        for k in range(imp.shape[1]):
            imp[idx, k] = 0.0
        if pj[idx] < 0:
            f = pair_force(y, n, idx, pi, pj, law, rsum, ramp, clamped, phi, mass, g, omega,
                           zeta, fdead)[0]  # fmt: skip
            _write_row(rows, iout, t, idx, f)
        return EventCode.CONTACT_START
    r = iout[IO_LOG]
    if kind == R_FULL:
        ramp[idx] = not ramp[idx]
        log[r, 1] = np.int64(EventCode.FULL_DAMPING)  # (an integer code in the float log)
    else:
        clamped[idx] = not clamped[idx]
        log[r, 1] = np.int64(EventCode.CLAMP_ON if clamped[idx] else EventCode.CLAMP_OFF)
    log[r, 0] = t
    log[r, 2] = idx
    iout[IO_LOG] = r + 1
    return EventCode.NONE


@helper_njit
def _apply_here(k, i, t, y, model, pstate, rows, log, iout, fresh, nfresh, f0):
    """Apply the event of row (k, i) at (t, y), remember the row as fresh (its function sits
    on 0 at the restart) and, after a kink handled here, recompute f0 = f(y) in the new
    region. Returns (status or EventCode.NONE, nfresh)."""
    status = _apply(k, i, t, y, model, pstate, rows, log, iout)
    nfresh = mark(k, i, fresh, nfresh)
    if status == EventCode.NONE:
        rhs(y, model, pstate, f0)
        iout[IO_NFEV] += 1
    return status, nfresh


@helper_njit
def _settle(y, model, pstate, count, plate_pair):
    """First ball whose only touching pair is the plate and whose excess energy
    (``settle_excess``) is below its settle energy; -1 if none. Checked at step ends."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
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
    pair (three times that with friction's rows, ``_friction_rows``), plus a start and an
    end row."""
    pi, pj, fric = model[4], model[5], model[14]
    touching = pstate[0]
    m = 0
    for p in range(pi.shape[0]):
        if touching[p] and pj[p] < 0:
            m += 3 if _moment_rows(fric, p) else 1
    return (nodes + 1) * m + 2


@helper_njit
def _apply_pending(k, i, t, y, model, pstate, rows, log, iout, fresh, nfresh, f0):
    """At the end of the step redone to end at the pending event of row (k, i): apply it
    (``_apply_here``) if the row is within twice its dead band of the crossing, else drop it.
    Returns (status or EventCode.NONE, nfresh)."""
    if row_value(k, i, y, model, pstate) <= 2.0 * row_band(k, i, model[7]):
        return _apply_here(k, i, t, y, model, pstate, rows, log, iout, fresh, nfresh, f0)
    return EventCode.NONE, nfresh


@helper_njit
def _limits(attempts, max_steps, nodes, model, pstate, rows, log, iout):
    """ST_STEP_LIMIT after max_steps attempts, ST_BUFFER if one more step (and its events)
    could overflow the force rows or the kink log, else EventCode.NONE."""
    if attempts >= max_steps:
        return ST_STEP_LIMIT
    if iout[IO_ROWS] + _rows_needed(model, pstate, nodes) > rows.shape[0] or (
        iout[IO_LOG] + 2 > log.shape[0]
    ):
        return ST_BUFFER
    return EventCode.NONE


@helper_njit
def _attempt(y, h, K, f0, tab, rtol, atol, model, pstate, ynew, tmp, iout):
    """One DOP853 step of h (s) from y with f(y) = f0 (``dop853_step``); returns its error
    norm (> 1 or NaN: reject)."""
    for q in range(f0.shape[0]):
        K[0, q] = f0[q]
    err = dop853_step(y, h, K, tab, rtol, atol, model, pstate, ynew, tmp)
    iout[IO_NFEV] += 12
    return err


@helper_njit
def _step_events(y, ynew, h, K, tab, model, pstate, dense, fresh, nfresh, pts, vinv, ws, iout,
                 tmp):  # fmt: skip
    """Dense output of a step of h (s) that passed the error test, then the earliest row
    crossing in it: (s fraction of the step, kind, idx), kind -1 if none (``detect``)."""
    dense_coef(y, ynew, h, K, tab, model, pstate, dense[2], tmp)
    iout[IO_NFEV] += 3
    y0 = dense[3]
    for q in range(y.shape[0]):
        y0[q] = y[q]
    prepare(dense)
    return detect(dense, fresh, nfresh, pts, vinv, model, pstate, ws)


@helper_njit
def _take_step(t, h, y, ynew, f0, K, dense, nodes, pts, vinv, model, pstate, rows, iout, ws,
               count, plate_pair):  # fmt: skip
    """Accept the step of h (s) from t (s) (peaks and force rows: ``_accept``): y = ynew,
    f0 = f(ynew). Returns the first ball that settles at its end (``_settle``), or -1."""
    _accept(t, h, ynew, dense, nodes, pts, vinv, model, pstate, rows, iout, ws)
    for q in range(y.shape[0]):
        y[q] = ynew[q]
        f0[q] = K[12, q]
    iout[IO_STEPS] += 1
    return _settle(y, model, pstate, count, plate_pair)


@njit(cache=True)
def _workspaces(y, model, pts):
    """Scratch arrays of one ``advance`` call: (K (16, N) stages, ynew (N,), tmp (N,), dense,
    ws, count (n,), plate_pair (n,), fresh (MAX_FRESH, 2)) with dense = (Y15, have, coef,
    y0, B, W15, have_w, proj) the step's dense output at the 15 points (``prepare``) and ws =
    (vals, wc, wv, wc2, wd, stack, tmp) the event search's (``detect``)."""
    nst = y.shape[0]
    npts = pts.shape[0]
    nb = model[0].shape[0]
    npairs = model[4].shape[0]
    dense = (np.zeros((npts, nst)), np.zeros(nb, dtype=np.bool_), np.zeros((7, nst)),
             np.zeros(nst), np.zeros(nst), np.zeros((npts, npairs, 4)),
             np.zeros(npairs, dtype=np.bool_), np.zeros((3, 8)))  # fmt: skip
    ws = (np.zeros(npts), np.zeros(npts), np.zeros(npts), np.zeros(npts), np.zeros(npts),
          np.zeros((256, 3)), np.zeros(nst))  # fmt: skip
    count = np.zeros(nb, dtype=np.int64)
    plate_pair = np.zeros(nb, dtype=np.int64)
    fresh = np.zeros((MAX_FRESH, 2), dtype=np.int64)
    return np.zeros((16, nst)), np.zeros(nst), np.zeros(nst), dense, ws, count, plate_pair, fresh


@helper_njit
def _run(t, h, f0, y, t_stop, rtol, atol, max_steps, nodes, model, pstate, tab, pts, vinv,
         rows, log, iout, work, carried, ncarried):  # fmt: skip
    """The stepping loop of ``advance`` from t (s) with first step h (s), f0 = f(y) (work:
    ``_workspaces``) and carried[:ncarried] the rows the previous call applied at t: returns
    (status, t, next step h, attempts, nfresh: the rows in work's fresh applied at that t)."""
    K, ynew, tmp, dense, ws, count, plate_pair, fresh = work
    nfresh = np.int64(0)  # (typed int64, not a literal: one compiled signature per helper)
    t0 = t
    pend_k, pend_i, pend_t = np.int64(-1), np.int64(-1), 0.0  # the pending event
    rejected = False
    attempts = 0
    while True:
        t_bound = pend_t if pend_k >= 0 else t_stop
        if t >= t_bound:
            if pend_k < 0:
                return EventCode.NONE, t, h, attempts, nfresh
            status, nfresh = _apply_pending(pend_k, pend_i, t, y, model, pstate, rows, log, iout,
                                            fresh, nfresh, f0)  # fmt: skip
            pend_k = np.int64(-1)
            if status != EventCode.NONE:
                return status, t, h, attempts, nfresh
            continue
        status = _limits(attempts, max_steps, nodes, model, pstate, rows, log, iout)
        if status != EventCode.NONE:
            return status, t, h, attempts, nfresh
        last = h >= t_bound - t
        hh = t_bound - t if last else h
        if hh <= 4.0 * EPS * abs(t):
            if last:  # the bound is within round-off of t: snap to it
                t = t_bound
                continue
            return ST_STEP_TINY, t, h, attempts, nfresh
        attempts += 1
        err = _attempt(y, hh, K, f0, tab, rtol, atol, model, pstate, ynew, tmp, iout)
        if not err <= 1.0:
            h = hh * shrink(err)
            rejected = True
            continue
        s, k, i = _step_events(y, ynew, hh, K, tab, model, pstate, dense, fresh, nfresh, pts,
                               vinv, ws, iout, tmp)  # fmt: skip
        if k >= 0 and pend_k >= 0 and t + s * hh >= pend_t - SAME_TIME * hh:
            k = -1  # (about) simultaneous with the pending event: taken after it
        if k >= 0 and found_again(k, i, s, hh, t, t0, carried, ncarried, fresh, nfresh, dense,
                                   model, pstate, tmp):  # fmt: skip
            nfresh = mark(k, i, fresh, nfresh)  # (its event was just applied: search again)
            iout[IO_AGAIN] += 1
            continue
        factor = growth(err, rejected)
        rejected = False
        if k < 0:
            b = _take_step(t, hh, y, ynew, f0, K, dense, nodes, pts, vinv, model, pstate, rows,
                           iout, ws, count, plate_pair)  # fmt: skip
            t = t_bound if last else t + hh
            nfresh = np.int64(0)
            h = hh * factor
            if b >= 0:
                iout[IO_INDEX] = b
                return EventCode.REST, t, h, attempts, nfresh
            continue
        t_e = t + s * hh
        if t_e <= t + 4.0 * EPS * abs(t) or s == 0.0:  # at the restart: apply there
            status, nfresh = _apply_here(k, i, t, y, model, pstate, rows, log, iout, fresh,
                                         nfresh, f0)  # fmt: skip
            if status != EventCode.NONE:
                return status, t, h, attempts, nfresh
            continue
        pend_k, pend_i, pend_t = k, i, t_e  # redo the step to end exactly at the event
        h = t_e - t


@njit(cache=True)
def advance(tio, y, t_stop, rtol, atol, max_steps, nodes, model, pstate, tab, pts, vinv, rows,
            log, iout, fresh):  # fmt: skip
    """Advance the active set from tio[0] with first step tio[1] until an event or t_stop.

    y (6 n + 2 m,) state in/out (m modes); atol (6 n + 2 m,) absolute tolerance per component.
    model = (mass, radius, g (3,), half (2,), pi, pj, law (P, L_CRES + 1), rsum, e_settle, alive,
    omega (m,), zeta (m,), phi (P, m), f_dead (m,)), pstate = (touching, ramp, clamped, peak,
    t_peak, pen): per-pair in/out.
    tab = DOP853 (A, B, E3, E5, D). rows (R, 3) force rows (t, pair, F) and log (L, 3) kinks
    (t, kind, pair) are appended from iout[IO_ROWS], iout[IO_LOG]. On return: tio = [t, next
    step], iout[IO_STATUS] (an ``EventCode``: the event returned at, NONE at t_stop; or a
    private ST_* when it stopped early), iout[IO_INDEX] (pair or ball), iout[IO_EDGE], work
    counts.

    fresh (MAX_FRESH, 2) rows (kind, index) whose events were applied at tio[0], in/out: the
    first iout[IO_FRESH] on entry (the caller passes those of the previous return when it
    restarts at that time, else none) and on return those applied at the returned time
    (with those carried in if time did not move). Their functions sit on 0 at the restart:
    a crossing of one of them found at the restart instant (where it would be applied
    there: the same event again) while the row is back on its side at ``FRESH_S`` of the
    step makes it fresh for this call and the step is searched again, from ``FRESH_S`` on
    for that row, so a genuine new crossing later in the step is still found; a row still
    on the wrong side at ``FRESH_S`` crosses there genuinely and is applied at the restart.
    Any other search is exactly as without the markers.
    """
    work = _workspaces(y, model, pts)
    K = work[0]
    rhs(y, model, pstate, K[0])
    iout[IO_NFEV] += 1
    f0 = K[0].copy()
    ncarried = np.int64(min(max(iout[IO_FRESH], 0), MAX_FRESH))
    status, t, h, attempts, nfresh = _run(tio[0], tio[1], f0, y, t_stop, rtol, atol, max_steps,
                                          nodes, model, pstate, tab, pts, vinv, rows, log, iout,
                                          work, fresh, ncarried)  # fmt: skip
    iout[IO_FRESH] = hand_back(fresh, ncarried, work[7], nfresh, t == tio[0])
    if status == EventCode.CONTACT_START:
        h = min(h, first_contact_step(y, model, iout[IO_INDEX], rtol))
    tio[0] = t
    tio[1] = h
    iout[IO_STATUS] = status
    iout[IO_ATTEMPTS] += attempts
