"""Compiled (numba) integrator of one ball-plate contact: DOP853 with kink events.

Why DOP853: the contact ODE is 2-D, non-stiff (the contact lasts a few of its own time scales)
and wanted to 1e-8..1e-12, where an 8th-order embedded Runge-Kutta pair takes few steps, and its
7th-degree dense output lets events be located on the polynomial without extra force
evaluations. The coefficient tables are scipy's (imported at run time, passed in as arrays).

State: penetration delta (m) and rate u = d delta/dt (m/s) in the local time tau = t -
t_contact, so nothing cancels (z = R - delta would lose delta's digits). m du/dt = m g - F.

Regions and kinks. The force law is smooth inside each region (ramp: delta < d, or full damping;
clamped: force held at 0 because k delta^e + STEP u < 0, or not) and the integrator uses that
region's formula, extended smoothly past its border, so no step straddles a kink. Watched
functions (sign changes located on the dense output to machine precision, then restart):
  full_damping  delta - d                   clamp_on/off  raw / (k delta^e)  (the clamp
  contact_end   delta (downwards)           indicator: sign of the raw force, not 0 at delta=0)
  rest          excess energy - E_rest (rule B, model.py)
and, without restart, u = 0 (maximum penetration) and dF/dt = 0 (peak force). Each watched
function is also checked at 3 interior points of every step, so a quick double crossing inside
one step is not missed; the function an integration restarts on (0 there) is divided by
(tau - tau_restart), which keeps its sign and roots but not the spurious zero at the start.

Contact start: F ~ delta^e ~ tau^e is not smooth at tau = 0; the first step is chosen from the
scales (h0 = t_s rtol^(1/(e+2)), the step at which the tau^(e+2) term of delta reaches rtol) and
the error control grows it geometrically, which keeps the 8th-order accuracy of later steps
(measured: tests/test_rigid_hertz.py reaches 1e-12 against the closed form).
"""

import math

import numpy as np

from tailbeam.jit import njit
from tailbeam.physics.contact_law import LAW_C, LAW_CLAMP, LAW_D
from tailbeam.results.records import EventCode
from tailbeam.solvers.numerics.dop853 import growth, shrink
from tailbeam.solvers.numerics.jit import helper_njit
from tailbeam.solvers.rigid.regions import (
    EPS,
    INTERIOR,
    N_WATCH,
    P_EREST,
    W_CLAMP,
    W_FULL,
    W_PEAK,
    W_REST,
    W_SEP,
    W_UMAX,
    accel,
    crosses,
    dense_eval,
    find_root,
    watch_all,
)
from tailbeam.solvers.rigid.step import dense_coefficients, step

# how integrate_contact ended (ires[I_STATUS])
ST_SEPARATED, ST_REST, ST_DURATION, ST_STEP_LIMIT, ST_BUFFER_FULL, ST_STEP_TINY = range(6)
# res and ires (the outputs) double as the running maxima and counters of the loop
R_TAU, R_VOUT, R_PEAK, R_TPEAK, R_PEN = range(5)
I_STATUS, I_PIECES, I_EVENTS, I_NFEV, I_STEPS, I_ATTEMPTS = range(6)


@helper_njit
def _watch_flags(direction, active, ramp, clamped, to_end, par):
    """Crossing direction (+1 up, -1 down) and whether each watched function is watched in
    the region (ramp, clamped); to_end: the step ends at the separation already located."""
    direction[W_FULL] = 1.0 if ramp else -1.0
    direction[W_CLAMP] = 1.0 if clamped else -1.0
    direction[W_SEP] = -1.0
    direction[W_REST] = -1.0
    direction[W_UMAX] = -1.0
    direction[W_PEAK] = -1.0
    active[W_FULL] = True
    active[W_CLAMP] = par[LAW_CLAMP] > 0.0 and par[LAW_C] > 0.0
    active[W_SEP] = not to_end
    active[W_REST] = par[P_EREST] > 0.0
    active[W_UMAX] = True
    active[W_PEAK] = not clamped


