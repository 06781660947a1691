"""One DOP853 step of a ball-plate contact's state (delta, u) and its dense output.

The pieces of ``kernel.integrate_contact`` that do not know about events: the Runge-Kutta
stages in one region of the law (``regions.accel``), scipy's error norm of the embedded
5th/3rd-order pair, and the dense-output coefficients (3 extra stages; the rows themselves
are ``tailbeam.solvers.numerics.dop853.dense_rows``).
"""

import math

from tailbeam.solvers.numerics.dop853 import dense_rows
from tailbeam.solvers.numerics.jit import helper_njit
from tailbeam.solvers.rigid.regions import accel


@helper_njit
def stages(K, A, first, stop, y0, y1, h, ramp, clamped, par):
    """Runge-Kutta stages first..stop-1 of the state (delta m, u m/s) into K (rows: stages,
    columns: d delta/dt m/s, du/dt m/s^2) for a step of h (s)."""
    for s in range(first, stop):
        s0 = 0.0
        s1 = 0.0
        for j in range(s):
            s0 += A[s, j] * K[j, 0]
            s1 += A[s, j] * K[j, 1]
        uu = y1 + h * s1
        K[s, 0] = uu
        K[s, 1] = accel(y0 + h * s0, uu, ramp, clamped, par)


@helper_njit
def step(K, A, B, E3, E5, y0, y1, f0, f1, h, ramp, clamped, par, rtol, atol0, atol1):
    """One DOP853 step of h (s) from (delta y0 m, u y1 m/s) with slopes (f0, f1) there.

    Fills K[0..12] (K[12] = the slopes at the step's end) and returns (delta m, u m/s) at the
    step's end and scipy's error norm (> 1 or NaN: reject; atol0 m, atol1 m/s)."""
    K[0, 0] = f0
    K[0, 1] = f1
    stages(K, A, 1, 12, y0, y1, h, ramp, clamped, par)
    b0 = 0.0
    b1 = 0.0
    for j in range(12):
        b0 += B[j] * K[j, 0]
        b1 += B[j] * K[j, 1]
    n0 = y0 + h * b0
    n1 = y1 + h * b1
    K[12, 0] = n1
    K[12, 1] = accel(n0, n1, ramp, clamped, par)
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
    return n0, n1, err


@helper_njit
def dense_coefficients(K, A, D, y0, y1, n0, n1, f0, f1, h, ramp, clamped, par, coef):
    """The 7 x 2 dense-output coefficients ``coef`` of an accepted step of h (s) from
    (y0 m, y1 m/s) to (n0, n1) (3 extra stages into K[13..15]; ``regions.dense_eval``)."""
    stages(K, A, 13, 16, y0, y1, h, ramp, clamped, par)
    dense_rows(coef, 0, n0 - y0, h, f0, K, D)
    dense_rows(coef, 1, n1 - y1, h, f1, K, D)
