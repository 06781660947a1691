"""The compiled stepping kernel of the two-way coupled ball / modal-plate model.

State: modal coordinates q, q' (n,), ball heights z and vertical speeds vz (nb,), the contact
forces F (nb,) at the current time and each ball's mode (flight, contact, clamped, rest).

One step is ``tailbeam.solvers.coupled.step.solve_step`` (implicit contact forces, exact modes).

Events (contact start / end, STEP kink delta = d, clamp on / off) are located on the step
function itself (Illinois root finding on tau): the kernel stops at the first event so the
driver can record it and update the modes of the balls. Contact starts can never be missed:
a step only goes on when the gap of every flying ball is certified positive on the whole step
by two bounds (|gap'| <= L, and gap'' >= -(g + A) with A a bound on the plate acceleration
from the modal energies), else the step is bisected. In free flight the step is the certified
horizon itself, so flights take a few dozen exact jumps, not contact-size steps.

A step whose contact forces are not solved (``step.solve_step``, with its fallback
``contact_solve.solve_forces``), there or while locating its events, is halved and taken again
(at most ``MAX_HALVINGS`` times): the smaller the step, the more the contacts decouple.
"""

import math

import numpy as np

from tailbeam.jit import njit
from tailbeam.results.records import EventCode
from tailbeam.solvers.coupled.step import CLAMPED, CONTACT, FLIGHT, solve_step
from tailbeam.solvers.numerics.jit import helper_njit

ST_STOP, ST_EVENT, ST_FULL, ST_FAIL, ST_STEPS = range(5)
MAX_HALVINGS = 30  # of a step whose contact forces are not solved (tau / 1e9)


@njit(cache=True)
def _bounds(ctx, st, f0m, f1m, tau, g):
    """Per-ball bounds over a step of tau: L >= |gap'| and A >= |plate acceleration|."""
    omega, zeta, phi, _c, _m, _r, _k, _e, _cc, _d, _cl = ctx
    q, qd, _z, vz, _F, _mode, _deep, _cur, _hist = st
    nb, n = phi.shape
    amp = np.empty(n)
    acc = np.empty(n)
    for i in range(n):
        w2 = omega[i] ** 2
        df = abs(f1m[i] - f0m[i])
        y = q[i] - f0m[i] / w2  # about the static position under the starting force
        a = math.sqrt(qd[i] ** 2 + w2 * y * y) + df * tau
        amp[i] = a
        acc[i] = df + omega[i] * (1.0 + 2.0 * zeta[i]) * a
    L = np.empty(nb)
    A = np.empty(nb)
    for b in range(nb):
        L[b] = abs(vz[b]) + g * tau + np.dot(np.abs(phi[b]), amp)
        A[b] = np.dot(np.abs(phi[b]), acc)
    return L, A


@njit(cache=True)
def _event_value(kind, b, aux, d):
    if kind == EventCode.CONTACT_START:
        return -aux[0, b]  # gap
    if kind == EventCode.CONTACT_END:
        return aux[0, b]
    if kind == EventCode.FULL_DAMPING:
        return aux[0, b] - d[b]
    return aux[2, b]


def _alloc(nb, n):
    return (
        np.empty(n),
        np.empty(n),
        np.empty(nb),
        np.empty(nb),
        np.empty(nb),
        np.empty((4, nb)),
        np.full((8, n + 1), -1.0),  # coefficient table + its tau
        np.empty(n),
        np.empty(n),
    )


_alloc = njit(cache=True)(_alloc)


@njit(cache=True)
def _copy_out(src, dst):
    dst[0][:] = src[0]
    dst[1][:] = src[1]
    dst[2][:] = src[2]
    dst[3][:] = src[3]
    dst[4][:] = src[4]
    dst[5][:, :] = src[5]
    dst[6][:, :] = src[6]
    dst[7][:] = src[7]
    dst[8][:] = src[8]


@njit(cache=True)
def _locate(kind, b, lo, flo, hi, fhi, ctx, st, out, g, d, guess):
    """Shrink [lo, hi] (f(lo) > 0 > f(hi) up to sign) around the event; returns hi.

    ``out`` holds the solution at the returned hi (the side where the event has happened)."""
    F1 = out[4]
    sgn = 1.0 if flo > 0.0 else -1.0
    flo *= sgn
    fhi *= sgn
    side = 0
    for _it in range(200):
        if hi - lo <= 1e-15 + 1e-13 * hi:
            break
        tm = (lo * fhi - hi * flo) / (fhi - flo)
        if not (lo < tm < hi):
            tm = 0.5 * (lo + hi)
        F1[:] = guess
        if not solve_step(tm, ctx, st, out, g):
            return -1.0
        fm = sgn * _event_value(kind, b, out[5], d)
        if fm >= 0.0:  # not yet happened (a zero stays on this side: hi is strictly past)
            lo, flo = tm, fm
            if side == 1:
                fhi *= 0.5
            side = 1
        else:
            hi, fhi = tm, fm
            if side == -1:
                flo *= 0.5
            side = -1
    F1[:] = guess
    if not solve_step(hi, ctx, st, out, g):
        return -1.0
    return hi


