"""Exact propagation of damped modal oscillators under a force that is linear in time.

Each mode obeys q'' + 2 zeta omega q' + omega^2 q = f(t) (unit modal mass; q in m sqrt(kg),
f in N/sqrt(kg)). Over a step of length tau with f(s) = f0 (1 - s/tau) + f1 s/tau the solution
is exact and linear in the data:

    q(tau)  = p11 q + p12 q' + a0 f0 + a1 f1
    q'(tau) = p21 q + p22 q' + b0 f0 + b1 f1

so any mode frequency and any tau are unconditionally stable (|eigenvalues| <= 1). Under-,
critically and over-damped modes share one formula (c = cos / 1 / cosh, s = sin(mu t)/mu ...).
For small omega tau the closed forms cancel catastrophically; a Taylor series of the ODE is used
there instead (same result to rounding).
"""

import math

import numpy as np

from tailbeam.jit import njit

# Rows of the coefficient table produced by ``coefficients``.
P11, P12, P21, P22, A0, A1, B0, B1 = range(8)
_SERIES_LIMIT = 0.05  # use the Taylor series when max(omega, zeta omega) tau is below this
_SERIES_TERMS = 16


@njit(cache=True)
def _series(omega, zeta, tau, out, i):
    """Taylor coefficients of the responses to x0 = 1, v0 = 1, unit constant and unit ramp force."""
    c2 = 2.0 * zeta * omega
    w2 = omega * omega
    # four responses: (x0=1), (v0=1), (f=1), (f = s / tau); x = sum x_k s^k
    for case in range(4):
        xk = np.zeros(_SERIES_TERMS + 2)
        if case == 0:
            xk[0] = 1.0
        elif case == 1:
            xk[1] = 1.0
        for k in range(_SERIES_TERMS):
            fk = 0.0
            if case == 2 and k == 0:
                fk = 1.0
            elif case == 3 and k == 1:
                fk = 1.0 / tau
            xk[k + 2] = (fk - c2 * (k + 1) * xk[k + 1] - w2 * xk[k]) / ((k + 2) * (k + 1))
        x = 0.0
        v = 0.0
        p = 1.0
        for k in range(_SERIES_TERMS + 2):
            x += xk[k] * p
            if k + 1 < _SERIES_TERMS + 2:
                v += (k + 1) * xk[k + 1] * p
            p *= tau
        if case == 0:
            out[P11, i] = x
            out[P21, i] = v
        elif case == 1:
            out[P12, i] = x
            out[P22, i] = v
        elif case == 2:
            out[A0, i] = x
            out[B0, i] = v
        else:
            out[A1, i] = x
            out[B1, i] = v
    # the constant-force response is the sum of the f0 and f1 responses
    out[A0, i] -= out[A1, i]
    out[B0, i] -= out[B1, i]


@njit(cache=True)
def coefficients(omega, zeta, tau, out):
    """Fill ``out`` (8, n) with the step coefficients for a step of ``tau`` seconds."""
    n = omega.shape[0]
    for i in range(n):
        w = omega[i]
        z = zeta[i]
        if max(w, z * w) * tau < _SERIES_LIMIT:
            _series(w, z, tau, out, i)
            continue
        e = math.exp(-z * w * tau)
        if z < 1.0:
            mu = w * math.sqrt(1.0 - z * z)
            c = math.cos(mu * tau)
            s = math.sin(mu * tau) / mu
        elif z > 1.0:
            mu = w * math.sqrt(z * z - 1.0)
            # cosh/sinh times e without overflow: e*cosh = (exp(-(zw-mu)t) + exp(-(zw+mu)t))/2
            ep = math.exp(-(z * w - mu) * tau)
            em = math.exp(-(z * w + mu) * tau)
            c = 0.5 * (ep + em) / e if e > 0.0 else 0.0
            s = 0.5 * (ep - em) / mu / e if e > 0.0 else 0.0
        else:
            c = 1.0
            s = tau
        p11 = e * (c + z * w * s)
        p12 = e * s
        p21 = -e * w * w * s
        p22 = e * (c - z * w * s)
        w2 = w * w
        xc = (1.0 - p11) / w2
        vc = -p21 / w2
        c1 = 1.0 / (tau * w2)
        c0 = -2.0 * z / (tau * w2 * w)
        xr = c0 * (1.0 - p11) + c1 * (tau - p12)
        vr = -p21 * c0 + c1 * (1.0 - p22)
        out[P11, i] = p11
        out[P12, i] = p12
        out[P21, i] = p21
        out[P22, i] = p22
        out[A0, i] = xc - xr
        out[A1, i] = xr
        out[B0, i] = vc - vr
        out[B1, i] = vr


@njit(cache=True)
def advance(coef, q, qd, f0, f1, q_out, qd_out):
    """One exact step with the coefficient table ``coef`` (f0, f1: modal forces at the ends)."""
    for i in range(q.shape[0]):
        q_out[i] = coef[P11, i] * q[i] + coef[P12, i] * qd[i] + coef[A0, i] * f0[i]
        q_out[i] += coef[A1, i] * f1[i]
        qd_out[i] = coef[P21, i] * q[i] + coef[P22, i] * qd[i] + coef[B0, i] * f0[i]
        qd_out[i] += coef[B1, i] * f1[i]


@njit(cache=True)
def _step_inplace(coef, q, qd, f0, f1, loaded):
    """advance() in place; skips the force terms when no load acts (free flight)."""
    for i in range(q.shape[0]):
        qi = q[i]
        vi = qd[i]
        nq = coef[P11, i] * qi + coef[P12, i] * vi
        nv = coef[P21, i] * qi + coef[P22, i] * vi
        if loaded:
            nq += coef[A0, i] * f0[i] + coef[A1, i] * f1[i]
            nv += coef[B0, i] * f0[i] + coef[B1, i] * f1[i]
        q[i] = nq
        qd[i] = nv


