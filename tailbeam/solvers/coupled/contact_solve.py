"""The contact forces of one coupled step when plain Newton does not converge.

A step's end forces x (N) of the na touching balls solve

    G(x) = x - IMPACT(dfree + S x, vfree + Sv x) = 0

(``step._contact_system``: -S and -Sv are the step's compliance matrices, symmetric and
positive definite). ``step._newton`` solves it by plain Newton, which converges in a few
iterations on almost every step. It can fail where the law is not smooth (the force's kink at
delta = 0, the end of the damping ramp at delta = d, the clamp) or where its 1e-13 test lies
below what rounding lets the residual reach (a long, light contact of a ball settling on the
plate: delta = R - z + w cancels to ~1e-7 of its terms). ``solve_forces`` is the fallback, on
the same equations:

1. damped Newton: the Newton direction with a backtracking (Armijo) line search on |G|^2;
2. nonlinear Gauss-Seidel: each contact's force alone, the others held, by a bracketed scalar
   solve. For one contact it is the exact answer: with the others held, G_j is continuous
   and, where the law's force grows with the penetration and its rate (always, but for the
   damping ramp's slope while unloading), strictly increasing with slope >= 1, so x0 and
   x0 - G(x0) bracket its root; where not, the bracket is widened until G changes sign.

Converged means every |G_j| at most its rounding floor (``_floor``: 8 eps times the magnitudes
of the terms G_j is computed from, through the law's partials), or Newton's own test
(|dx| <= 1e-13 of the largest force). The kernel (``kernel.run``) halves the step when even
this fails: as the step shrinks the contacts decouple (the coupling through the modes falls as
tau^2), so the halved steps end in scalar equations the bracketed solve always solves.
"""

import numpy as np

from tailbeam.jit import njit
from tailbeam.physics.impact import force_partials

EPS = np.finfo(np.float64).eps
ROUNDING = 8.0  # the floor of |G_j|, in units of eps x the magnitude of its terms
NEWTON_TOL = 1e-13  # |dx| / largest force (as step._newton)
DAMPED_ITERATIONS = 100
SWEEPS = 200  # Gauss-Seidel sweeps
SCALAR_ITERATIONS = 200


@njit(cache=True)
def _scalar_residual(x, a, av, s, sv, k, e, c, d, clamp):
    """(g = x - F, F, rounding floor of g) for one contact: penetration a + s x (m), rate
    av + sv x (m/s)."""
    dl = a + s * x
    dv = av + sv * x
    f, fd, fv, _raw = force_partials(dl, dv, k, e, c, d, clamp)
    floor = ROUNDING * EPS * (abs(x) + abs(f) + abs(fd) * (abs(a) + abs(s * x))
                              + abs(fv) * (abs(av) + abs(sv * x)))  # fmt: skip
    return x - f, f, floor


@njit(cache=True)
def scalar_force(x0, a, av, s, sv, k, e, c, d, clamp):
    """The root x (N) of x = IMPACT(a + s x, av + sv x) near ``x0`` by a bracketed
    (Illinois) solve; returns (x, converged)."""
    g0, f0, fl0 = _scalar_residual(x0, a, av, s, sv, k, e, c, d, clamp)
    if abs(g0) <= fl0:
        return x0, True
    lo, glo = x0, g0
    step = -g0  # x0 - g0 = F(x0): the bracket when F falls with x
    hi, ghi = x0, g0
    for _ in range(80):
        hi = x0 + step
        ghi, _f, flh = _scalar_residual(hi, a, av, s, sv, k, e, c, d, clamp)
        if abs(ghi) <= flh:
            return hi, True
        if (ghi > 0.0) != (glo > 0.0):
            break
        step *= 2.0
    else:
        return x0, False
    side = 0
    for _ in range(SCALAR_ITERATIONS):
        xm = (lo * ghi - hi * glo) / (ghi - glo)
        if not (min(lo, hi) < xm < max(lo, hi)):
            xm = 0.5 * (lo + hi)
        gm, fm, flm = _scalar_residual(xm, a, av, s, sv, k, e, c, d, clamp)
        big = max(1.0, abs(fm))
        if abs(gm) <= flm or abs(hi - lo) <= NEWTON_TOL * big:
            return xm, True
        if (gm > 0.0) == (glo > 0.0):
            lo, glo = xm, gm
            if side == 1:
                ghi *= 0.5
            side = 1
        else:
            hi, ghi = xm, gm
            if side == -1:
                glo *= 0.5
            side = -1
    return 0.5 * (lo + hi), False


