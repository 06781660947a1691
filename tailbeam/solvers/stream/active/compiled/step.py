"""One DOP853 step of an active set and its dense output, evaluated where the events need it.

The step (``dop853_step``: 12 right-hand-side evaluations, scipy's error norm per block of the
state: balls, then modes), the 7 dense-output rows of an accepted step (``dense_coef``: 3 more
evaluations) and their evaluation: one component or the whole state at a fraction s of the
step, a ball's 6 components at the 15 Chebyshev points of the step (``ensure_ball``, once per
ball and step), and with the modal plate the modes projected on a plate pair's phi first
(``project``, ``project_plate``, ``ensure_plate``: O(modes) per pair and step, not per point).
State layout (``active_kernel.advance``): positions (3 n, m), velocities (3 n, m/s), then the
modal coordinates (m) and their rates. Helpers compiled without reference counting
(``tailbeam.solvers.numerics.jit``).
"""

import math

import numpy as np

from tailbeam.solvers.numerics.dop853 import dense_rows
from tailbeam.solvers.numerics.jit import helper_njit
from tailbeam.solvers.stream.active.compiled.pairs import FIXED, rhs, rhs_arrays

EPS = 2.220446049250313e-16


@helper_njit
def stages(K, A, first, stop, y, h, model, pstate, tmp):
    """Runge-Kutta stages first..stop-1 into K (rows: stages)."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    touching, ramp, clamped = pstate[0], pstate[1], pstate[2]
    n = y.shape[0]
    for s in range(first, stop):
        for q in range(n):
            acc = 0.0
            for j in range(s):
                acc += A[s, j] * K[j, q]
            tmp[q] = y[q] + h * acc
        rhs_arrays(tmp, mass, g, pi, pj, law, rsum, touching, ramp, clamped, alive, omega, zeta,
                   phi, fdead, radius, fric, K[s])  # fmt: skip


@helper_njit
def dop853_step(y, h, K, tab, rtol, atol, model, pstate, ynew, tmp):
    """One DOP853 step of size h from y (K[0] = f(y) given): ynew, K[12] = f(ynew); returns
    scipy's error norm (NaN or > 1: reject), taken separately over the balls and the modal
    block (the larger: many modes do not dilute the balls' error). atol (N,) per component."""
    A, B = tab[0], tab[1]
    n = y.shape[0]
    nb6 = 6 * model[0].shape[0]  # balls' positions and velocities, then the modal block
    nfixed = fixed_count(model[9])  # (their components never change: not in the norm's count)
    stages(K, A, np.int64(1), np.int64(12), y, h, model, pstate, tmp)
    for q in range(n):
        acc = 0.0
        for j in range(12):
            acc += B[j] * K[j, q]
        ynew[q] = y[q] + h * acc
    rhs(ynew, model, pstate, K[12])
    err = block_error(y, ynew, h, K, tab, rtol, atol, np.int64(0), nb6, nb6 - 6 * nfixed)
    if n > nb6 and err == err:
        spins = 3 * nfixed if model[14].shape[1] > 0 else 0
        err_modes = block_error(y, ynew, h, K, tab, rtol, atol, nb6, n, n - nb6 - spins)
        if not err_modes <= err:
            err = err_modes
    return err


@helper_njit
def block_error(y, ynew, h, K, tab, rtol, atol, lo, hi, count):
    """scipy's DOP853 error norm over the components lo..hi-1, ``count`` of them counted
    (those of FIXED balls, exactly constant, are not)."""
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
    return h * err5 / math.sqrt((err5 + 0.01 * err3) * count)


@helper_njit
def fixed_count(alive):
    """How many balls are FIXED obstacles (``pairs.FIXED``)."""
    c = 0
    for b in range(alive.shape[0]):
        if alive[b] == FIXED:
            c += 1
    return c


@helper_njit
def dense_coef(y, ynew, h, K, tab, model, pstate, coef, tmp):
    """The 3 extra stages and the 7 rows of DOP853's dense output (scipy's F)."""
    A, D = tab[0], tab[4]
    stages(K, A, np.int64(13), np.int64(16), y, h, model, pstate, tmp)
    for q in range(y.shape[0]):
        dense_rows(coef, q, ynew[q] - y[q], h, K[0, q], K, D)


@helper_njit
def dense_component(coef, y, s, q):
    """Component q of the dense output at fraction s of the step."""
    a = 0.0
    for i in range(6, -1, -1):
        a += coef[i, q]
        a *= s if (6 - i) % 2 == 0 else 1.0 - s
    return y[q] + a


@helper_njit
def dense_state(coef, y, s, out):
    for q in range(y.shape[0]):
        out[q] = dense_component(coef, y, s, q)


@helper_njit
def project(coef, y, phi, p, off, out):
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
def dense_projected(c8, s):
    """A projected dense output (``project``) at fraction s of the step (as ``dense_component``)."""
    a = 0.0
    for i in range(6, -1, -1):
        a += c8[i]
        a *= s if (6 - i) % 2 == 0 else 1.0 - s
    return c8[7] + a


@helper_njit
def project_plate(coef, y, model, p, proj):
    """The dense outputs (``project``) of the plate under plate pair p of the step: w, w' and
    acc0 = -g_z + phi[p] . (f_dead - 2 zeta omega q' - omega^2 q) (``plate_free_acceleration``)
    into proj[0..2]; returns kappa = 1/m + phi[p] . phi[p] (1/kg). The modes projected on
    phi[p] first: O(modes) per step, not per point."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    n = mass.shape[0]
    nm = phi.shape[1]
    off = 6 * n
    project(coef, y, phi, p, off, proj[0])
    project(coef, y, phi, p, off + nm, proj[1])
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
def ensure_ball(Y15, have, coef, y, pts, b):
    """Ball b's 6 state components at the 15 Chebyshev points of the step (once per step)."""
    if b < 0 or have[b]:
        return
    have[b] = True
    n = have.shape[0]
    for q in range(pts.shape[0]):
        for k in range(3):
            Y15[q, 3 * b + k] = dense_component(coef, y, pts[q], 3 * b + k)
            Y15[q, 3 * n + 3 * b + k] = dense_component(coef, y, pts[q], 3 * n + 3 * b + k)


@helper_njit
def ensure_plate(W15, have_w, coef, y, pts, model, p, proj):
    """The plate's deflection, velocity and free acceleration (``project_plate``) under plate
    pair p at the 15 Chebyshev points of the step, and kappa (once per step)."""
    if have_w[p]:
        return
    have_w[p] = True
    kappa = project_plate(coef, y, model, p, proj)
    for q in range(pts.shape[0]):
        W15[q, p, 0] = dense_projected(proj[0], pts[q])
        W15[q, p, 1] = dense_projected(proj[1], pts[q])
        W15[q, p, 2] = dense_projected(proj[2], pts[q])
        W15[q, p, 3] = kappa
