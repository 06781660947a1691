"""One step of the coupled ball / modal-plate system, with the contact forces solved implicitly.

Over a step of length tau the contact forces are linear in time (first-order hold). Each mode is
propagated exactly for that force (``propagator``), each ball exactly (cubic in time). The
forces at the step's end solve, by Newton's method on the few active contacts,

    F_j = IMPACT(delta_j, delta_dot_j),   delta_j = R_j - z_j + w_j - C_j F_j,

(the law and its partial derivatives: ``tailbeam.physics.impact.force_partials``)

with w_j = sum_i phi_ji q_i the plate under ball j (two-way coupling) and C_j the residual
compliance of the truncated modes (quasi-static, in series with the contact; its rate term uses
a variable-step BDF2 derivative of F, so the scheme stays 2nd order). delta_j is linear in the
unknown end forces, so each Newton iteration costs O(na^2) after one O(na^2 n) set-up. Where
plain Newton does not converge, ``contact_solve.solve_forces`` solves the same equations
(damped Newton, then bracketed scalar solves); the kernel halves the step if that fails too.
"""

import numpy as np

from tailbeam.jit import njit
from tailbeam.physics.impact import force_partials
from tailbeam.solvers.coupled.contact_solve import solve_forces
from tailbeam.solvers.numerics.jit import helper_njit
from tailbeam.solvers.plate_loads.propagator import A1, B1, advance, coefficients

FLIGHT, CONTACT, CLAMPED, REST, OFF = 0, 1, 2, 3, 4


@helper_njit
def _modal_loads(phi, mass, F, mode, g, f0m, f1m):
    """Modal forces (N) at the step's start f0m (the contact forces F) and end f1m (the
    resting balls' weights only: the contact end forces are still unknown)."""
    n = phi.shape[1]
    for i in range(n):
        f0m[i] = 0.0
        f1m[i] = 0.0
    for b in range(phi.shape[0]):
        if F[b] != 0.0:
            for i in range(n):
                f0m[i] -= phi[b, i] * F[b]
        if mode[b] == REST:
            w = mass[b] * g
            for i in range(n):
                f1m[i] -= phi[b, i] * w


@njit(cache=True, inline="always")
def _touching(mode):
    """Indices of the balls in contact (CONTACT or CLAMPED) and their number."""
    idx = np.empty(mode.shape[0], dtype=np.int64)
    na = 0
    for b in range(mode.shape[0]):
        if mode[b] == CONTACT or mode[b] == CLAMPED:
            idx[na] = b
            na += 1
    return idx, na


@njit(cache=True, inline="always")
def _contact_system(idx, na, tau, phi, cres, mass, radius, z, vz, F, hist, coef, q1, qd1, g):
    """The penetrations (m) and rates (m/s) at the step's end, linear in the unknown end
    forces x (N) of the touching balls: delta = dfree + S x, delta_dot = vfree + Sv x (the free
    modes q1, qd1 at the end given). Returns (dfree, vfree, S, Sv)."""
    n = phi.shape[1]
    dfree, vfree = np.empty(na), np.empty(na)
    S, Sv = np.empty((na, na)), np.empty((na, na))
    for jj in range(na):
        j = idx[jj]
        zf = z[j] + vz[j] * tau - 0.5 * g * tau * tau + F[j] * tau * tau / (3.0 * mass[j])
        vf = vz[j] - g * tau + F[j] * tau / (2.0 * mass[j])
        dfree[jj] = radius[j] - zf + np.dot(phi[j], q1)
        beta = tau / (tau + hist[1, j]) if hist[1, j] > 0.0 else 0.0
        vfree[jj] = -vf + np.dot(phi[j], qd1) + cres[j] * ((1.0 + beta) * F[j] / tau)
        vfree[jj] += cres[j] * beta * hist[0, j]
        for ll in range(na):
            lb = idx[ll]
            gx = 0.0
            gv = 0.0
            for i in range(n):
                pp = phi[j, i] * phi[lb, i]
                gx += pp * coef[A1, i]
                gv += pp * coef[B1, i]
            S[jj, ll] = -gx
            Sv[jj, ll] = -gv
        S[jj, jj] -= tau * tau / (6.0 * mass[j]) + cres[j]
        beta = tau / (tau + hist[1, j]) if hist[1, j] > 0.0 else 0.0
        Sv[jj, jj] -= tau / (2.0 * mass[j]) + cres[j] * (1.0 + beta) / tau
    return dfree, vfree, S, Sv