@njit(cache=True)
def _certify(b, tau, ctx, st, out, g, L, A, gap0, rate0, guess):
    """Earliest (lo, hi, f(lo), f(hi)) bracket of a contact start of flying ball b in (0, tau],
    or lo = -1 if the gap is certified positive on the whole step (bisection with bounds)."""
    stack = np.empty((64, 4))
    stack[0, 0] = 0.0
    stack[0, 1] = tau
    stack[0, 2] = gap0
    stack[0, 3] = rate0
    top = 1
    count = 0
    while top > 0 and count < 200:
        count += 1
        top -= 1
        a, bb, ga, ra = stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3]
        out[4][:] = guess
        if not solve_step(bb, ctx, st, out, g):
            return -2.0, 0.0, 0.0, 0.0
        gb = -out[5][0, b]
        if gb <= 0.0:
            return a, bb, ga, gb
        span = bb - a
        if ga + gb >= L[b] * span:
            continue
        if ga >= 0.0 and ga + ra * span - 0.5 * (g + A[b]) * span * span > 0.0:
            continue
        if top + 2 >= 64 or span < 1e-15:
            continue  # a graze below any resolvable depth: no contact
        mid = 0.5 * (a + bb)
        out[4][:] = guess
        if not solve_step(mid, ctx, st, out, g):
            return -2.0, 0.0, 0.0, 0.0
        gm = -out[5][0, b]
        rm = out[5][3, b]
        # push the later half first so the earlier half is examined first
        stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3] = mid, bb, gm, rm
        top += 1
        stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3] = a, mid, ga, ra
        top += 1
    return -1.0, 0.0, 0.0, 0.0


@helper_njit
def _pending_event(F, mode, deep, cur, d, clampf):
    """Apply the first event that happened at the same instant as the one that ended the
    previous run (found in the step-end quantities ``cur``): (kind, ball), or EventCode.NONE."""
    for b in range(mode.shape[0]):
        touching = mode[b] == CONTACT or mode[b] == CLAMPED
        if mode[b] == FLIGHT and cur[0, b] >= 0.0:
            mode[b] = CONTACT
            deep[b] = cur[0, b] > d[b]
            return EventCode.CONTACT_START, b
        elif touching and cur[0, b] < 0.0:
            mode[b] = FLIGHT
            F[b] = 0.0
            deep[b] = False
            return EventCode.CONTACT_END, b
        elif touching and (cur[0, b] > d[b]) != deep[b]:
            deep[b] = not deep[b]
            return EventCode.FULL_DAMPING, b
        elif clampf[b] and mode[b] == CONTACT and cur[2, b] < 0.0:
            mode[b] = CLAMPED
            return EventCode.CLAMP_ON, b
        elif clampf[b] and mode[b] == CLAMPED and cur[2, b] > 0.0:
            mode[b] = CONTACT
            return EventCode.CLAMP_OFF, b
    return EventCode.NONE, -1


@njit(cache=True)
def _flight_step(ctx, st, remaining, h, g, fm):
    """Step (s) with no ball in contact: the certified horizon before any flying ball can
    touch (from the bounds of ``_bounds`` on the gap), at least its h, at most remaining."""
    phi = ctx[2]
    _q, _qd, _z, _vz, F, mode, _deep, cur, _hist = st
    nb = phi.shape[0]
    fm[:] = 0.0
    for b in range(nb):
        if F[b] != 0.0:
            fm -= phi[b] * F[b]
    L, A = _bounds(ctx, st, fm, fm, 0.0, g)
    tau = remaining
    for b in range(nb):
        if mode[b] != FLIGHT:
            continue
        gap = -cur[0, b]
        rate = cur[3, b]
        V = L[b]
        t1 = 2.0 * gap / (V + math.sqrt(V * V + 4.0 * g * gap))
        at = g + A[b]
        root = math.sqrt(max(rate * rate + 2.0 * at * gap, 0.0))
        if rate < 0.0:
            t2 = 2.0 * gap / (root - rate)  # stable form while approaching
        elif at > 0.0:
            t2 = (rate + root) / at
        else:
            t2 = remaining
        tau = min(tau, max(max(t1, t2) * (1.0 - 1e-9), h[b]))
    return tau


