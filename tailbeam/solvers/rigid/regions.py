"""Pieces of the compiled contact kernel: the right-hand side in one region of the IMPACT law
(the law itself: ``tailbeam.physics.impact``), the watched (event) functions, DOP853
dense-output evaluation and bracketed root finding.

A region is (ramp, clamped): ramp means delta < d (STEP's cubic), clamped means Adams' max(0, .)
holds the force at 0. Each region's formula is smooth and is used past the region's border
too, so integration steps never straddle a kink (see kernel.py).
"""

import numpy as np

from tailbeam.jit import njit
from tailbeam.physics import impact
from tailbeam.physics.contact_law import LAW_C, LAW_COLUMNS, LAW_D, LAW_E, LAW_K

# the parameter vector: the law's columns (LAW_K ... LAW_CLAMP), then the ball's own
P_M, P_G, P_EREST, P_ETRAP = range(LAW_COLUMNS, LAW_COLUMNS + 4)
N_PAR = LAW_COLUMNS + 4
# watched functions
W_FULL, W_CLAMP, W_SEP, W_REST, W_UMAX, W_PEAK = range(6)
N_WATCH = 6

EPS = np.finfo(float).eps
INTERIOR = (0.25, 0.5, 0.75)


@njit(cache=True)
def accel(delta, u, ramp, clamped, par):
    """du/dt = g - F / m in the region (ramp, clamped)."""
    if clamped or delta <= 0.0:
        return par[P_G]
    k, e, c, d = par[LAW_K], par[LAW_E], par[LAW_C], par[LAW_D]
    return par[P_G] - impact.region_force(delta, u, k, e, c, d, ramp, False) / par[P_M]


@njit(cache=True)
def watch_all(delta, u, ramp, clamped, par, out):
    """Values of all watched functions at (delta, u); returns the force in the region."""
    k, e, c, d, m, g = par[LAW_K], par[LAW_E], par[LAW_C], par[LAW_D], par[P_M], par[P_G]
    out[W_FULL] = delta - d
    out[W_SEP] = delta
    out[W_UMAX] = u
    raw = impact.region_force(delta, u, k, e, c, d, ramp, False) if delta > 0.0 else 0.0
    out[W_CLAMP] = impact.clamp_indicator(delta, u, k, e, c, d, ramp)
    out[W_PEAK] = impact.region_force_rate(delta, u, g - raw / m, k, e, c, d, ramp)
    elastic = impact.elastic_energy(delta, k, e)
    out[W_REST] = 0.5 * m * u * u + elastic - m * g * delta + par[P_ETRAP] - par[P_EREST]
    if clamped:
        return 0.0
    return raw


@njit(cache=True)
def dense_eval(x, y0, y1, coef):
    """DOP853 dense output at x in [0, 1] of a step: returns (delta, u)."""
    a0 = 0.0
    a1 = 0.0
    for i in range(6, -1, -1):
        a0 += coef[i, 0]
        a1 += coef[i, 1]
        w = x if (6 - i) % 2 == 0 else 1.0 - x
        a0 *= w
        a1 *= w
    return y0 + a0, y1 + a1


@njit(cache=True)
def _gval(w, x, fresh, y0, y1, coef, ramp, clamped, par, buf):
    """Watched function w at x of the step; divided by x when it is the restart function."""
    dl, u = dense_eval(x, y0, y1, coef)
    watch_all(dl, u, ramp, clamped, par, buf)
    if fresh:
        return buf[w] / x
    return buf[w]


@njit(cache=True)
def find_root(w, xa, ga, xb, gb, fresh, y0, y1, coef, ramp, clamped, par, buf, xtol):
    """Bracketed root of watched function w on [xa, xb] (Illinois with bisection guard)."""
    side = 0
    for it in range(200):
        if xb - xa <= xtol:
            break
        if it % 3 == 2:
            xm = 0.5 * (xa + xb)
        else:
            xm = (xa * gb - xb * ga) / (gb - ga)
            if not (xa < xm < xb):
                xm = 0.5 * (xa + xb)
        gm = _gval(w, xm, fresh, y0, y1, coef, ramp, clamped, par, buf)
        if gm == 0.0:
            return xm
        if (gm > 0.0) == (ga > 0.0):
            xa, ga = xm, gm
            if side == -1:
                gb *= 0.5
            side = -1
        else:
            xb, gb = xm, gm
            if side == 1:
                ga *= 0.5
            side = 1
    return 0.5 * (xa + xb)


@njit(cache=True)
def crosses(ga, gb, direction):
    if direction > 0:
        return ga < 0.0 and gb >= 0.0
    return ga > 0.0 and gb <= 0.0
