"""The piecewise representation of one ball's vertical motion, and its exact evaluation.

A trajectory is a sorted sequence of pieces, each valid from its start time to the next piece's
start (the last one to the end of the simulation):

- flight: closed-form ballistic motion z(t) = z0 + vz0 (t - t0) - g (t - t0)^2 / 2, force 0;
- contact: one integrator step's dense-output polynomial (DOP853's 7th-degree interpolant) in
  the local contact time tau = t - t_contact, for the state (penetration delta, rate u);
  z = R - delta, vz = -u, force from the ImpactLaw;
- rest: z = R - delta_static, vz = 0, force = m g.

Sampling evaluates these pieces, so the states never depend on any output rate. The contact
polynomial is evaluated in the nested form of the interpolant with x = (tau - tau_old) / h:
y = y_old + x (F0 + (1 - x) (F1 + x (F2 + (1 - x) (F3 + ...))))  (F has 7 rows).
"""

import numpy as np

from tailbeam.physics.contact_law import ImpactLaw, impact_force

FLIGHT, CONTACT, REST = 0, 1, 2
N_DENSE = 7


class TrajectoryBuilder:
    """Collects pieces in time order (contacts as whole arrays); ``build`` freezes them."""

    def __init__(self):
        self.starts = []  # arrays of piece start times, in order
        self.kinds = []
        self.flights = []  # (t0, z0, vz0)
        self.contact_t = []  # arrays (one per contact)
        self.tau_old = []
        self.step = []
        self.y_old = []
        self.coef = []
        self.rests = []  # (z, force)

    def flight(self, t0: float, z0: float, vz0: float) -> None:
        self.starts.append(np.array([float(t0)]))
        self.kinds.append(np.array([FLIGHT], dtype=np.int8))
        self.flights.append((t0, z0, vz0))

    def contact_pieces(self, t_contact, tau_start, tau_old, step, y_old, coef) -> None:
        """Add one contact's polynomial pieces (arrays over pieces); piece i is valid from
        t_contact + tau_start[i] on."""
        n = len(tau_old)
        self.starts.append(t_contact + np.asarray(tau_start, dtype=float))
        self.kinds.append(np.full(n, CONTACT, dtype=np.int8))
        self.contact_t.append(np.full(n, float(t_contact)))
        self.tau_old.append(np.asarray(tau_old, dtype=float))
        self.step.append(np.asarray(step, dtype=float))
        self.y_old.append(np.asarray(y_old, dtype=float).reshape(n, 2))
        self.coef.append(np.asarray(coef, dtype=float).reshape(n, N_DENSE, 2))

    def rest(self, t0: float, z: float, force: float) -> None:
        self.starts.append(np.array([float(t0)]))
        self.kinds.append(np.array([REST], dtype=np.int8))
        self.rests.append((z, force))

    def build(self, radius: float, mass: float, law: ImpactLaw, gravity: float):
        return Trajectory(self, radius, mass, law, gravity)


def _cat(parts, shape):
    return np.concatenate(parts) if parts else np.zeros((0, *shape))


class Trajectory:
    """Frozen pieces of one ball (see the module docstring); ``sample`` evaluates them."""

    def __init__(self, b: TrajectoryBuilder, radius, mass, law, gravity):
        self.radius, self.mass, self.law, self.gravity = radius, mass, law, gravity
        self.starts = _cat(b.starts, ())
        self.kinds = _cat(b.kinds, ()).astype(np.int8)
        # index of each piece within the arrays of its kind
        self.index = np.zeros(self.kinds.size, dtype=np.int64)
        for kind in (FLIGHT, CONTACT, REST):
            sel = self.kinds == kind
            self.index[sel] = np.arange(np.count_nonzero(sel))
        self.flights = np.asarray(b.flights, dtype=float).reshape(-1, 3)
        self.contact_t = _cat(b.contact_t, ())
        self.tau_old = _cat(b.tau_old, ())
        self.step = _cat(b.step, ())
        self.y_old = _cat(b.y_old, (2,))
        self.coef = _cat(b.coef, (N_DENSE, 2))
        self.rests = np.asarray(b.rests, dtype=float).reshape(-1, 2)
        if self.starts.size and np.any(np.diff(self.starts) < 0.0):
            raise AssertionError("trajectory pieces out of time order")

    @property
    def n_pieces(self) -> int:
        return int(self.starts.size)

    def sample(self, times):
        """z (m), vz (m/s), force on the ball (N) at ``times`` (s, a 1-D array)."""
        t = np.asarray(times, dtype=float)
        z = np.empty_like(t)
        vz = np.empty_like(t)
        force = np.zeros_like(t)
        piece = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, None)
        kind = self.kinds[piece]
        idx = self.index[piece]

        sel = kind == FLIGHT
        if np.any(sel):
            t0, z0, vz0 = self.flights[idx[sel]].T
            dt = t[sel] - t0
            z[sel] = z0 + dt * (vz0 - 0.5 * self.gravity * dt)
            vz[sel] = vz0 - self.gravity * dt

        sel = kind == CONTACT
        if np.any(sel):
            j = idx[sel]
            tau = t[sel] - self.contact_t[j]
            delta, u = evaluate_dense(
                tau, self.tau_old[j], self.step[j], self.y_old[j], self.coef[j]
            )
            z[sel] = self.radius - delta
            vz[sel] = -u
            force[sel] = impact_force(delta, u, self.law)

        sel = kind == REST
        if np.any(sel):
            zr, fr = self.rests[idx[sel]].T
            z[sel] = zr
            vz[sel] = 0.0
            force[sel] = fr
        return z, vz, force


def evaluate_dense(tau, tau_old, step, y_old, coef):
    """Evaluate DOP853 dense-output pieces: arrays over points; returns (delta, u)."""
    x = ((tau - tau_old) / step)[:, None]
    y = np.zeros_like(y_old)
    for i in range(N_DENSE - 1, -1, -1):
        y = (y + coef[:, i, :]) * (x if (N_DENSE - 1 - i) % 2 == 0 else 1.0 - x)
    y = y + y_old
    return y[:, 0], y[:, 1]
