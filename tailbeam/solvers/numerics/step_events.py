"""Events inside one integration step, from its dense output (no step is trusted blindly).

An explicit Runge-Kutta step with a dense output of degree 7 (DOP853) makes every squared
distance between centres, plate gap and edge distance a polynomial of degree <= 14 in the
step's time. Such a function g is interpolated exactly at the 15 Chebyshev points
``STEP_POINTS`` (fractions of the step, 0 and 1 included); on [0, 1] its Chebyshev series
satisfies |g - c0| <= sum_k>=1 |c_k|, so c0 > sum |c_k| certifies g > 0 on the whole step
(however short the approach and retreat it would hide between the step's ends). The
remaining rows are root-found (``chebroots``, Newton-polished). Used by the stream
reference; meant for the fast solver's island steps too.
"""

import math

import numpy as np
from numpy.polynomial import chebyshev as cheb

NODES = 15  # Chebyshev points per step: exact for degree-14 polynomials
_U = -np.cos(np.pi * np.arange(NODES) / (NODES - 1))  # increasing, -1 .. 1
STEP_POINTS = 0.5 * (_U + 1.0)  # the same points as fractions of the step
_VINV = np.linalg.inv(cheb.chebvander(_U, NODES - 1))
FRESH_S = 1e-10  # roots closer than this (fraction of a step) to a restart are the restart's


def chebyshev_coefficients(values) -> np.ndarray:
    """Chebyshev coefficients (..., 15) of the interpolants through ``values`` (..., 15)
    given at ``STEP_POINTS``."""
    return np.asarray(values) @ _VINV.T


def certified_positive(coef) -> np.ndarray:
    """Rows (of coefficients) whose polynomial is > 0 on the whole step: c0 > sum |c_k|."""
    coef = np.atleast_2d(coef)
    return coef[:, 0] > np.sum(np.abs(coef[:, 1:]), axis=1) * (1.0 + 1e-12)


def first_downward_crossing(c, values, is_fresh) -> float:
    """First fraction s in [0, 1] of the step where the degree-14 polynomial g with Chebyshev
    coefficients ``c`` (``values`` at the Chebyshev points) becomes negative; inf if none.
    ``is_fresh``: g sat on zero at the step's start (the restart of its own event): roots
    within ``FRESH_S`` of the start are that one."""
    if not is_fresh and values[0] < 0.0:
        return 0.0
    dc = cheb.chebder(c)
    best = math.inf
    for r in cheb.chebroots(c):
        if abs(r.imag) > 1e-6 or not -1.0 - 1e-9 <= r.real <= 1.0 + 1e-9:
            continue
        u = float(r.real)
        for _ in range(3):  # Newton polish on the interpolant
            d = cheb.chebval(u, dc)
            if d == 0.0:
                break
            u = min(max(u - cheb.chebval(u, c) / d, -1.0), 1.0)
        s = 0.5 * (u + 1.0)
        if is_fresh and s < FRESH_S:
            continue
        if cheb.chebval(u, dc) < 0.0 and s < best:  # a crossing downwards
            best = s
    return best


def interpolant_max(values) -> tuple[float, float]:
    """(s, value) of the maximum on [0, 1] of the degree-14 Chebyshev interpolant through
    ``values`` at the Chebyshev points: the largest of the node values and the interpolant at
    the real roots of its derivative. Inside a region the force and penetration are smooth
    and each step is resolved to rtol, so the interpolant is accurate to about rtol there."""
    k = int(np.argmax(values))
    best_u, best = _U[k], float(values[k])
    c = _VINV @ values
    for r in cheb.chebroots(cheb.chebder(c)):
        if abs(r.imag) < 1e-9 and -1.0 < r.real < 1.0:
            value = float(cheb.chebval(r.real, c))
            if value > best:
                best_u, best = float(r.real), value
    return 0.5 * (best_u + 1.0), best