@njit(cache=True)
def replay(
    omega, zeta, t_nodes, forces, seg_phase, phis, times, q_out, qd_out, qdd_out, points, modal
):
    """Modal states at sorted ``times`` from the piecewise-linear force history.

    t_nodes (K,) sorted node times, forces (K, nb) ball forces at the nodes (N), seg_phase (K,)
    index into phis (P, nb, n) of the contact points in force between node k and k+1. The plate
    starts at rest at t_nodes[0]. Outputs (n, len(times)): q, q' and q'' (exact, closed form) if
    ``modal``; else the deflection, velocity and acceleration at the points whose mode shapes
    are ``points`` (p, n): (p, len(times)).
    """
    n = omega.shape[0]
    coef = np.empty((8, n))
    q = np.zeros(n)
    qd = np.zeros(n)
    f0 = np.empty(n)
    f1 = np.empty(n)
    c2 = 2.0 * zeta * omega
    w2 = omega * omega
    K = t_nodes.shape[0]
    k = 0
    t = t_nodes[0]
    last_tau = -1.0
    # Reuse the step coefficients when tau repeats to 1e-10 (uniform output grids: their
    # differences carry rounding noise ~ eps t / dt). Worst case this shifts the times by
    # 1e-10 of the elapsed time (a phase of 6e-6 rad at 10 kHz after 1 s).
    same = 1e-10
    loaded = False
    for j in range(times.shape[0]):
        tj = times[j]
        # advance node by node up to the node interval holding tj
        while k + 1 < K and t_nodes[k + 1] <= tj:
            tau = t_nodes[k + 1] - t
            if tau > 0.0:
                loaded = _seg_forces(phis, seg_phase, k, forces, t_nodes, t, t_nodes[k + 1], f0, f1)
                last_tau = _step_reusing(omega, zeta, tau, last_tau, same, coef, q, qd, f0, f1,
                                         loaded)  # fmt: skip
            t = t_nodes[k + 1]
            k += 1
        tau = tj - t
        if k + 1 < K:
            loaded = _seg_forces(phis, seg_phase, k, forces, t_nodes, t, tj, f0, f1)
        else:
            loaded = _seg_forces(phis, seg_phase, k, forces, t_nodes, t, t, f0, f1)
            f1[:] = f0
        if tau > 0.0:
            last_tau = _step_reusing(omega, zeta, tau, last_tau, same, coef, q, qd, f0, f1, loaded)
            t = tj
        _write_output(j, q, qd, f1, loaded, c2, w2, modal, points, q_out, qd_out, qdd_out)
    return 0


@njit(cache=True, inline="always")
def _step_reusing(omega, zeta, tau, last_tau, same, coef, q, qd, f0, f1, loaded):
    """Step (q, q') by tau (s) under the linear modal force f0 -> f1, recomputing the
    coefficients only if tau differs from last_tau by more than ``same`` relative; returns
    the tau of the coefficients now in coef."""
    if abs(tau - last_tau) > same * tau:
        coefficients(omega, zeta, tau, coef)
        last_tau = tau
    _step_inplace(coef, q, qd, f0, f1, loaded)
    return last_tau


@njit(cache=True, inline="always")
def _write_output(j, q, qd, f1, loaded, c2, w2, modal, points, q_out, qd_out, qdd_out):
    """Column j of the outputs: q, q', q'' if modal, else the deflection (m), velocity (m/s)
    and acceleration (m/s^2) at the points (mode shapes ``points`` (p, n))."""
    n = q.shape[0]
    if modal:
        for i in range(n):
            q_out[i, j] = q[i]
            qd_out[i, j] = qd[i]
            qdd_out[i, j] = (f1[i] if loaded else 0.0) - c2[i] * qd[i] - w2[i] * q[i]
        return
    for p in range(points.shape[0]):  # only the plate at the points: no (n, len(times)) arrays
        w = 0.0
        v = 0.0
        a = 0.0
        for i in range(n):
            ph = points[p, i]
            w += ph * q[i]
            v += ph * qd[i]
            acc = -c2[i] * qd[i] - w2[i] * q[i]
            if loaded:
                acc += f1[i]
            a += ph * acc
        q_out[p, j] = w
        qd_out[p, j] = v
        qdd_out[p, j] = a


@njit(cache=True)
def _seg_forces(phis, seg_phase, k, forces, t_nodes, ta, tb, f0, f1):
    """Modal forces at times ta, tb inside node interval k (linear in time between nodes);
    returns whether any load acts (else f0, f1 are left untouched)."""
    K = t_nodes.shape[0]
    loaded = False
    for b in range(forces.shape[1]):
        if forces[k, b] != 0.0 or (k + 1 < K and forces[k + 1, b] != 0.0):
            loaded = True
    if not loaded:
        return False
    ph = phis[seg_phase[k]]
    n = f0.shape[0]
    f0[:] = 0.0
    f1[:] = 0.0
    span = t_nodes[k + 1] - t_nodes[k] if k + 1 < K else 0.0
    for b in range(forces.shape[1]):
        Fa = forces[k, b]
        Fb = forces[k + 1, b] if k + 1 < K else Fa
        if span > 0.0:
            ua = Fa + (Fb - Fa) * (ta - t_nodes[k]) / span
            ub = Fa + (Fb - Fa) * (tb - t_nodes[k]) / span
        else:
            ua = Fa
            ub = Fa
        if ua != 0.0 or ub != 0.0:
            for i in range(n):
                f0[i] -= ph[b, i] * ua
                f1[i] -= ph[b, i] * ub
    return True
