"""Closed-form motion between contacts, and when it ends: pure helpers of the solvers.

A ball that touches nothing moves with a constant acceleration a (m/s^2) in the plate frame:

* flying: a = g_vec = g (sin theta, 0, -cos theta);
* sliding (resting quasi-statically on the frictionless plate, the stream driver's sliders):
  a = (g sin theta, 0, 0), its height held at the static penetration.

so x(tau) = x0 + v0 tau + a tau^2 / 2. The times at which such motion ends are roots of
polynomials of degree <= 4, found here without missing a grazing touch:

* the plate: z(tau) = r (a quadratic);
* an edge: x(tau) = +-a/2 or y(tau) = +-b/2 (quadratics);
* another ball: |x_i(tau) - x_j(tau)|^2 = (r_i + r_j)^2 (a quartic in general, a quadratic
  when both accelerate alike).

``first_crossing`` splits [0, horizon] at the roots of the derivative (the polynomial is
monotone between them), so a dip below zero between two sampled times cannot hide, then
brackets the first downward crossing and solves it with ``brentq`` to machine precision.
"""

import math

import numpy as np
from scipy.optimize import brentq

from tailbeam.physics.incline import EDGES
from tailbeam.results.records import LeaveEvent

NEVER = math.inf


def advance(x0, v0, a, tau):
    """Position and velocity after tau s of constant acceleration a (arrays broadcast)."""
    x0, v0, a = (np.asarray(q, dtype=float) for q in (x0, v0, a))
    tau = np.asarray(tau, dtype=float)[..., None] if np.ndim(tau) else float(tau)
    return x0 + v0 * tau + 0.5 * a * tau * tau, v0 + a * tau


def _poly(c, t):
    """Polynomial with ascending coefficients c at t (Horner)."""
    value = 0.0
    for ck in c[::-1]:
        value = value * t + ck
    return value


def first_crossing(coefficients, horizon: float) -> float:
    """First tau in (0, horizon] where p(tau) (ascending ``coefficients``) falls to <= 0.

    p(0) > 0 is the usual case; p(0) <= 0 with p'(0) < 0 returns 0 (touching and closing);
    p(0) <= 0 with p'(0) >= 0 looks for the next downward crossing. Returns inf if none.
    """
    c = np.trim_zeros(np.asarray(coefficients, dtype=float), "b")
    if c.size == 0 or not horizon > 0:
        return NEVER
    slope = c[1] if c.size > 1 else 0.0
    if c[0] <= 0.0 and slope < 0.0:
        return 0.0
    cuts = [0.0, horizon]
    if c.size > 2:
        deriv = c[1:] * np.arange(1, c.size)
        roots = np.roots(deriv[::-1])
        scale = max(horizon, 1e-300)
        real = roots[np.abs(roots.imag) <= 1e-7 * (np.abs(roots.real) + scale)].real
        cuts += [float(r) for r in real if 0.0 < r < horizon]
    cuts = sorted(cuts)
    lo, p_lo = cuts[0], c[0]
    for hi in cuts[1:]:
        p_hi = _poly(c, hi)
        if p_lo > 0.0 and p_hi <= 0.0:
            if p_hi == 0.0:
                return hi
            return brentq(lambda s: _poly(c, s), lo, hi, xtol=1e-300, rtol=4 * np.finfo(float).eps)
        lo, p_lo = hi, p_hi
    return NEVER


def plate_time(z0: float, vz: float, az: float, radius: float) -> float:
    """Time (s) until a flying ball's height z (m, centre) comes down to its radius, or inf.

    az = -g cos theta <= 0 (m/s^2). Closed form of the quadratic, in the cancellation-free
    form while approaching.
    """
    gap = z0 - radius
    gn = -az
    if gap < 0.0:
        gap = 0.0
    if gn <= 0.0:
        return gap / -vz if vz < 0.0 else NEVER
    root = math.sqrt(vz * vz + 2.0 * gn * gap)
    if vz <= 0.0:
        return 2.0 * gap / (root - vz) if root - vz > 0.0 else 0.0
    return (vz + root) / gn