@helper_njit
def _contact_step(mode, remaining, h):
    """(whether a ball is in contact, the smallest contact step h[b] (s) of those balls, at
    most remaining)."""
    in_contact = False
    for b in range(mode.shape[0]):
        if mode[b] == CONTACT or mode[b] == CLAMPED:
            in_contact = True
    tau = remaining
    if in_contact:
        for b in range(mode.shape[0]):
            if mode[b] == CONTACT or mode[b] == CLAMPED:
                tau = min(tau, h[b])
    return in_contact, tau


@helper_njit
def _contact_kinds(b, mode, deep, aux, d, clampf, kinds):
    """The events of touching ball b whose function changed sign over the step (step-end
    quantities aux) into kinds; returns their number (0 if b is not touching)."""
    nk = 0
    if not (mode[b] == CONTACT or mode[b] == CLAMPED):
        return nk
    if aux[0, b] < 0.0:
        kinds[nk] = EventCode.CONTACT_END
        nk += 1
    if (aux[0, b] > d[b]) != deep[b]:
        kinds[nk] = EventCode.FULL_DAMPING
        nk += 1
    if clampf[b] and mode[b] == CONTACT and aux[2, b] < 0.0:
        kinds[nk] = EventCode.CLAMP_ON
        nk += 1
    if clampf[b] and mode[b] == CLAMPED and aux[2, b] > 0.0:
        kinds[nk] = EventCode.CLAMP_OFF
        nk += 1
    return nk


@njit(cache=True)
def _keep(hit, kd, b, best, kind_best, b_best, out2, out_best):
    """Keep event kd of ball b at hit (s) (solution in out2) if it is the earliest so far."""
    if hit < best or kind_best == EventCode.NONE:
        _copy_out(out2, out_best)
        return hit, kd, b
    return best, kind_best, b_best


@njit(cache=True)
def _ball_events(b, tau, ctx, st, aux, out2, out_best, g, L, A, guess, best, kind_best, b_best,
                 mode, cur, d, kinds, nk):  # fmt: skip
    """Locate the events of ball b in the step of tau (s) (touching: the nk kinds found by
    ``_contact_kinds``; flying: a contact start) and keep the earliest of all (``_keep``);
    returns (ok, best, kind_best, b_best), ok False if a step solve failed."""
    if mode[b] == CONTACT or mode[b] == CLAMPED:
        for kk in range(nk):
            kd = kinds[kk]
            f_lo = _event_value(kd, b, cur, d)
            f_hi = _event_value(kd, b, aux, d)
            if f_lo == 0.0:
                f_lo = -f_hi * 1e-30
            hit = _locate(kd, b, 0.0, f_lo, tau, f_hi, ctx, st, out2, g, d, guess)
            if hit < 0.0:
                return False, best, kind_best, b_best
            best, kind_best, b_best = _keep(hit, kd, b, best, kind_best, b_best, out2, out_best)
    elif mode[b] == FLIGHT:
        lo, hi, flo, fhi = _certify(b, tau, ctx, st, out2, g, L, A, -cur[0, b], cur[3, b], guess)
        if lo == -2.0:
            return False, best, kind_best, b_best
        if lo >= 0.0:
            if flo == 0.0:
                flo = 1e-300
            hit = _locate(EventCode.CONTACT_START, b, lo, flo, hi, fhi, ctx, st, out2, g, d, guess)
            if hit < 0.0:
                return False, best, kind_best, b_best
            best, kind_best, b_best = _keep(hit, EventCode.CONTACT_START, b, best, kind_best,
                                            b_best, out2, out_best)  # fmt: skip
    return True, best, kind_best, b_best


@helper_njit
def _accept(q, qd, z, vz, F, mode, cur, hist, q1, qd1, z1, vz1, F1, aux, tau):
    """Take the step of tau (s) (ending in q1, .., aux) as the new state (q, .., cur), and the
    BDF2 force history hist."""
    for b in range(mode.shape[0]):
        if mode[b] == CONTACT or mode[b] == CLAMPED:
            hist[0, b] = (F1[b] - F[b]) / tau
            hist[1, b] = tau
        else:
            hist[0, b] = 0.0
            hist[1, b] = 0.0
    for i in range(q.shape[0]):
        q[i] = q1[i]
        qd[i] = qd1[i]
    for b in range(z.shape[0]):
        z[b] = z1[b]
        vz[b] = vz1[b]
        F[b] = F1[b]
        for r in range(cur.shape[0]):
            cur[r, b] = aux[r, b]