@helper_njit
def _watch_step(y0, y1, n0, n1, coef, ramp, clamped, par, fresh_w, direction, G, buf):
    """Watched functions at the step's start, its 3 interior points and its end into the rows
    of G (x = 0, 0.25, 0.5, 0.75, 1); the restart function fresh_w (0 at x = 0) divided by
    x. Returns the contact force (N) at both ends."""
    force_a = watch_all(y0, y1, ramp, clamped, par, G[0])
    force_b = watch_all(n0, n1, ramp, clamped, par, G[4])
    for q in range(3):
        dl, uq = dense_eval(INTERIOR[q], y0, y1, coef)
        watch_all(dl, uq, ramp, clamped, par, buf)
        for w in range(N_WATCH):
            G[q + 1, w] = buf[w]
    if fresh_w >= 0:
        G[0, fresh_w] = -direction[fresh_w]
        for q in range(3):
            G[q + 1, fresh_w] /= INTERIOR[q]
    return force_a, force_b


@helper_njit
def _root_in(w, q, dirn, fresh, G, y0, y1, coef, ramp, clamped, par, buf, xtol):
    """Root (fraction of the step) of watched function w in the q-th quarter of the step
    (values at its ends: G[q, w], G[q + 1, w]) if it crosses there in direction dirn (+1 up,
    -1 down), else -1; fresh: w is the restart function (``regions.find_root``)."""
    xa = 0.0 if q == 0 else INTERIOR[q - 1]
    xb = INTERIOR[q] if q < 3 else 1.0
    va, vb = G[q, w], G[q + 1, w]
    if not crosses(va, vb, dirn):
        return -1.0
    return find_root(w, xa, va, xb, vb, fresh, y0, y1, coef, ramp, clamped, par, buf, xtol)


@helper_njit
def _first_kink(active, direction, G, fresh_w, y0, y1, coef, ramp, clamped, par, buf, xtol):
    """Earliest crossing (x_sw, w_sw) in the step of a terminal watched function (kinks,
    separation, rest): x_sw in [0, 1] of the step, w_sw = -1 (x_sw = 2) if none."""
    x_sw = 2.0
    w_sw = -1
    for w in range(4):
        if not active[w]:
            continue
        for q in range(4):
            if (0.0 if q == 0 else INTERIOR[q - 1]) >= x_sw:
                break
            xr = _root_in(w, q, direction[w], fresh_w == w, G, y0, y1, coef, ramp, clamped, par,
                          buf, xtol)  # fmt: skip
            if xr >= 0.0:
                if xr < x_sw:
                    x_sw, w_sw = xr, w
                break
    return x_sw, w_sw


@helper_njit
def _maxima(active, G, x_end, tau, h, y0, y1, coef, ramp, clamped, par, buf, xtol, force_a,
            res):  # fmt: skip
    """Update the maxima of the penetration (m) and of the force (N, at tau_peak s) in res
    with the step up to x_end of it (its start included, its end not)."""
    pen, peak, tau_peak = res[R_PEN], res[R_PEAK], res[R_TPEAK]
    for w in (W_UMAX, W_PEAK):
        if not active[w]:
            continue
        for q in range(4):
            if (0.0 if q == 0 else INTERIOR[q - 1]) >= x_end:
                break
            xr = _root_in(w, q, -1.0, False, G, y0, y1, coef, ramp, clamped, par, buf, xtol)
            if 0.0 <= xr <= x_end:
                dl, uq = dense_eval(xr, y0, y1, coef)
                fr = watch_all(dl, uq, ramp, clamped, par, buf)
                if w == W_UMAX:
                    pen = max(pen, dl)
                elif fr > peak:
                    peak, tau_peak = fr, tau + xr * h
    _update_maxima(res, force_a, tau, y0, pen, peak, tau_peak)


@helper_njit
def _update_maxima(res, force, tau_f, delta, pen, peak, tau_peak):
    """Write the maxima (pen m, peak N at tau_peak s) into res after comparing them with a
    force (N) at tau_f (s) and a penetration delta (m)."""
    if force > peak:
        peak, tau_peak = force, tau_f
    res[R_PEN] = max(pen, delta)
    res[R_PEAK] = peak
    res[R_TPEAK] = tau_peak