def band_time(z0: float, vz: float, az: float, height: float) -> float:
    """Time (s) until a flying ball's centre comes down to ``height`` (m) above the plate
    (z may start below it: then the descending crossing; 0 if it is below and not rising:
    it is in the band now, never a time in the past), or inf if its apex stays below."""
    gn = -az
    gap = z0 - height
    if gap < 0.0 and vz <= 0.0:
        return 0.0
    if gn <= 0.0:
        return max(gap, 0.0) / -vz if vz < 0.0 else NEVER
    disc = vz * vz + 2.0 * gn * gap
    if disc < 0.0:
        return NEVER
    root = math.sqrt(disc)
    if gap >= 0.0 and vz <= 0.0:
        return 2.0 * gap / (root - vz) if root - vz > 0.0 else 0.0
    return (vz + root) / gn


def _exit_time(room: float, rate: float, accel: float) -> float:
    """First tau > 0 where room - rate tau - accel tau^2 / 2 = 0, room >= 0 (m), or inf."""
    room = max(room, 0.0)
    if accel == 0.0:
        return room / rate if rate > 0.0 else NEVER
    disc = rate * rate + 2.0 * accel * room
    if disc < 0.0:
        return NEVER
    root = math.sqrt(disc)
    if accel > 0.0:
        return 2.0 * room / (rate + root) if rate + root > 0.0 else 0.0
    # decelerating towards the edge: the first root if it is reached at all
    return 2.0 * room / (rate + root) if rate > 0.0 else NEVER


def edge_time(x0, v0, a, half_sizes) -> tuple:
    """(time s, edge name) at which the centre first passes an edge, or (inf, "")."""
    best, edge = NEVER, ""
    for axis, half in enumerate(half_sizes):
        for sign, name in ((-1.0, EDGES[2 * axis]), (1.0, EDGES[2 * axis + 1])):
            tau = _exit_time(half - sign * x0[axis], sign * v0[axis], sign * a[axis])
            if tau < best:
                best, edge = tau, name
    return best, edge


def pair_coefficients(dx, dv, da, radius_sum: float) -> np.ndarray:
    """Ascending coefficients of |dx + dv tau + da tau^2 / 2|^2 - radius_sum^2."""
    dx, dv, da = (np.asarray(q, dtype=float) for q in (dx, dv, da))
    return np.array(
        [
            dx @ dx - radius_sum * radius_sum,
            2.0 * (dx @ dv),
            dv @ dv + dx @ da,
            dv @ da,
            0.25 * (da @ da),
        ]
    )


def pair_time(dx, dv, da, radius_sum: float, horizon: float) -> float:
    """Time (s) within ``horizon`` at which two balls in closed-form motion first touch."""
    return first_crossing(pair_coefficients(dx, dv, da, radius_sum), horizon)


def lateral_leaves(balls, plate, duration: float) -> list:
    """``LeaveEvent`` of every ball whose centre passes an edge of ``plate`` by ``duration`` s,
    in time order, for balls moving laterally at their constant initial velocity (the
    single-ball solvers: a horizontal frictionless plate); edges named as ``EDGES``."""
    out = [_lateral_leave(b, plate, duration) for b in balls]
    return sorted((e for e in out if e is not None), key=lambda e: e.time)


def _lateral_leave(ball, plate, duration):
    (x, y, _z), (vx, vy, _vz) = ball.position, ball.velocity
    ha, hb = 0.5 * plate.size_x, 0.5 * plate.size_y
    best = None
    for edge, dist, rate in (
        ("x-", x + ha, vx), ("x+", ha - x, -vx), ("y-", y + hb, vy), ("y+", hb - y, -vy)
    ):  # fmt: skip
        if rate < 0.0:
            t = dist / -rate
            if t <= duration and (best is None or t < best.time):
                best = LeaveEvent(ball.name, t, edge)
    return best