@helper_njit
def _record(bt, bz, bvz, bF, bd, nbuf, t, z, vz, F, cur):
    """Write node nbuf of the buffers: t (s), heights z (m), speeds vz (m/s), forces F (N),
    penetrations delta (m)."""
    bt[nbuf] = t
    for b in range(z.shape[0]):
        bz[nbuf, b] = z[b]
        bvz[nbuf, b] = vz[b]
        bF[nbuf, b] = F[b]
        bd[nbuf, b] = cur[0, b]


@helper_njit
def _apply_event(kind, b, F, mode, deep, cur, hist, d):
    """Change ball b's mode for the event kind located at the step's end (st accepted)."""
    if kind == EventCode.CONTACT_START:
        mode[b] = CONTACT
        deep[b] = cur[0, b] > d[b]
    elif kind == EventCode.CONTACT_END:
        mode[b] = FLIGHT
        F[b] = 0.0
        deep[b] = False
    elif kind == EventCode.FULL_DAMPING:
        deep[b] = cur[0, b] > d[b]
    elif kind == EventCode.CLAMP_ON:
        mode[b] = CLAMPED
    else:
        mode[b] = CONTACT
    if kind != EventCode.FULL_DAMPING:
        # dF/dt jumps here (the STEP kink keeps it continuous): restart the BDF2 history
        hist[0, b] = 0.0
        hist[1, b] = 0.0


@njit(cache=True)
def run(ctx, st, t, t_stop, h, max_steps, g, bufs, nbuf, evout):
    """Step from t until t_stop, the first event, a full buffer or max_steps.

    Returns (status, t, nbuf, steps). bufs = (t, z, vz, F, delta) node buffers; evout[0:2] =
    (kind, ball) of the event that stopped the run.
    """
    _om, _ze, phi, _cr, _mass, _ra, _k, _e, _c, d, clampf = ctx
    q, qd, z, vz, F, mode, deep, cur, hist = st
    bt, bz, bvz, bF, bd = bufs
    nb, n = phi.shape
    out, out2, out_best = _alloc(nb, n), _alloc(nb, n), _alloc(nb, n)
    q1, qd1, z1, vz1, F1, aux, _coef, f0m, f1m = out
    guess = np.empty(nb)
    fm = np.empty(n)
    kinds = np.zeros(4, dtype=np.int64)  # events of one ball in a step
    evout[0], evout[1] = _pending_event(F, mode, deep, cur, d, clampf)
    if evout[0] != EventCode.NONE:
        return ST_EVENT, t, nbuf, 0
    steps = 0
    while t < t_stop:
        if nbuf >= bt.shape[0]:
            return ST_FULL, t, nbuf, steps
        if steps >= max_steps:
            return ST_STEPS, t, nbuf, steps
        steps += 1
        in_contact, tau = _contact_step(mode, t_stop - t, h)
        if not in_contact:  # the certified flight horizon
            tau = _flight_step(ctx, st, t_stop - t, h, g, fm)
        tau = min(tau, t_stop - t)
        ok = False
        best, kind_best, b_best = tau, EventCode.NONE, -1
        for _halving in range(MAX_HALVINGS + 1):  # a step whose forces are not solved: halve it
            for b in range(nb):
                guess[b] = F[b] + hist[0, b] * tau
                F1[b] = guess[b]
            ok = solve_step(tau, ctx, st, out, g)
            # --- events on this step: keep the earliest
            best, kind_best, b_best = tau, EventCode.NONE, -1
            if ok:
                L, A = _bounds(ctx, st, f0m, f1m, tau, g)
                for b in range(nb):
                    nk = _contact_kinds(b, mode, deep, aux, d, clampf, kinds)
                    if nk == 0 and mode[b] != FLIGHT:
                        continue  # (nothing to locate: no tuples handed over, see numerics.jit)
                    ok, best, kind_best, b_best = _ball_events(b, tau, ctx, st, aux, out2,
                                                               out_best, g, L, A, guess, best,
                                                               kind_best, b_best, mode, cur, d,
                                                               kinds, nk)  # fmt: skip
                    if not ok:
                        break
            if ok:
                break
            tau *= 0.5
        if not ok:
            return ST_FAIL, t, nbuf, steps
        if kind_best != EventCode.NONE:
            # the solution at the located time, exactly as the root finder checked its sign
            tau = best
            _copy_out(out_best, out)
        _accept(q, qd, z, vz, F, mode, cur, hist, q1, qd1, z1, vz1, F1, aux, tau)
        t = t + tau
        _record(bt, bz, bvz, bF, bd, nbuf, t, z, vz, F, cur)
        nbuf += 1
        if kind_best != EventCode.NONE:
            _apply_event(kind_best, b_best, F, mode, deep, cur, hist, d)
            evout[0] = kind_best
            evout[1] = b_best
            return ST_EVENT, t, nbuf, steps
    return ST_STOP, t, nbuf, steps
