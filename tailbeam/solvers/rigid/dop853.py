"""One DOP853 step of the contact state (delta, u) and its 7th-degree dense output.

The pieces of ``kernel.integrate_contact`` that do not know about events: the Runge-Kutta
stages in one region of the law (``regions.accel``), scipy's error norm of the embedded
5th/3rd-order pair, and the dense-output coefficients (3 extra stages). The coefficient
tables are scipy's (``dop853_tables``, read at run time and passed in as arrays).
"""

import math

import numpy as np

from tailbeam.solvers.jit import helper_njit
from tailbeam.solvers.rigid.regions import MAX_FACTOR, MIN_FACTOR, SAFETY, accel


def dop853_tables():
    """(A, B, C, E3, E5, D) of Dormand-Prince 8(5,3) with its 7th-degree dense output."""
    from scipy.integrate._ivp import dop853_coefficients as co

    return tuple(
        np.ascontiguousarray(x, dtype=float) for x in (co.A, co.B, co.C, co.E3, co.E5, co.D)
    )


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


@helper_njit
def dense_rows(coef, q, dy, h, f_start, K, D):
    """Rows 0-6 of component q of DOP853's dense output (scipy's F) after a step of h (s)
    that changed it by dy, with f_start its derivative at the step's start and K (16, .)
    the step's stages (the extra three included); D the dense-output table. Shared by the
    rigid and the stream kernels."""
    coef[0, q] = dy
    coef[1, q] = h * f_start - dy
    coef[2, q] = 2.0 * dy - h * (K[12, q] + f_start)
    for i in range(4):
        acc = 0.0
        for j in range(16):
            acc += D[i, j] * K[j, q]
        coef[3 + i, q] = h * acc


@helper_njit
def growth(err, rejected):
    """Factor of the next step after an accepted one with error norm err (not above 1 right
    after a rejection)."""
    factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err ** (-1.0 / 8.0))
    if rejected:
        factor = min(1.0, factor)
    return factor


@helper_njit
def shrink(err):
    """Factor of the retried step after a rejected one (error norm err > 1, or NaN)."""
    return max(MIN_FACTOR, SAFETY * err ** (-1.0 / 8.0)) if err > 1.0 else MIN_FACTOR