@njit(cache=True)
def _evaluate(idx, na, dfree, vfree, S, Sv, x, k, e, c, d, clampf, r, J, floor):
    """Residual r = G(x), its Jacobian J and rounding floor per contact; returns the largest
    force (at least 1 N)."""
    big = 1.0
    for jj in range(na):
        j = idx[jj]
        dl, dv = dfree[jj], vfree[jj]
        sd, sv = abs(dfree[jj]), abs(vfree[jj])
        for ll in range(na):
            dl += S[jj, ll] * x[ll]
            dv += Sv[jj, ll] * x[ll]
            sd += abs(S[jj, ll] * x[ll])
            sv += abs(Sv[jj, ll] * x[ll])
        f, fd, fv, _raw = force_partials(dl, dv, k[j], e[j], c[j], d[j], clampf[j])
        r[jj] = x[jj] - f
        floor[jj] = ROUNDING * EPS * (abs(x[jj]) + abs(f) + abs(fd) * sd + abs(fv) * sv)
        big = max(big, abs(f))
        for ll in range(na):
            J[jj, ll] = -(fd * S[jj, ll] + fv * Sv[jj, ll])
        J[jj, jj] += 1.0
    return big


@njit(cache=True)
def _at_floor(r, floor):
    for jj in range(r.shape[0]):
        if abs(r[jj]) > floor[jj]:
            return False
    return True


@njit(cache=True)
def _damped_newton(idx, na, dfree, vfree, S, Sv, x, k, e, c, d, clampf):
    """Newton with a backtracking line search on |G|^2 from ``x`` (updated in place);
    returns True when converged."""
    r, rt, fl, flt = np.empty(na), np.empty(na), np.empty(na), np.empty(na)
    J, Jt = np.empty((na, na)), np.empty((na, na))
    xt = np.empty(na)
    for _it in range(DAMPED_ITERATIONS):
        big = _evaluate(idx, na, dfree, vfree, S, Sv, x, k, e, c, d, clampf, r, J, fl)
        if _at_floor(r, fl):
            return True
        try:
            dx = np.linalg.solve(J, r)
        except Exception:  # (a singular Jacobian: leave it to Gauss-Seidel)
            return False
        merit = np.dot(r, r)
        lam = 1.0
        accepted = False
        for _ls in range(50):
            xt[:] = x - lam * dx
            _evaluate(idx, na, dfree, vfree, S, Sv, xt, k, e, c, d, clampf, rt, Jt, flt)
            if np.dot(rt, rt) <= (1.0 - 1e-4 * lam) * merit or _at_floor(rt, flt):
                accepted = True
                break
            lam *= 0.5
        if not accepted:
            return False
        x[:] = xt
        if lam * np.max(np.abs(dx)) <= NEWTON_TOL * big:
            return True
    return False


@njit(cache=True)
def _gauss_seidel(idx, na, dfree, vfree, S, Sv, x, k, e, c, d, clampf):
    """Each contact's force by ``scalar_force``, the others held, sweep after sweep, until
    the whole residual is at its floor or a sweep changes no force by more than Newton's
    test; returns True when converged."""
    r, fl = np.empty(na), np.empty(na)
    J = np.empty((na, na))
    for _sweep in range(SWEEPS):
        change = 0.0
        for jj in range(na):
            j = idx[jj]
            a, av = dfree[jj], vfree[jj]
            for ll in range(na):
                if ll != jj:
                    a += S[jj, ll] * x[ll]
                    av += Sv[jj, ll] * x[ll]
            xj, ok = scalar_force(x[jj], a, av, S[jj, jj], Sv[jj, jj], k[j], e[j], c[j], d[j],
                                  clampf[j])  # fmt: skip
            if not ok:
                return False
            change = max(change, abs(xj - x[jj]))
            x[jj] = xj
        big = _evaluate(idx, na, dfree, vfree, S, Sv, x, k, e, c, d, clampf, r, J, fl)
        if _at_floor(r, fl) or change <= NEWTON_TOL * big:
            return True
    return False


@njit(cache=True)
def solve_forces(idx, na, dfree, vfree, S, Sv, x, k, e, c, d, clampf):
    """The end forces x (N; in: the guess, out: the solution) of the step's contact system
    (module docstring) when plain Newton failed; returns False if no method converged."""
    x0 = x.copy()
    if na > 1 and _damped_newton(idx, na, dfree, vfree, S, Sv, x, k, e, c, d, clampf):
        return True
    x[:] = x0
    return _gauss_seidel(idx, na, dfree, vfree, S, Sv, x, k, e, c, d, clampf)
