"""Every ball of a stream between its contacts: status, closed-form motion, predicted events.

A ball is PENDING (not released yet), FLY (free flight), SLIDE (resting quasi-statically on
the frictionless plate: its centre at the static penetration, sliding downhill), ACTIVE (in
the active set: integrated by the compiled kernel), GONE (left over an edge) or SLEEP (held
at rest by friction, frozen: ``sleep``). FLY, SLIDE and SLEEP balls move in closed form (a
sleeping ball stands still) from a reference state (t0, x0, v0); ``version`` counts changes of
that motion, so predictions made for an older motion are recognised as stale.
"""

import math

import numpy as np

from tailbeam.physics.contacts import PLATE
from tailbeam.solvers.numerics.flight import advance, band_time, edge_time, pair_time, plate_time

PENDING, FLY, SLIDE, ACTIVE, GONE, SLEEP = range(6)
_STILL = np.zeros(3)  # a sleeping ball's acceleration


class Balls:
    """Per-ball arrays of a stream (n balls, in release order).

    Parameters
    ----------
    particles : list of Particle
        The stream's particles (name, mass kg, radius m, t_release s, position m, velocity
        m/s in the plate frame).
    incline : InclinedPlate
        The plate (half sizes m) and gravity (m/s^2, plate frame).
    contacts : ContactTable
        The particles' contact laws.
    """

    def __init__(self, particles, incline, contacts):
        self.particles = list(particles)
        n = len(self.particles)
        self.names = [p.name for p in self.particles]
        self.mass = np.array([p.mass for p in self.particles], dtype=float)
        self.radius = np.array([p.radius for p in self.particles], dtype=float)
        self.t_release = np.array([p.t_release for p in self.particles], dtype=float)
        self.status = np.full(n, PENDING, dtype=np.int8)
        self.version = np.zeros(n, dtype=np.int64)
        self.in_set = np.zeros(n, dtype=np.bool_)  # FLY/SLIDE balls watched by the active set
        self.t0 = self.t_release.copy()
        self.x0 = np.array([p.position for p in self.particles], dtype=float).reshape(n, 3)
        self.v0 = np.array([p.velocity for p in self.particles], dtype=float).reshape(n, 3)
        # angular velocities (rad/s): constant in flight; the active set's while in it
        self.w = np.array([p.angular_velocity for p in self.particles], dtype=float).reshape(n, 3)
        self.release_position = self.x0.copy()  # m: where each is released (a slot: moved)
        self.g = np.asarray(incline.gravity_vector, dtype=float)
        self.g_slide = np.array([self.g[0], self.g[1], 0.0])
        self.half = incline.half_sizes
        self.table = contacts  # the ContactTable of the particles (tailbeam.physics.contacts)
        weight_n = self.mass * max(-self.g[2], 0.0)
        self.static_pen = np.array(
            [self.plate_law(i).static_penetration(w) for i, w in enumerate(weight_n)]
        )
        self.slide_since = np.full(n, math.nan)

    def plate_law(self, i: int):
        """The ball-plate law of ball i (its row in the contact table)."""
        return self.table.law(i, PLATE)

    def accel(self, i: int) -> np.ndarray:
        if self.status[i] == SLEEP:
            return _STILL
        return self.g_slide if self.status[i] == SLIDE else self.g

    def state(self, i: int, t: float):
        """Closed-form position and velocity of a FLY or SLIDE ball at time t."""
        return advance(self.x0[i], self.v0[i], self.accel(i), t - self.t0[i])

    def states(self, idx, t: float):
        """Vectorised ``state`` for the balls ``idx`` (all FLY or SLIDE)."""
        idx = np.asarray(idx, dtype=np.int64)
        acc = np.where((self.status[idx] == SLIDE)[:, None], self.g_slide, self.g)
        acc = np.where((self.status[idx] == SLEEP)[:, None], 0.0, acc)
        dt = (t - self.t0[idx])[:, None]
        return self.x0[idx] + self.v0[idx] * dt + 0.5 * acc * dt * dt, self.v0[idx] + acc * dt

    def set_motion(self, i: int, status: int, t: float, x, v) -> None:
        """Start a new closed-form motion of ball i (FLY or SLIDE) at time t."""
        self.status[i] = status
        self.t0[i] = t
        self.x0[i] = x
        self.v0[i] = v
        if status == SLIDE:
            self.x0[i, 2] = self.radius[i] - self.static_pen[i]
            self.v0[i, 2] = 0.0
        self.version[i] += 1

    def closed_form(self) -> np.ndarray:
        """Indices of the balls moving in closed form (FLY, SLIDE or SLEEP)."""
        s = self.status
        return np.flatnonzero((s == FLY) | (s == SLIDE) | (s == SLEEP))

    def resting(self, t: float):
        """(xy (p, 2) m, weights (p,) N) of the balls resting on the plate outside the
        active set (SLIDE) at time t (s)."""
        idx = np.flatnonzero((self.status == SLIDE) & ~self.in_set)
        if not len(idx):
            return np.empty((0, 2)), np.empty(0)
        x, _ = self.states(idx, t)
        return x[:, :2], self.mass[idx] * -self.g[2]

    def speed_bounds(self, idx, t: float, horizon: float) -> np.ndarray:
        """Bounds (m/s) on the speeds of closed-form balls ``idx`` over [t, t + horizon]."""
        _, v = self.states(idx, t)
        acc = np.where(self.status[idx] == SLIDE, abs(self.g_slide[0]), np.linalg.norm(self.g))
        acc = np.where(self.status[idx] == SLEEP, 0.0, acc)
        return np.linalg.norm(v, axis=1) + acc * horizon

    def own_events(self, i: int, t: float, margin: float = 0.0) -> list:
        """(time, kind, edge) of the plate touch (FLY; with a margin (m) above the plate: the
        vibrating plate's deflection bound) and the edge crossing of ball i."""
        x, v = self.state(i, t)
        a = self.accel(i)
        out = []
        if self.status[i] == FLY:
            if margin > 0.0:
                tau = band_time(x[2], v[2], a[2], self.radius[i] + margin)
            else:
                tau = plate_time(x[2], v[2], a[2], self.radius[i])
            if math.isfinite(tau):
                out.append((t + tau, "plate", ""))
        tau, edge = edge_time(x, v, a, self.half)
        if math.isfinite(tau):
            out.append((t + tau, "edge", edge))
        return out

    def pair_event(self, i: int, j: int, t: float, horizon: float) -> float:
        """Absolute time at which closed-form balls i and j first touch within horizon."""
        xi, vi = self.state(i, t)
        xj, vj = self.state(j, t)
        tau = pair_time(
            xi - xj, vi - vj, self.accel(i) - self.accel(j), self.radius[i] + self.radius[j],
            horizon,
        )  # fmt: skip
        return t + tau