@helper_njit
def _examine(K, A, D, y0, y1, n0, n1, f0, f1, tau, h, h0, ramp, clamped, par, fresh_w, to_end,
             W, res, ires):  # fmt: skip
    """Dense output (into W[0]; counted in ires) and events of a step of h (s) from tau (s)
    that passed the error test (W: scratch arrays, see ``integrate_contact``): returns
    (x_sw, w_sw, redo, force_b) with the earliest terminal crossing (``_first_kink``), redo
    True if it is a separation to end the step at (beyond delta = 0 the force is 0: the step
    straddles a kink, so rather than trust its dense output it is redone to end exactly
    there, unless that is closer than the time resolution: then it ends at the root), and
    the force (N) at the step's end; else the maxima in res are updated with the step."""
    coef, buf, direction, active, G = W
    ires[I_STEPS] += 1
    ires[I_NFEV] += 3
    dense_coefficients(K, A, D, y0, y1, n0, n1, f0, f1, h, ramp, clamped, par, coef)
    _watch_flags(direction, active, ramp, clamped, to_end, par)
    force_a, force_b = _watch_step(y0, y1, n0, n1, coef, ramp, clamped, par, fresh_w,
                                   direction, G, buf)  # fmt: skip
    xtol = 2.0 * EPS * (abs(tau) + h) / h
    x_sw, w_sw = _first_kink(active, direction, G, fresh_w, y0, y1, coef, ramp, clamped, par,
                             buf, xtol)  # fmt: skip
    if w_sw == W_SEP and x_sw * h > 64.0 * EPS * max(abs(tau), h0):
        return x_sw, w_sw, True, force_b
    _maxima(active, G, min(x_sw, 1.0), tau, h, y0, y1, coef, ramp, clamped, par, buf, xtol,
            force_a, res)  # fmt: skip
    return x_sw, w_sw, False, force_b


@helper_njit
def _store_piece(p_tau, p_h, p_y, p_coef, ires, tau, h, y0, y1, coef):
    """Append a dense-output piece: start tau (s), length h (s), start state, coefficients;
    returns False (nothing written) if a buffer is full."""
    npc = ires[I_PIECES]
    if npc >= p_tau.shape[0]:
        return False
    p_tau[npc] = tau
    p_h[npc] = h
    p_y[npc, 0] = y0
    p_y[npc, 1] = y1
    for i in range(7):
        p_coef[npc, i, 0] = coef[i, 0]
        p_coef[npc, i, 1] = coef[i, 1]
    ires[I_PIECES] = npc + 1
    return True


@helper_njit
def _at_kink(x_sw, tau, h, y0, y1, coef, ramp, clamped, par, buf, res):
    """State at the located crossing x_sw of the step: (tau_ev s, delta m, u m/s); the
    maxima in res updated with it."""
    tau_ev = tau + x_sw * h
    d_ev, u_ev = dense_eval(x_sw, y0, y1, coef)
    f_ev = watch_all(d_ev, u_ev, ramp, clamped, par, buf)
    _update_maxima(res, f_ev, tau_ev, d_ev, res[R_PEN], res[R_PEAK], res[R_TPEAK])
    return tau_ev, d_ev, u_ev


@helper_njit
def _switch_region(w_sw, d_ev, ramp, clamped, par):
    """The region after kink w_sw (full damping or clamp): (delta m to restart from, ramp,
    clamped, event code); the full-damping restart sits exactly on delta = d."""
    if w_sw == W_FULL:
        return par[LAW_D], not ramp, clamped, EventCode.FULL_DAMPING
    clamped = not clamped
    return d_ev, ramp, clamped, EventCode.CLAMP_ON if clamped else EventCode.CLAMP_OFF


@helper_njit
def _log(ev_tau, ev_kind, ires, tau, kind):
    """Append event (tau s, kind) to the event buffer (its room checked per step)."""
    ev_tau[ires[I_EVENTS]] = tau
    ev_kind[ires[I_EVENTS]] = kind
    ires[I_EVENTS] += 1


@helper_njit
def _finish(res, ires, status, tau, v_out):
    """End status and time (s), rebound speed (m/s; NaN unless separated, 0 at rest)."""
    ires[I_STATUS] = status
    res[R_TAU] = tau
    res[R_VOUT] = v_out