@njit(cache=True, inline="always")
def _newton(idx, na, dfree, vfree, S, Sv, x, k, e, c, d, clampf):
    """Solve x = IMPACT(dfree + S x, vfree + Sv x) for the end forces x (N; in: the guess)
    by Newton's method; returns False if 60 iterations do not reach 1e-13 relative."""
    J = np.empty((na, na))
    r = np.empty(na)
    for _it in range(60):
        big = 1.0
        for jj in range(na):
            j = idx[jj]
            dl = dfree[jj]
            dv = vfree[jj]
            for ll in range(na):
                dl += S[jj, ll] * x[ll]
                dv += Sv[jj, ll] * x[ll]
            f, fd, fv, _raw = force_partials(dl, dv, k[j], e[j], c[j], d[j], clampf[j])
            r[jj] = x[jj] - f
            big = max(big, abs(f))
            for ll in range(na):
                J[jj, ll] = -(fd * S[jj, ll] + fv * Sv[jj, ll])
            J[jj, jj] += 1.0
        dx = np.linalg.solve(J, r)
        x -= dx
        if np.max(np.abs(dx)) <= 1e-13 * big:
            return True
    return False


@helper_njit
def _ball_ends(tau, phi, cres, mass, radius, k, e, c, d, z, vz, F, mode, hist, q1, qd1, z1, vz1,
               F1, aux, g):  # fmt: skip
    """Balls at the step's end (heights z1 m, speeds vz1 m/s, cubic in time under the linear
    force; resting balls' weights into F1 N) and the event quantities aux rows: delta (m),
    delta_dot (m/s), raw force (N), gap' (m/s)."""
    for b in range(phi.shape[0]):
        if mode[b] == REST:
            z1[b] = z[b]
            vz1[b] = 0.0
            F1[b] = mass[b] * g
        else:
            if mode[b] == FLIGHT:
                F1[b] = 0.0
            fb = F[b]
            z1[b] = z[b] + vz[b] * tau - 0.5 * g * tau * tau
            z1[b] += (fb * tau * tau / 3.0 + F1[b] * tau * tau / 6.0) / mass[b]
            vz1[b] = vz[b] - g * tau + (fb + F1[b]) * tau / (2.0 * mass[b])
        w = np.dot(phi[b], q1)
        wd = np.dot(phi[b], qd1)
        aux[0, b] = radius[b] - z1[b] + w - cres[b] * F1[b]
        # dF/dt at the step's end: 2nd-order backward difference (BDF2, variable step)
        beta = tau / (tau + hist[1, b]) if hist[1, b] > 0.0 else 0.0
        fdot = (1.0 + beta) * (F1[b] - F[b]) / tau - beta * hist[0, b]
        aux[1, b] = -vz1[b] + wd - cres[b] * fdot
        _f, _fd, _fv, raw = force_partials(aux[0, b], aux[1, b], k[b], e[b], c[b], d[b], False)
        aux[2, b] = raw if aux[0, b] > 0.0 else 0.0
        aux[3, b] = vz1[b] - wd  # rate of the gap (= -delta) of a flying ball


@njit(cache=True)
def solve_step(tau, ctx, st, out, g):
    """Advance ``st`` by ``tau`` into ``out`` (all arrays); returns False if Newton failed."""
    omega, zeta, phi, cres, mass, radius, k, e, c, d, clampf = ctx
    q, qd, z, vz, F, mode, _deep, _cur, hist = st
    q1, qd1, z1, vz1, F1, aux, coef, f0m, f1m = out
    n = phi.shape[1]
    if coef[0, n] != tau:  # the last column remembers the tau of the table (contact steps repeat)
        coefficients(omega, zeta, tau, coef)
        coef[0, n] = tau
    _modal_loads(phi, mass, F, mode, g, f0m, f1m)
    advance(coef, q, qd, f0m, f1m, q1, qd1)  # free part (contact end forces still zero)
    idx, na = _touching(mode)
    if na > 0:
        dfree, vfree, S, Sv = _contact_system(idx, na, tau, phi, cres, mass, radius, z, vz, F,
                                              hist, coef, q1, qd1, g)  # fmt: skip
        x = np.empty(na)
        for jj in range(na):
            x[jj] = F1[idx[jj]]  # caller's guess
        if not _newton(idx, na, dfree, vfree, S, Sv, x, k, e, c, d, clampf):
            for jj in range(na):
                x[jj] = F1[idx[jj]]  # the fallback starts again from the guess
            if not solve_forces(idx, na, dfree, vfree, S, Sv, x, k, e, c, d, clampf):
                return False
        for jj in range(na):
            F1[idx[jj]] = x[jj]
            f1m -= phi[idx[jj]] * x[jj]
        advance(coef, q, qd, f0m, f1m, q1, qd1)
    _ball_ends(tau, phi, cres, mass, radius, k, e, c, d, z, vz, F, mode, hist, q1, qd1, z1, vz1,
               F1, aux, g)  # fmt: skip
    return True
