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
from numba import njit

from tailbeam.solvers.rigid.regions import (  # noqa: F401  (re-exported for solver.py)
    EPS,
    EV_CLAMP_OFF,
    EV_CLAMP_ON,
    EV_END,
    EV_FULL,
    EV_REST,
    EVENT_NAMES,
    INTERIOR,
    MAX_FACTOR,
    MIN_FACTOR,
    N_WATCH,
    P_C,
    P_CLAMP,
    P_D,
    P_EREST,
    SAFETY,
    ST_BUFFER_FULL,
    ST_DURATION,
    ST_REST,
    ST_SEPARATED,
    ST_STEP_LIMIT,
    ST_STEP_TINY,
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


def dop853_tables():
    """(A, B, C, E3, E5, D) of Dormand-Prince 8(5,3) with its 7th-degree dense output."""
    from scipy.integrate._ivp import dop853_coefficients as co

    return tuple(
        np.ascontiguousarray(x, dtype=float) for x in (co.A, co.B, co.C, co.E3, co.E5, co.D)
    )


@njit(cache=True)
def _stages(K, A, first, stop, y0, y1, h, ramp, clamped, par):
    """Runge-Kutta stages first..stop-1 of the state (delta, u) into K (rows: stages)."""
    for s in range(first, stop):
        s0 = 0.0
        s1 = 0.0
        for j in range(s):
            s0 += A[s, j] * K[j, 0]
            s1 += A[s, j] * K[j, 1]
        uu = y1 + h * s1
        K[s, 0] = uu
        K[s, 1] = accel(y0 + h * s0, uu, ramp, clamped, par)


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
    K = np.zeros((16, 2))
    coef = np.zeros((7, 2))
    ga = np.zeros(N_WATCH)
    gb = np.zeros(N_WATCH)
    gi = np.zeros((3, N_WATCH))
    buf = np.zeros(N_WATCH)
    direction = np.zeros(N_WATCH)
    active = np.zeros(N_WATCH, dtype=np.bool_)
    clamp_law = par[P_CLAMP] > 0.0 and par[P_C] > 0.0
    tau, y0, y1 = 0.0, 0.0, v_in
    ramp, clamped = True, False
    fresh_w = -1
    npc = nev = nfev = nsteps = attempts = 0
    peak = tau_peak = pen = 0.0
    v_out = math.nan
    f0, f1 = y1, accel(y0, y1, ramp, clamped, par)
    nfev += 1
    h = min(h0, h_max)
    rejected = False
    to_end = False  # this step was cut to end exactly at the separation
    status = ST_DURATION
    while True:
        if tau >= tau_max:
            status = ST_DURATION
            break
        if attempts >= max_steps:
            status = ST_STEP_LIMIT
            break
        last = False
        if h >= tau_max - tau:
            h = tau_max - tau
            last = True
        if h <= 8.0 * EPS * max(abs(tau), h0):
            status = ST_STEP_TINY
            break
        attempts += 1
        # --- one DOP853 step (autonomous system) ---
        K[0, 0] = f0
        K[0, 1] = f1
        _stages(K, A, 1, 12, y0, y1, h, ramp, clamped, par)
        b0 = 0.0
        b1 = 0.0
        for j in range(12):
            b0 += B[j] * K[j, 0]
            b1 += B[j] * K[j, 1]
        n0 = y0 + h * b0
        n1 = y1 + h * b1
        K[12, 0] = n1
        K[12, 1] = accel(n0, n1, ramp, clamped, par)
        nfev += 12
        e50 = e51 = e30 = e31 = 0.0
        for j in range(13):
            e50 += E5[j] * K[j, 0]
            e51 += E5[j] * K[j, 1]
            e30 += E3[j] * K[j, 0]
            e31 += E3[j] * K[j, 1]
        sc0 = atol0 + rtol * max(abs(y0), abs(n0))
        sc1 = atol1 + rtol * max(abs(y1), abs(n1))
        err5 = (e50 / sc0) ** 2 + (e51 / sc1) ** 2
        err3 = (e30 / sc0) ** 2 + (e31 / sc1) ** 2
        err = 0.0
        if not (err5 == 0.0 and err3 == 0.0):  # NaN goes this way too
            err = h * err5 / math.sqrt((err5 + 0.01 * err3) * 2.0)
        if not err <= 1.0:  # also rejects a NaN error (overflow in a far-off stage)
            h *= max(MIN_FACTOR, SAFETY * err ** (-1.0 / 8.0)) if err > 1.0 else MIN_FACTOR
            rejected = True
            to_end = False  # a shorter step cannot end at the separation: locate it again
            continue
        nsteps += 1
        # --- dense output (3 extra stages) ---
        _stages(K, A, 13, 16, y0, y1, h, ramp, clamped, par)
        nfev += 3
        for q in range(2):
            yq_old = y0 if q == 0 else y1
            yq_new = n0 if q == 0 else n1
            dy = yq_new - yq_old
            fo = f0 if q == 0 else f1
            coef[0, q] = dy
            coef[1, q] = h * fo - dy
            coef[2, q] = 2.0 * dy - h * (K[12, q] + fo)
            for i in range(4):
                acc = 0.0
                for j in range(16):
                    acc += D[i, j] * K[j, q]
                coef[3 + i, q] = h * acc
        # --- watched functions at both ends and 3 interior points ---
        direction[W_FULL] = 1.0 if ramp else -1.0
        direction[W_CLAMP] = 1.0 if clamped else -1.0
        direction[W_SEP] = -1.0
        direction[W_REST] = -1.0
        direction[W_UMAX] = -1.0
        direction[W_PEAK] = -1.0
        active[W_FULL] = True
        active[W_CLAMP] = clamp_law
        active[W_SEP] = not to_end
        active[W_REST] = par[P_EREST] > 0.0
        active[W_UMAX] = True
        active[W_PEAK] = not clamped
        force_a = watch_all(y0, y1, ramp, clamped, par, ga)
        force_b = watch_all(n0, n1, ramp, clamped, par, gb)
        for q in range(3):
            dl, uq = dense_eval(INTERIOR[q], y0, y1, coef)
            watch_all(dl, uq, ramp, clamped, par, buf)
            for w in range(N_WATCH):
                gi[q, w] = buf[w]
        if fresh_w >= 0:
            ga[fresh_w] = -direction[fresh_w]
            for q in range(3):
                gi[q, fresh_w] /= INTERIOR[q]
        xtol = 2.0 * EPS * (abs(tau) + h) / h
        # earliest kink (terminal) crossing in the step
        x_sw = 2.0
        w_sw = -1
        for w in range(4):
            if not active[w]:
                continue
            xa, va = 0.0, ga[w]
            for q in range(4):
                xb = INTERIOR[q] if q < 3 else 1.0
                vb = gi[q, w] if q < 3 else gb[w]
                if xa >= x_sw:
                    break
                if crosses(va, vb, direction[w]):
                    xr = find_root(w, xa, va, xb, vb, fresh_w == w, y0, y1, coef, ramp, clamped,
                               par, buf, xtol)  # fmt: skip
                    if xr < x_sw:
                        x_sw, w_sw = xr, w
                    break
                xa, va = xb, vb
        if w_sw == W_SEP and x_sw * h > 64.0 * EPS * max(abs(tau), h0):
            # Beyond delta = 0 the force is 0: the step straddles a kink, so rather than trust
            # its dense output, redo it to end exactly at the located separation (unless that
            # is closer than the time resolution: then it ends at the root below).
            h *= x_sw
            to_end = True
            continue
        x_end = min(x_sw, 1.0)
        # maxima of penetration and force before it (no restart)
        for w in (W_UMAX, W_PEAK):
            if not active[w]:
                continue
            xa, va = 0.0, ga[w]
            for q in range(4):
                xb = INTERIOR[q] if q < 3 else 1.0
                vb = gi[q, w] if q < 3 else gb[w]
                if xa >= x_end:
                    break
                if crosses(va, vb, -1.0):
                    xr = find_root(w, xa, va, xb, vb, False, y0, y1, coef, ramp, clamped, par,
                               buf, xtol)  # fmt: skip
                    if xr <= x_end:
                        dl, uq = dense_eval(xr, y0, y1, coef)
                        fr = watch_all(dl, uq, ramp, clamped, par, buf)
                        if w == W_UMAX:
                            pen = max(pen, dl)
                        elif fr > peak:
                            peak, tau_peak = fr, tau + xr * h
                xa, va = xb, vb
        if force_a > peak:
            peak, tau_peak = force_a, tau
        pen = max(pen, y0)
        # store the piece
        if npc >= p_tau.shape[0] or nev >= ev_tau.shape[0]:
            status = ST_BUFFER_FULL
            break
        p_tau[npc] = tau
        p_h[npc] = h
        p_y[npc, 0] = y0
        p_y[npc, 1] = y1
        for i in range(7):
            p_coef[npc, i, 0] = coef[i, 0]
            p_coef[npc, i, 1] = coef[i, 1]
        npc += 1
        factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err ** (-1.0 / 8.0))
        if rejected:
            factor = min(1.0, factor)
        rejected = False
        h_next = min(h * factor, h_max)
        if w_sw < 0:
            if force_b > peak:
                peak, tau_peak = force_b, tau + h
            pen = max(pen, n0)
            if to_end:
                tau += h
                ev_tau[nev] = tau
                ev_kind[nev] = EV_END
                nev += 1
                v_out = -n1
                status = ST_SEPARATED
                break
            tau = tau_max if last else tau + h
            y0, y1 = n0, n1
            f0, f1 = K[12, 0], K[12, 1]
            fresh_w = -1
            h = h_next
            continue
        # --- a kink: restart there in the new region ---
        tau_ev = tau + x_sw * h
        d_ev, u_ev = dense_eval(x_sw, y0, y1, coef)
        f_ev = watch_all(d_ev, u_ev, ramp, clamped, par, buf)
        if f_ev > peak:
            peak, tau_peak = f_ev, tau_ev
        pen = max(pen, d_ev)
        tau = tau_ev
        if w_sw == W_SEP or (d_ev <= 0.0 and u_ev < 0.0):
            # (a kink this close to the separation that the restart state is already out)
            ev_tau[nev] = tau_ev
            ev_kind[nev] = EV_END
            nev += 1
            v_out = -u_ev
            status = ST_SEPARATED
            break
        if w_sw == W_REST:
            status = ST_REST
            v_out = 0.0
            break
        if w_sw == W_FULL:
            d_ev = par[P_D]
            ramp = not ramp
            ev_kind[nev] = EV_FULL
        else:
            clamped = not clamped
            ev_kind[nev] = EV_CLAMP_ON if clamped else EV_CLAMP_OFF
        ev_tau[nev] = tau_ev
        nev += 1
        y0, y1 = d_ev, u_ev
        f0, f1 = y1, accel(y0, y1, ramp, clamped, par)
        nfev += 1
        fresh_w = w_sw
        to_end = False
        h = h_next
    res[0] = tau
    res[1] = v_out
    res[2] = peak
    res[3] = tau_peak
    res[4] = pen
    ires[0] = status
    ires[1] = npc
    ires[2] = nev
    ires[3] = nfev
    ires[4] = nsteps
    ires[5] = attempts