@njit(cache=True)
def integrate_contact(
    par, v_in, tau_max, rtol, atol0, atol1, h0, h_max, max_steps,
    A, B, C, E3, E5, D,
    p_tau, p_h, p_y, p_coef, ev_tau, ev_kind, res, ires,
):  # fmt: skip
    """Integrate one contact from delta = 0, u = v_in until separation, rest (rule B) or
    tau_max. Writes the dense-output pieces (p_*), the kink events (ev_*), and
    res = [tau_end, v_out, peak_force, tau_peak, max_penetration],
    ires = [status, n_pieces, n_events, nfev, n_steps, n_attempts]."""
    K = np.zeros((16, 2))  # stages; W = (coef, buf, direction, active, watched values G)
    W = (np.zeros((7, 2)), np.zeros(N_WATCH), np.zeros(N_WATCH), np.zeros(N_WATCH, dtype=np.bool_),
         np.zeros((5, N_WATCH)))  # fmt: skip
    tau, y0, y1, ramp, clamped, fresh_w = 0.0, 0.0, v_in, True, False, -1
    res[:] = 0.0
    ires[:] = 0
    f0, f1 = y1, accel(y0, y1, ramp, clamped, par)
    ires[I_NFEV] = 1
    h = min(h0, h_max)
    rejected = to_end = False  # to_end: this step was cut to end exactly at the separation
    while True:
        if tau >= tau_max or ires[I_ATTEMPTS] >= max_steps:
            return _finish(res, ires, ST_DURATION if tau >= tau_max else ST_STEP_LIMIT, tau,
                           math.nan)  # fmt: skip
        last = h >= tau_max - tau
        h = tau_max - tau if last else h
        if h <= 8.0 * EPS * max(abs(tau), h0):
            return _finish(res, ires, ST_STEP_TINY, tau, math.nan)
        ires[I_ATTEMPTS] += 1
        ires[I_NFEV] += 12
        n0, n1, err = step(K, A, B, E3, E5, y0, y1, f0, f1, h, ramp, clamped, par, rtol, atol0,
                           atol1)  # fmt: skip
        if not err <= 1.0:  # also rejects a NaN error (overflow in a far-off stage)
            h *= shrink(err)
            # (a shorter step cannot end at the separation: locate it again)
            rejected, to_end = True, False
            continue
        x_sw, w_sw, redo, force_b = _examine(K, A, D, y0, y1, n0, n1, f0, f1, tau, h, h0,
                                             ramp, clamped, par, fresh_w, to_end, W, res,
                                             ires)  # fmt: skip
        if redo:
            h, to_end = h * x_sw, True
            continue
        if ires[I_EVENTS] >= ev_tau.shape[0] or not _store_piece(p_tau, p_h, p_y, p_coef, ires,
                                                                 tau, h, y0, y1, W[0]):  # fmt: skip
            return _finish(res, ires, ST_BUFFER_FULL, tau, math.nan)
        h_next = min(h * growth(err, rejected), h_max)
        rejected = False
        if w_sw < 0:
            _update_maxima(res, force_b, tau + h, n0, res[R_PEN], res[R_PEAK], res[R_TPEAK])
            if to_end:
                _log(ev_tau, ev_kind, ires, tau + h, EventCode.CONTACT_END)
                return _finish(res, ires, ST_SEPARATED, tau + h, -n1)
            tau = tau_max if last else tau + h
            y0, y1, f0, f1, fresh_w, h = n0, n1, K[12, 0], K[12, 1], -1, h_next
            continue
        # --- a kink: restart there in the new region ---
        tau, d_ev, u_ev = _at_kink(x_sw, tau, h, y0, y1, W[0], ramp, clamped, par, W[1], res)
        if w_sw == W_SEP or (d_ev <= 0.0 and u_ev < 0.0):
            # (a kink this close to the separation that the restart state is already out)
            _log(ev_tau, ev_kind, ires, tau, EventCode.CONTACT_END)
            return _finish(res, ires, ST_SEPARATED, tau, -u_ev)
        if w_sw == W_REST:
            return _finish(res, ires, ST_REST, tau, 0.0)
        y0, ramp, clamped, kind = _switch_region(w_sw, d_ev, ramp, clamped, par)
        _log(ev_tau, ev_kind, ires, tau, kind)
        y1, fresh_w, to_end, h = u_ev, w_sw, False, h_next
        f0, f1 = y1, accel(y0, y1, ramp, clamped, par)
        ires[I_NFEV] += 1
