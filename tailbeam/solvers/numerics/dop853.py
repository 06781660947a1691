"""The parts of Dormand-Prince 8(5,3) every compiled integrator shares: scipy's coefficient
tables (``dop853_tables``, read at run time and passed in as arrays), the rows of the
7th-degree dense output (``dense_rows``) and the step-size control (``growth``, ``shrink``).
"""

import numpy as np

from tailbeam.solvers.numerics.jit import helper_njit

SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0  # step-size control


def dop853_tables():
    """(A, B, C, E3, E5, D) of Dormand-Prince 8(5,3) with its 7th-degree dense output."""
    from scipy.integrate._ivp import dop853_coefficients as co

    return tuple(
        np.ascontiguousarray(x, dtype=float) for x in (co.A, co.B, co.C, co.E3, co.E5, co.D)
    )


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
