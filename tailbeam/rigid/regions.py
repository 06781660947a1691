"""Pieces of the compiled contact kernel: the force law of one region of the IMPACT law, the
watched (event) functions, DOP853 dense-output evaluation and bracketed root finding.

A region is (ramp, clamped): ramp means delta < d (STEP's cubic), clamped means Adams' max(0, .)
holds the force at 0. Each region's formula is smooth and is used past the region's border
too, so integration steps never straddle a kink (see kernel.py).
"""

import math

import numpy as np
from numba import njit

# parameter vector layout
P_M, P_G, P_K, P_E, P_C, P_D, P_CLAMP, P_EREST, P_ETRAP = range(9)
N_PAR = 9
# watched functions
W_FULL, W_CLAMP, W_SEP, W_REST, W_UMAX, W_PEAK = range(6)
N_WATCH = 6
# event codes written to the event buffer
EV_FULL, EV_CLAMP_ON, EV_CLAMP_OFF, EV_END, EV_REST = range(5)
EVENT_NAMES = ("full_damping", "clamp_on", "clamp_off", "contact_end", "rest")
# return status
ST_SEPARATED, ST_REST, ST_DURATION, ST_STEP_LIMIT, ST_BUFFER_FULL, ST_STEP_TINY = range(6)

SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0
EPS = np.finfo(float).eps
INTERIOR = (0.25, 0.5, 0.75)


@njit(cache=True)
def _pow(x, e):
    """x^e for x > 0; the Hertz exponent 3/2 as x sqrt(x) (several times cheaper)."""
    if e == 1.5:
        return x * math.sqrt(x)
    return x**e


@njit(cache=True)
def _damping(delta, ramp, par):
    if not ramp:
        return par[P_C]
    s = delta / par[P_D]
    return par[P_C] * s * s * (3.0 - 2.0 * s)


@njit(cache=True)
def accel(delta, u, ramp, clamped, par):
    """du/dt = g - F / m in the region (ramp, clamped)."""
    if clamped or delta <= 0.0:
        return par[P_G]
    return par[P_G] - (par[P_K] * _pow(delta, par[P_E]) + _damping(delta, ramp, par) * u) / par[P_M]


@njit(cache=True)
def watch_all(delta, u, ramp, clamped, par, out):
    """Values of all watched functions at (delta, u); returns the force in the region."""
    k, e, c, d, m, g = par[P_K], par[P_E], par[P_C], par[P_D], par[P_M], par[P_G]
    out[W_FULL] = delta - d
    out[W_SEP] = delta
    out[W_UMAX] = u
    damp = _damping(delta, ramp, par)
    if delta > 0.0:
        pe = _pow(delta, e)
        raw = k * pe + damp * u
        out[W_CLAMP] = 1.0 + damp * u / (k * pe)
        elastic = k * pe * delta / (e + 1.0)
        ddamp = c * 6.0 * (delta / d) * (1.0 - delta / d) / d if ramp else 0.0
        accel = g - raw / m
        out[W_PEAK] = (k * e * pe / delta + ddamp * u) * u + damp * accel
    else:
        raw = 0.0
        elastic = 0.0
        if ramp and e < 2.0:
            out[W_CLAMP] = 1.0
        elif ramp and e == 2.0:
            out[W_CLAMP] = 1.0 + 3.0 * c * u / (k * d * d)
        else:
            out[W_CLAMP] = -1.0 if u < 0.0 else 1.0
        out[W_PEAK] = 0.0
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
